"""Event location inside one integrator step, shared by the laws that integrate through events.

An integrating law (compliant contacts, energetic impulse dynamics) restarts its integrator at
every event: a gap closing, a compression ending, a damper changing sign. The event is the
first sign change of a smooth function on the step's dense output; it is found by Brent's
method to rounding (about ten evaluations, where bisection to rounding takes fifty), then moved
forward by the smallest step that reaches the new sign, so that the state restarted there is on
the new branch.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

ROUNDING = 4 * float(np.finfo(float).eps)


def crossing(function: Callable[[float], float], lo: float, hi: float, past: bool = True) -> float:
    """A point just past the sign change of ``function`` in ``(lo, hi]``.

    The old sign is the one at ``lo``, the new one the one at ``hi``; when they agree there is
    no change and ``hi`` is returned. A function that Brent's method cannot pin down (a jump
    rather than a zero) is bisected. With ``past`` False, Brent's root itself is returned (to
    rounding, on either side of the zero).
    """
    import scipy.optimize  # on first use: registering a law imports no optimizer

    old, new = np.sign(function(lo)), np.sign(function(hi))
    if new == old:
        return hi
    try:
        root = scipy.optimize.brentq(function, lo, hi, xtol=1e-300, rtol=ROUNDING, maxiter=200)
    except RuntimeError:
        return _bisect(function, lo, hi, old)
    if not past:
        return root
    step = np.spacing(max(abs(root), abs(hi - lo)))
    while root < hi and np.sign(function(root)) != new:
        root = min(root + step, hi)
        step *= 4
    return root


def _bisect(function: Callable[[float], float], lo: float, hi: float, old: float) -> float:
    """The upper end of a bracket of the sign change, halved until it cannot shrink."""
    while (mid := 0.5 * (lo + hi)) not in (lo, hi):
        if np.sign(function(mid)) == old:
            lo = mid
        else:
            hi = mid
    return hi
