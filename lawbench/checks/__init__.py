"""What is asked of a law's answer: checks with their verdicts, measures and regions.

Owns the checks (each returns a value, a verdict and a reason, or is skipped with one), the
regions where a law's claims apply, the measures a study records and the values its sweeps give
(`lawbench.checks.knobs`), and rigid laws met event by event through gaps. Laws and scenes
import it to state their claims and the measures of the studies they declare as data; the study
engine that builds and runs those studies is above them (`lawbench.studies`). May import
`lawbench.core` and `lawbench.numerics`, never a law, a scene, the study engine or a view.

Single-solve checks read one trial (a law solved on a case): ``energy_gain``, ``energy_kept``,
``admissible``, ``impulse_sign``, ``friction_cone``, ``momentum``, ``reference``; `run_checks`
runs them by default. ``continuity`` and ``dispersion`` solve the case again and run on request;
``yardstick`` runs only in the studies that name it (`ON_REQUEST`).
"""

from lawbench.checks import continuity, dispersion, outcome_checks, yardstick
from lawbench.checks.outcome_checks import (
    CHECKS,
    ON_REQUEST,
    SINGLE_SOLVE,
    CheckResult,
    CheckResults,
    run_checks,
)

__all__ = [
    "CHECKS",
    "ON_REQUEST",
    "SINGLE_SOLVE",
    "CheckResult",
    "CheckResults",
    "continuity",
    "dispersion",
    "outcome_checks",
    "run_checks",
    "yardstick",
]
