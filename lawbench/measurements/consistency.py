"""Self-consistency of measured impacts, before any law is fitted.

A rigid impact changes the generalized velocity only through the contact impulses:
``M (v_after - v) = Wn Pn + Wt Pt``. With more coordinates than impulse components this
overdetermines the impulses, so the measured change must lie in the span of the contact
Jacobian's columns. Solving for the impulses by least squares and reporting the relative
residual ``|M dv - W P| / |M dv|`` tells how far a measurement (its noise, its conventions,
its mass matrix) is from any rigid impact at the stated contacts.

Both norms are taken in the kinetic metric, ``|p|^2 = p^T M^-1 p`` for a momentum, so the
residual is a share of ``sqrt(dv^T M dv)`` without unit: a plain Euclidean norm would add
kg m/s to kg m^2/s and let the translation of a body of a few centimetres hide any error in
its rotation.
A sign convention that disagrees between the Jacobian and the velocities shows up here long
before a law is fitted.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from lawbench.core.metric import as_array
from lawbench.measurements.impacts import MeasuredImpact

# A residual above this share of |M dv| counts as inconsistent in `consistency`.
THRESHOLD = 0.05


def residuals(impacts: Iterable[MeasuredImpact]) -> np.ndarray:
    """The relative residual of every impact's best impulses, in order.

    Each is ``|M dv - W P| / |M dv|`` in the kinetic metric, with P the impulses that
    minimize it (no sign constraint: the check asks only whether any impulse at the contacts
    explains the change); 0 for a change of zero. With ``M = L L^T`` the momentum residual's
    kinetic norm is the Euclidean norm of ``L^-1 (M dv - W P) = L^T dv - L^-1 W P``. Impacts
    of one shape are solved together as stacks of small matrices.
    """
    impacts = list(impacts)
    values = np.zeros(len(impacts))
    shapes: dict[tuple[int, ...], list[int]] = {}
    for k, impact in enumerate(impacts):
        shapes.setdefault(np.shape(impact.problem.W), []).append(k)
    for rows in shapes.values():
        M = np.stack([as_array(impacts[k].problem.M) for k in rows])
        W = np.stack([as_array(impacts[k].problem.W) for k in rows])
        dv = np.stack([impacts[k].dv for k in rows])
        factor = np.linalg.cholesky(M)
        scaled_change = np.einsum("kji,kj->ki", factor, dv)
        scaled_W = np.linalg.solve(factor, W)
        impulses = np.einsum("kij,kj->ki", np.linalg.pinv(scaled_W), scaled_change)
        miss = scaled_change - np.einsum("kij,kj->ki", scaled_W, impulses)
        size = np.linalg.norm(scaled_change, axis=1)
        values[rows] = np.linalg.norm(miss, axis=1) / np.where(size > 0.0, size, 1.0)
    return values


def residual(impact: MeasuredImpact) -> float:
    """The relative residual of the impulses that best explain ``impact`` (see `residuals`)."""
    return float(residuals([impact])[0])


@dataclass(frozen=True)
class Consistency:
    """A summary of the residuals of a set of impacts.

    Attributes
    ----------
    count : int
        Impacts checked.
    median, p95 : float
        Median and 95th percentile of the relative residuals.
    above : int
        Impacts whose residual exceeds ``threshold``.
    threshold : float
        The residual counted as inconsistent.
    """

    count: int
    median: float
    p95: float
    above: int
    threshold: float


def consistency(impacts: Iterable[MeasuredImpact], threshold: float = THRESHOLD) -> Consistency:
    """Summarize the residuals of ``impacts`` (a set's impacts, or any sequence of them)."""
    values = residuals(impacts)
    if values.size == 0:
        return Consistency(0, float("nan"), float("nan"), 0, threshold)
    return Consistency(
        count=int(values.size),
        median=float(np.median(values)),
        p95=float(np.percentile(values, 95)),
        above=int((values > threshold).sum()),
        threshold=threshold,
    )
