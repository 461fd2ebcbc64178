"""The exact piecewise impulse-time dynamics of `SingleContactImpact`, for a batch at once.

Planar slip, stick, slip from rest and the frictionless impact keep their impulse ratio
``r = dPt/dPn`` through a phase, so velocities are affine and the normal work quadratic in the
normal impulse, and every event (slip stop, end of compression, termination) is a closed-form
root (`lawbench.laws.darboux_keller.dynamics`, module docstring). Here each problem of a batch
runs the same phases as `SingleContactImpact._affine_phase`, one phase of every problem per
step, with the same thresholds and the same order of tests, until every impact has ended.

Spatial slip (a direction that may turn, integrated there by an ODE) is left to the one-by-one
path, and so is a problem that path refuses or fails (compression that never ends, a phase that
never ends, too many phases): its impulses are NaN.
"""

from __future__ import annotations

import numpy as np

from lawbench.laws.darboux_keller.dynamics import MAX_PHASES, ROUNDING, SIMULTANEOUS


class _Batch:
    """The state of every impact of a batch: impulses, contact velocity, normal work, phase."""

    def __init__(
        self, G: np.ndarray, u_minus: np.ndarray, mu: np.ndarray, termination: str, e: np.ndarray
    ) -> None:
        size, k = u_minus.shape
        self.G, self.u_minus, self.mu, self.termination, self.e = G, u_minus, mu, termination, e
        self.d = k - 1
        self.impulse_scale = -u_minus[:, 0] / G[:, 0, 0]
        self.slope_zero = ROUNDING * np.abs(G).max(axis=(1, 2)) * (1.0 + mu)
        self.velocity_zero = ROUNDING * np.linalg.norm(u_minus, axis=1)
        self.P, self.Pt = np.zeros(size), np.zeros((size, self.d))
        self.u, self.W = u_minus.astype(float), np.zeros(size)
        self.Pc, self.Wc = np.zeros(size), np.zeros(size)
        self.compressed = np.zeros(size, dtype=bool)
        # Spatial friction may turn the slip: the one-by-one path integrates it.
        approaching = u_minus[:, 0] < 0
        self.failed = approaching & (self.d == 2) & (mu > 0)
        self.active = approaching & ~self.failed

    def phase(self) -> tuple[np.ndarray, np.ndarray]:
        """Ratio ``r`` (B, d) and slip-stop distance (inf: the phase lasts) of every impact."""
        size = len(self.P)
        r, stop = np.zeros((size, self.d)), np.full(size, np.inf)
        if self.d != 1:
            return r, stop
        Gtn, Gtt, ut = self.G[:, 1, 0], self.G[:, 1, 1], self.u[:, 1]
        sliding = np.abs(ut) > self.velocity_zero
        direction = np.sign(ut)
        rate = direction * (Gtn - self.mu * Gtt * direction)
        with np.errstate(divide="ignore", invalid="ignore"):
            stop = np.where(sliding & (rate < 0), -np.abs(ut) / rate, np.inf)
            stick = np.where(Gtt != 0, -Gtn / Gtt, 0.0)
        sticks = np.abs(stick) <= self.mu * (1 + ROUNDING)
        at_rest = np.where(sticks, stick, -self.mu * np.sign(Gtn))
        r[:, 0] = np.where(sliding, -self.mu * direction, at_rest)
        frictionless = self.mu == 0
        r[frictionless], stop[frictionless] = 0.0, np.inf
        return r, stop

    def to_termination(self, slope: np.ndarray) -> np.ndarray:
        """Normal impulse still to apply before the termination (compression over)."""
        un = self.u[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.termination == "poisson":
                return np.maximum((1 + self.e) * self.Pc - self.P, 0.0)
            if self.termination == "newton":
                target = -self.e * self.u_minus[:, 0] - un
                rest = np.where(slope > self.slope_zero, target / slope, np.inf)
                return np.where(target <= 0, 0.0, rest)
            remaining = -(self.e**2) * self.Wc - (self.W - self.Wc)
            discriminant = un * un + 2 * slope * remaining
            root = un + np.sqrt(np.maximum(discriminant, 0.0))
            # The positive root of un x + slope x^2 / 2 = remaining, without cancellation.
            rest = np.where((discriminant < 0) | (root <= 0), np.inf, 2 * remaining / root)
            return np.where(remaining <= 0, 0.0, rest)

    def end_compression(self, rows: np.ndarray) -> None:
        """Compression ends at ``rows``: the normal velocity vanishes there, the state is kept."""
        self.u[rows, 0] = 0.0
        self.Pc[rows], self.Wc[rows] = self.P[rows], self.W[rows]
        self.compressed |= rows

    def step(self) -> None:
        """Every active impact through one phase to its first event (`_affine_phase`)."""
        r, stop = self.phase()
        g = self.G[:, :, 0] + np.einsum("kij,kj->ki", self.G[:, :, 1:], r)
        flat = (g[:, 0] <= self.slope_zero) & (stop == np.inf)
        compressing = self.active & ~self.compressed
        at_rest = compressing & flat & (-self.u[:, 0] <= self.velocity_zero)
        self.failed |= compressing & flat & ~at_rest
        no_expansion = self.active & self.compressed & flat
        with np.errstate(divide="ignore", invalid="ignore"):
            end = np.where(
                self.compressed,
                self.to_termination(g[:, 0]),
                np.where(g[:, 0] > self.slope_zero, -self.u[:, 0] / g[:, 0], np.inf),
            )
        x = np.minimum(stop, end)
        # A flat phase ends compression at rest, fails, or ends the impact: no advance.
        moving = self.active & ~flat
        self.failed |= moving & ~np.isfinite(x)
        moving &= np.isfinite(x)
        xm = np.where(moving, x, 0.0)
        self.W = self.W + self.u[:, 0] * xm + g[:, 0] * xm * xm / 2
        self.P, self.Pt = self.P + xm, self.Pt + r * xm[:, None]
        self.u = self.u + g * xm[:, None]
        near = x * (1 + SIMULTANEOUS) + ROUNDING * self.impulse_scale
        self.u[moving & (stop <= near), 1:] = 0.0
        ended = moving & (end <= near)
        finished = (ended & self.compressed) | no_expansion
        self.end_compression(at_rest | (ended & ~self.compressed))
        self.active &= ~finished & ~self.failed


def impulses(
    G: np.ndarray, u_minus: np.ndarray, mu: np.ndarray, termination: str, e: np.ndarray
) -> np.ndarray:
    """The impulses ``(Pn, Pt)`` (B, 1 + d) of every impact; NaN where it is left alone.

    Parameters
    ----------
    G : array (B, 1 + d, 1 + d)
        Contact Delassus matrices, normal row and column first.
    u_minus : array (B, 1 + d)
        Pre-impact contact velocities; an impact with ``un >= 0`` takes no impulse.
    mu : array (B,)
        Coulomb coefficients.
    termination : str
        'newton', 'poisson' or 'energetic'.
    e : array (B,)
        The coefficient of that termination.
    """
    batch = _Batch(G, u_minus, mu, termination, e)
    for _ in range(MAX_PHASES):
        if not batch.active.any():
            break
        batch.step()
    P = np.concatenate([batch.P[:, None], batch.Pt], axis=1)
    P[batch.failed | batch.active] = np.nan
    return P
