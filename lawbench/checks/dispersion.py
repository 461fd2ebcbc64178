"""Energy dispersion: how the kinetic energy after the impact spreads over the bodies.

The shares of the post-impact kinetic energy carried by each body (``problem.bodies``) and one
dispersion index: the Shannon entropy of the shares over its largest value,
``D = -sum s_b ln s_b / ln(number of bodies)``, 0 when one body carries all the energy (the
textbook, non-dispersive outcome of a chain) and 1 when every body carries the same. The
reference is the scene's ground truth when it is a converged model (``Case.ground_truth``: for
the chains, compliant contacts at the scene's stiffnesses) on the same problem, solved once per
process with the model error's (`lawbench.checks.solved`); the value is the
largest difference of a share, and the outcome agrees with the reference when it is below 0.05.
"""

from __future__ import annotations

import math

import numpy as np

from lawbench.checks.outcome_checks import check
from lawbench.checks.solved import velocity_after
from lawbench.core.errors import LawbenchError
from lawbench.core.mechanics import energy_shares
from lawbench.core.trial import Trial

AGREEMENT = 0.05


def dispersion_index(shares: dict[str, float]) -> float:
    """Normalized Shannon entropy of the energy shares (0: one body, 1: spread evenly)."""
    values = np.array([s for s in shares.values() if s > 0])
    if len(shares) < 2 or values.size == 0:
        return 0.0
    return max(0.0, float(-(values * np.log(values)).sum() / math.log(len(shares))))


@check("dispersion", several_solves=True)
def dispersion(trial: Trial) -> tuple:
    """Largest share difference against the scene's converged model; agrees below 0.05."""
    problem = trial.problem
    if len(problem.bodies) < 2:
        return None, None, "fewer than two bodies"
    truth = trial.case.ground_truth if trial.case is not None else None
    if truth is None or truth.law is None:
        return None, None, "the scene declares no converged model as its ground truth"
    try:
        reference = velocity_after(truth.law, dict(truth.options), problem, trial)
    except LawbenchError as exc:
        return None, None, f"no reference ({truth.law}): {type(exc).__name__}: {exc}"
    shares = energy_shares(problem, trial.outcome.v_plus)
    expected = energy_shares(problem, reference)
    value = max(abs(shares[b] - expected[b]) for b in shares)
    detail = (
        f"index {dispersion_index(shares):.3f} ({truth.law} {dispersion_index(expected):.3f}); "
        "shares " + ", ".join(f"{b} {s:.3f}" for b, s in shares.items())
    )
    return value, value <= AGREEMENT, detail
