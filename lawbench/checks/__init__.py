"""Checks of an outcome: each returns a value, a verdict and a reason, or is skipped with one.

``energy_gain``, ``admissible``, ``impulse_sign``, ``momentum`` and ``reference`` read one
trial (a law solved on a case); `run_checks` runs them all.
"""

from lawbench.checks import outcome_checks, reference
from lawbench.checks.base import CHECKS, CheckResult, Trial, run_checks

__all__ = ["CHECKS", "CheckResult", "Trial", "outcome_checks", "reference", "run_checks"]
