"""Energy dispersion: how the kinetic energy after the impact spreads over the bodies.

The shares of the post-impact kinetic energy carried by each body (``problem.bodies``) and one
dispersion index: the Shannon entropy of the shares over its largest value,
``D = -sum s_b ln s_b / ln(number of bodies)``, 0 when one body carries all the energy (the
textbook, non-dispersive outcome of a chain) and 1 when every body carries the same. The
reference is the high-fidelity compliant model (`compliant`, its default force law, tolerance
1e-10) on the same case and parameters; the value is the largest difference of a share, and
the outcome agrees with the reference when it is below 0.05.
"""

from __future__ import annotations

import math

import numpy as np

from lawbench.checks.base import Trial, check
from lawbench.errors import LawbenchError
from lawbench.law import LAWS
from lawbench.mechanics import energy_shares

AGREEMENT = 0.05


def dispersion_index(shares: dict[str, float]) -> float:
    """Normalized Shannon entropy of the energy shares (0: one body, 1: spread evenly)."""
    values = np.array([s for s in shares.values() if s > 0])
    if len(shares) < 2 or values.size == 0:
        return 0.0
    return max(0.0, float(-(values * np.log(values)).sum() / math.log(len(shares))))


@check("dispersion", several_solves=True)
def dispersion(trial: Trial) -> tuple:
    """Largest share difference against the compliant model; agrees below 0.05."""
    problem = trial.problem
    if len(problem.bodies) < 2:
        return None, None, "fewer than two bodies"
    try:
        reference = LAWS.get("compliant").resolve(problem, rtol=1e-10)
    except LawbenchError as exc:
        return None, None, f"no compliant reference: {type(exc).__name__}: {exc}"
    shares = energy_shares(problem, trial.outcome.v_plus)
    expected = energy_shares(problem, reference.v_plus)
    value = max(abs(shares[b] - expected[b]) for b in shares)
    detail = (
        f"index {dispersion_index(shares):.3f} (compliant {dispersion_index(expected):.3f}); "
        "shares " + ", ".join(f"{b} {s:.3f}" for b, s in shares.items())
    )
    return value, value <= AGREEMENT, detail
