"""The bench: the cost of lawbench's answers, against peers measured in the same run.

Owns ``lawbench bench``: the timings and the peers called directly (`lawbench.bench.timing`),
the figures of small impacts, batches, long and integrating chains, the engines and start-up
(`lawbench.bench.impacts`), every law on a folder of problem files with its guarded rows
(`lawbench.bench.problems`) and their performance profiles (`lawbench.bench.profiles`), and
Siconos as a peer (`lawbench.bench.peer`, its solvers in `lawbench.bench.siconos_peer`, a
script that imports numpy and siconos only). The laws and scenes it times are those that
declare its roles (`lawbench.bench.roles.ROLES`). May import the core, numerics, files, checks,
the laws and cases (through their registries) and the study engine (its guard); never a view,
never the fitting.
"""

from lawbench.bench.impacts import report
from lawbench.bench.problems import COLUMNS, SOLVED_FC3D, bench_problems, solvers
from lawbench.bench.profiles import performance_profiles, problems_summary
from lawbench.bench.roles import ROLES, start_up_command, subject, subjects

__all__ = [
    "COLUMNS",
    "ROLES",
    "SOLVED_FC3D",
    "bench_problems",
    "performance_profiles",
    "problems_summary",
    "report",
    "solvers",
    "start_up_command",
    "subject",
    "subjects",
]
