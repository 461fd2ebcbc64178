"""lawbench: compare the classical impact laws of rigid-body mechanics on shared scenes.

The entry point is `solve` (or `evaluate`, which also keeps the problem and parameters for the
checks): a law on a registered scene or on an `ImpactProblem` of your own. Laws and cases are
in the registries `LAWS` and `CASES`; every check's result carries a `Verdict`. `fit`
identifies a law's coefficients from measured pre- and post-impact velocities.
"""

import importlib

from lawbench.api import evaluate, solve, solve_batch
from lawbench.case import CASES, Case, GroundTruth, Reference
from lawbench.checks import CHECKS, CheckResult, Trial, run_checks
from lawbench.errors import (
    BudgetExceeded,
    InvalidProblem,
    LawbenchError,
    NotApplicable,
    SolverFailure,
)
from lawbench.law import LAWS, Law
from lawbench.outcome import Outcome
from lawbench.problem import Contact, ImpactProblem
from lawbench.spec import Spec
from lawbench.tags import Tags
from lawbench.verdicts import Claim, Region, Verdict

# Loaded when first asked for: problem files need scipy.sparse (and h5py for HDF5), fitting
# needs pandas and scipy.optimize, run tables pandas and pyarrow, figures matplotlib; batches
# are more code than a single solve reads.
_LAZY = {
    "OutcomeBatch": "lawbench.batch",
    "ProblemBatch": "lawbench.batch",
    "load_problem": "lawbench.problem_files",
    "save_problem": "lawbench.problem_files",
    "fit": "lawbench.fitting",
    "FitResult": "lawbench.fitting",
    "load_run": "lawbench.runfile",
    "plot_outcome": "lawbench.plotting",
    "plot_path": "lawbench.plotting",
    "plot_sweep": "lawbench.plotting",
}


def __getattr__(name: str) -> object:
    if name == "__version__":
        # The installed distribution's version, read when asked: importlib.metadata costs a
        # third of the start-up of a small command.
        from importlib.metadata import version

        return version("lawbench")
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'lawbench' has no attribute {name!r}")


__all__ = [
    "CASES",
    "CHECKS",
    "LAWS",
    "BudgetExceeded",
    "Case",
    "CheckResult",
    "Claim",
    "Contact",
    "FitResult",
    "GroundTruth",
    "ImpactProblem",
    "InvalidProblem",
    "Law",
    "LawbenchError",
    "NotApplicable",
    "Outcome",
    "OutcomeBatch",
    "ProblemBatch",
    "Reference",
    "Region",
    "SolverFailure",
    "Spec",
    "Tags",
    "Trial",
    "Verdict",
    "evaluate",
    "fit",
    "load_problem",
    "load_run",
    "plot_outcome",
    "plot_path",
    "plot_sweep",
    "run_checks",
    "save_problem",
    "solve",
    "solve_batch",
]
