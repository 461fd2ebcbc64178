"""The yardstick checked: a law's answer against the scene's ground-truth model, solved again.

A scene whose ground truth is a converged model (``Case.ground_truth.law``: compliant contact
integrated in time, on the chains and the frictional scenes) holds every law to that model's
answer. An independent engine that integrates the same impact in time, tuned as rigid and as
faithful to e and mu as it allows, checks the yardstick in turn: where the two model the same
physics they must agree, and where they differ the difference is a finding of the engine
(its force law, its dissipation, its friction), never left unexplained.

The value is the difference relative to the pre-impact motion in the kinetic metric,
``sqrt(dv^T M dv / v^T M v)`` with ``dv = v+ - v_model`` (the measure of the measured sets:
no unit, rotation and translation weighed by the bodies' inertia); the check holds within
`LEVEL`. It runs only where a study names it (``on_request``): held to it, every rigid law
would fail on every chain by its very model.
"""

from __future__ import annotations

import math

from lawbench.checks.outcome_checks import check
from lawbench.checks.solved import velocity_after
from lawbench.core.errors import LawbenchError
from lawbench.core.trial import Trial

# Agreement of two integrations in time of the same contact model: an engine tuned as rigid as
# it allows resolves about a thousandth of the speeds (a plastic contact leaves at 1e-3 of its
# approach, friction sticks below 1e-3 of the speed). Measured with the physics matched (linear
# springs, stiff tangential springs, elastic contacts): 2e-5 on the chains, 6e-4 at most.
LEVEL = 1e-3


def kinetic_difference(trial: Trial, v_model: object) -> float:
    """``sqrt(dv^T M dv / v^T M v)``, ``dv = v+ - v_model``, on ``trial``'s problem."""
    problem = trial.problem
    dv = trial.outcome.v_plus - v_model
    T_minus = problem.T_minus
    return math.sqrt(problem.kinetic_energy(dv) / T_minus) if T_minus > 0 else math.inf


@check("yardstick", several_solves=True, on_request=True)
def yardstick(trial: Trial) -> tuple:
    """Difference in the kinetic metric from the scene's ground-truth model; holds within LEVEL."""
    truth = trial.case.ground_truth if trial.case is not None else None
    if truth is None or truth.law is None:
        return None, None, "the scene declares no converged model as its ground truth"
    if trial.law.name == truth.law:
        return None, None, f"{truth.law} is the ground truth's model itself"
    try:
        v_model = velocity_after(truth.law, dict(truth.options), trial.problem, trial)
    except LawbenchError as exc:
        return None, None, f"no yardstick ({truth.law}): {type(exc).__name__}: {exc}"
    value = kinetic_difference(trial, v_model)
    detail = (
        f"{value:.3g} of the pre-impact motion (kinetic metric) from {truth.law}; "
        f"agreement within {LEVEL:g}"
    )
    return value, value <= LEVEL, detail
