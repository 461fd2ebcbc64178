"""lawbench: compare the classical impact laws of rigid-body mechanics on shared scenes.

The entry point is `solve` (or `evaluate`, which also keeps the problem and parameters for the
checks): a law on a registered scene or on an `ImpactProblem` of your own. Laws and cases are
in the registries `LAWS` and `CASES`; every check's result carries a `Verdict`.
"""

import importlib.metadata

from lawbench.api import evaluate, solve, solve_batch
from lawbench.batch import OutcomeBatch, ProblemBatch
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
from lawbench.runfile import load_run
from lawbench.spec import Spec
from lawbench.tags import Tags
from lawbench.verdicts import Claim, Region, Verdict

__version__ = importlib.metadata.version("lawbench")

__all__ = [
    "CASES",
    "CHECKS",
    "LAWS",
    "BudgetExceeded",
    "Case",
    "CheckResult",
    "Claim",
    "Contact",
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
    "load_run",
    "run_checks",
    "solve",
    "solve_batch",
]
