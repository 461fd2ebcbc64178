"""Checks of an outcome: each returns a value, a verdict and a reason, or is skipped with one.

Single-solve checks read one trial (a law solved on a case): ``energy_gain``, ``energy_kept``,
``admissible``,
``impulse_sign``, ``friction_cone``, ``momentum``, ``reference``; `run_checks` runs them by
default. ``continuity`` and ``dispersion`` solve the case again and run on request.
"""

from lawbench.checks import continuity, dispersion, outcome_checks, reference
from lawbench.checks.base import CHECKS, SINGLE_SOLVE, CheckResult, Trial, run_checks

__all__ = [
    "CHECKS",
    "SINGLE_SOLVE",
    "CheckResult",
    "Trial",
    "continuity",
    "dispersion",
    "outcome_checks",
    "reference",
    "run_checks",
]
