"""What is asked of a law's answer: checks with their verdicts, measures, regions and studies.

Owns the checks (each returns a value, a verdict and a reason, or is skipped with one), the
regions where a law's claims apply, the measures a study records, rigid laws met event by event
through gaps, and studies as data (`Study`, the `STUDIES` registry and the shapes that laws and
scenes declare theirs with). May import `lawbench.core` and `lawbench.numerics`, never a law,
a scene, the study engine or a view.

Single-solve checks read one trial (a law solved on a case): ``energy_gain``, ``energy_kept``,
``admissible``, ``impulse_sign``, ``friction_cone``, ``momentum``, ``reference``; `run_checks`
runs them by default. ``continuity`` and ``dispersion`` solve the case again and run on request.
"""

from lawbench.checks import continuity, dispersion, outcome_checks
from lawbench.checks.base import CHECKS, SINGLE_SOLVE, CheckResult, CheckResults, run_checks

__all__ = [
    "CHECKS",
    "SINGLE_SOLVE",
    "CheckResult",
    "CheckResults",
    "continuity",
    "dispersion",
    "outcome_checks",
    "run_checks",
]
