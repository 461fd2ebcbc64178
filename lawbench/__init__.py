"""lawbench: compare the classical impact laws of rigid-body mechanics on shared scenes.

The entry point is `solve` (or `evaluate`, which also keeps the problem and parameters for the
checks). Laws and cases are in the registries `LAWS` and `CASES`.
"""

from lawbench.api import evaluate, solve
from lawbench.case import CASES, Case, Reference, Requirements
from lawbench.checks import CHECKS, CheckResult, Trial, run_checks
from lawbench.errors import InvalidProblem, LawbenchError, NotApplicable, SolverFailure
from lawbench.law import LAWS, Capabilities, Law
from lawbench.outcome import Outcome
from lawbench.problem import Contact, ImpactProblem
from lawbench.spec import Spec

__version__ = "0.1.0"

__all__ = [
    "CASES",
    "CHECKS",
    "LAWS",
    "Capabilities",
    "Case",
    "CheckResult",
    "Contact",
    "ImpactProblem",
    "InvalidProblem",
    "Law",
    "LawbenchError",
    "NotApplicable",
    "Outcome",
    "Reference",
    "Requirements",
    "SolverFailure",
    "Spec",
    "Trial",
    "evaluate",
    "run_checks",
    "solve",
]
