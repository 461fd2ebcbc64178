"""lawbench: compare the classical impact laws of rigid-body mechanics on shared scenes.

The entry points share one convention, ``(law, scene name or problem, **params,
options=...)``: `solve` returns the `Outcome`, `evaluate` the whole `Trial`, `run_checks` the
verdict of every check (it also takes a trial alone). Laws, scenes and studies are in the
read-only registries `LAWS`, `CASES` and ``lawbench.studies.declared.STUDIES``; every check's
result carries a `Verdict`. `solve_batch` solves many problems of one shape, `fit` identifies
a law's coefficients from measured velocities, `check_law` holds any law to the common checks,
`load_problem` and `save_problem` read and write problem files, `load_run` reads a run table.
A `ContactProblem` is Coulomb's frictional contact problem in contact space (FCLIB's local
form, ``W``, ``q``, ``mu`` as given), solved by a law's ``solve_contact`` into a
`ContactSolution`.

The package is built in layers, each importing only those below it::

    views      command line, report, figures           (lawbench.views)
    bench, fitting   the benchmark, fits to measurements (lawbench.bench, lawbench.fitting)
    studies    the study engine: studies built from their declarations, grids, runs,
               tables, baselines                       (lawbench.studies)
    laws, cases  laws and scenes, their studies declared as data
                                                         (lawbench.laws, lawbench.cases)
    checks     checks, measures, regions               (lawbench.checks)
    numerics, files                                      (lawbench.numerics, lawbench.files)
    core       problem, outcome, law, case, registries, errors, verdicts (lawbench.core)

This module only gathers the public names; nothing in the package imports it.
"""

import importlib

# Every public name is loaded when first asked for, so that importing the package (as the
# ``lawbench`` program does first, `lawbench.views.program`) loads no numerical library: a
# single solve loads the core and numpy, problem files scipy.sparse (and h5py for HDF5),
# fitting pandas and scipy.optimize, run tables pandas and pyarrow, figures matplotlib.
_LAZY = {
    **dict.fromkeys(("CHECKS", "CheckResult", "run_checks"), "lawbench.checks"),
    **dict.fromkeys(("CASES", "Case", "GroundTruth", "Reference"), "lawbench.core.case"),
    **dict.fromkeys(("ContactProblem", "ContactSolution"), "lawbench.core.contact"),
    **dict.fromkeys(
        (
            "BudgetExceeded",
            "InvalidProblem",
            "LawbenchError",
            "LossyExport",
            "NotApplicable",
            "SolverFailure",
            "UnknownName",
        ),
        "lawbench.core.errors",
    ),
    **dict.fromkeys(("LAWS", "Law"), "lawbench.core.law"),
    "Outcome": "lawbench.core.outcome",
    **dict.fromkeys(("Contact", "ImpactProblem"), "lawbench.core.problem"),
    "Spec": "lawbench.core.spec",
    "Tags": "lawbench.core.tags",
    **dict.fromkeys(("Trial", "evaluate", "solve", "solve_batch"), "lawbench.core.trial"),
    **dict.fromkeys(("Claim", "Region", "Verdict"), "lawbench.core.verdicts"),
    **dict.fromkeys(("OutcomeBatch", "ProblemBatch"), "lawbench.core.batch"),
    **dict.fromkeys(("load_problem", "save_problem"), "lawbench.files.problem_files"),
    **dict.fromkeys(("fit", "FitResult"), "lawbench.fitting"),
    "load_run": "lawbench.studies.runfile",
    **dict.fromkeys(
        ("plot_outcome", "plot_path", "plot_profiles", "plot_sweep"), "lawbench.views.plotting"
    ),
    "check_law": "lawbench.studies.conformance",
}


def __getattr__(name: str) -> object:
    if name == "__version__":
        # The installed distribution's version, read when asked: importlib.metadata costs a
        # third of the start-up of a small command.
        from importlib.metadata import version

        return version("lawbench")
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value  # asked once
        return value
    raise AttributeError(f"module 'lawbench' has no attribute {name!r}")


def __dir__() -> list[str]:
    # The lazy names too, so that dir(), help() and completion show the whole public API.
    return sorted({*globals(), *__all__})


__all__ = [
    "CASES",
    "CHECKS",
    "LAWS",
    "BudgetExceeded",
    "Case",
    "CheckResult",
    "Claim",
    "Contact",
    "ContactProblem",
    "ContactSolution",
    "FitResult",
    "GroundTruth",
    "ImpactProblem",
    "InvalidProblem",
    "Law",
    "LawbenchError",
    "LossyExport",
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
    "UnknownName",
    "Verdict",
    "check_law",
    "evaluate",
    "fit",
    "load_problem",
    "load_run",
    "plot_outcome",
    "plot_path",
    "plot_profiles",
    "plot_sweep",
    "run_checks",
    "save_problem",
    "solve",
    "solve_batch",
]
