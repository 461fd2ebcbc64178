"""Coulomb's law at the impulse level at one contact, for a batch of problems at once.

Whittaker's law, and Moreau's at one contact, ask for impulses ``P = (Pn, Pt)`` with
``u = bias + G P`` (``G`` the contact Delassus matrix, ``bias`` the pre-impact contact velocity
with the restitution term on the normal row): ``0 <= un _|_ Pn >= 0``, ``|Pt| <= mu Pn`` and
``Pt = -mu Pn ut / |ut|`` where ``ut != 0`` (Brogliato 2010, friction at the impulse level).
Every mode is a closed form: no impulse, stick (``G P = -bias``), and slip along a direction
``s`` with ``un = 0`` and ``Pt = -mu Pn s``: ``s = +-1`` in the plane, in space the roots of the
quartic of `lawbench.laws.whittaker` (module docstring). Here each is computed for every
problem of a batch with a few numpy calls, checked with Whittaker's conditions and a tolerance,
and the solutions are counted by their post-impact velocity as `lawbench.laws.whittaker` counts
them, in the same order, so that a choice among them is the one-by-one path's.

A problem whose modes need more than a closed form (a contact Delassus matrix too close to
singular for a stick solve, a slip whose normal rate does not change with the impulse, a quartic
of lower degree) is marked for the one-by-one path: its impulses are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch

# Contact Delassus matrices of a larger condition number are solved one by one, where a stick
# solve falls back to least squares or linear programming.
CONDITION = 1e8
# The eight angles whose samples give the Fourier coefficients of the slip condition exactly.
_ANGLES = 2 * np.pi * np.arange(8) / 8
_SAMPLES = np.stack([np.cos(_ANGLES), np.sin(_ANGLES)])
NEWTON_STEPS = 20


@dataclass(frozen=True)
class Solutions:
    """Every mode's impulses of a batch of one-contact problems, and which solve the law.

    ``P`` is (B, C, 1 + d) over the C modes in Whittaker's order (no impulse, stick, slips);
    ``kept`` marks the solutions, one per post-impact velocity; ``T_plus`` their kinetic
    energies after the impact; ``alone`` the problems left to the one-by-one path.
    """

    P: np.ndarray
    kept: np.ndarray
    T_plus: np.ndarray
    alone: np.ndarray

    def least_energy(self) -> np.ndarray:
        """The solution of least kinetic energy after the impact (the first on a tie), (B, 1 + d).

        NaN for a problem left to the one-by-one path or with no solution (whose reason that
        path gives).
        """
        energy = np.where(self.kept, self.T_plus, np.inf)
        chosen = self.P[np.arange(len(self.P)), np.argmin(energy, axis=1)]
        chosen[self.alone | ~self.kept.any(axis=1)] = np.nan
        return chosen

    def unique(self) -> np.ndarray:
        """The solution where there is exactly one, NaN elsewhere, (B, 1 + d)."""
        chosen = self.least_energy()
        chosen[self.kept.sum(axis=1) != 1] = np.nan
        return chosen


def solutions(batch: ProblemBatch, normal: np.ndarray, tolerance: float) -> Solutions:
    """Every solution of the impulse-level Coulomb law at one contact, for a batch.

    Parameters
    ----------
    batch : ProblemBatch
        One-contact problems, frictionless or not (a problem with ``mu = 0`` has the
        frictionless closed form).
    normal : array (B, 1)
        The normal rate's part of ``u(P) - G P``: ``un-`` with the restitution term.
    tolerance : float
        Relative tolerance of the law's conditions (`lawbench.laws.whittaker.TOLERANCE`).
    """
    G, mu, T_minus = batch.contact_delassus, batch.mu[:, 0], batch.kinetic_energy(batch.v)
    bias = np.concatenate([normal, batch.ut], axis=1)
    u = np.concatenate([batch.un, batch.ut], axis=1)
    size, k = bias.shape
    d = k - 1
    speed = np.maximum(np.maximum(np.abs(bias).max(axis=1), np.abs(u[:, 0])), 1e-300)
    impulse = speed / np.einsum("kii->ki", G).max(axis=1)
    frictionless = np.zeros((size, k))
    frictionless[:, 0] = np.maximum(-bias[:, 0] / G[:, 0, 0], 0.0)
    if d == 0:
        candidates, alone = frictionless[:, None, :], np.zeros(size, dtype=bool)
    else:
        stick, alone = _stick(G, bias)
        slips, singular = _slips(G, bias, mu, speed)
        alone |= singular
        candidates = np.concatenate([np.zeros((size, 1, k)), stick[:, None], slips], axis=1)
    kept = _admissible(G, bias, mu, candidates, speed * tolerance, impulse, tolerance)
    # Without friction the law is the unilateral one: one solution, in closed form.
    plain = mu == 0
    if d == 0:
        kept[:] = True
    else:
        candidates[plain] = 0.0
        candidates[plain, 0] = frictionless[plain]
        kept[plain] = False
        kept[plain, 0] = True
        alone &= ~plain
    GP = np.einsum("kij,kcj->kci", G, candidates)
    T_plus = T_minus[:, None] + np.einsum("ki,kci->kc", u, candidates)
    T_plus += 0.5 * np.einsum("kci,kci->kc", candidates, GP)
    kept = _distinct(G, candidates, kept, T_minus)
    return Solutions(candidates, kept, T_plus, alone)


def _stick(G: np.ndarray, bias: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Impulses that stop the contact, ``G P = -bias``, and the problems left alone (singular)."""
    values = np.linalg.eigvalsh(G)
    alone = ~(values[:, -1] < CONDITION * values[:, 0])
    regular = np.where(alone[:, None, None], np.eye(G.shape[1]), G)
    return -np.linalg.solve(regular, bias[:, :, None])[:, :, 0], alone


def _slips(
    G: np.ndarray, bias: np.ndarray, mu: np.ndarray, speed: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Impulses of every slip direction (B, S, 1 + d), NaN where a direction is no root.

    ``Pt = -mu Pn s`` with ``Pn`` from ``un = 0``; returns too the problems left alone (a
    normal rate that the slip impulse does not change, or a quartic of lower degree).
    """
    size, d = len(bias), bias.shape[1] - 1
    if d == 1:
        directions = np.broadcast_to(np.array([[1.0], [-1.0]]), (size, 2, 1))
        valid, alone = np.ones((size, 2), dtype=bool), np.zeros(size, dtype=bool)
    else:
        directions, valid, alone = _slip_directions(G, bias, mu, speed)
    column = np.concatenate(
        [np.ones((*directions.shape[:2], 1)), -mu[:, None, None] * directions], axis=2
    )
    rate = np.einsum("kj,ksj->ks", G[:, 0], column)
    if d == 1:
        # A slip that leaves the normal rate unchanged is searched by linear programming.
        alone |= (rate == 0).any(axis=1) & (mu > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.where(rate != 0, -bias[:, :1] / rate, 0.0)
    return np.where(valid[:, :, None], x[:, :, None] * column, np.nan), alone


def _slip_directions(
    G: np.ndarray, bias: np.ndarray, mu: np.ndarray, speed: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spatial slip directions (B, 4, 2) from the quartic, which of them are roots, and alone.

    ``g(theta) = (ut D(s) + c (Gtn - mu Gtt s)) x s``, ``D(s) = Gnn - mu Gnt s``,
    ``c = -bias_n``: its Fourier coefficients from eight samples, the roots of the quartic on
    the unit circle, each polished by Newton's method on the angle.
    """
    gtn, Gtt, ut, c = G[:, 1:, 0], G[:, 1:, 1:], bias[:, 1:], -bias[:, 0]
    D = G[:, 0, 0, None] - mu[:, None] * (gtn @ _SAMPLES)
    a = ut[:, :, None] * D[:, None, :] + c[:, None, None] * (
        gtn[:, :, None] - mu[:, None, None] * (Gtt @ _SAMPLES)
    )
    g = _SAMPLES[0] * a[:, 1] - _SAMPLES[1] * a[:, 0]
    fourier = np.fft.fft(g, axis=1) / 8
    coefficients = fourier[:, [2, 1, 0, 7, 6]]
    scale = speed * (G[:, 0, 0] + np.abs(G).max(axis=(1, 2)))
    none = np.abs(coefficients).max(axis=1) <= 1e-14 * scale
    # A quartic of lower degree has fewer roots than the companion matrix of four gives.
    alone = ~none & (coefficients[:, 0] == 0)
    lead = np.where(alone | none, 1.0, coefficients[:, 0])
    companion = np.zeros((len(g), 4, 4), dtype=complex)
    companion[:, 0] = -coefficients[:, 1:] / lead[:, None]
    companion[:, 1:, :3] += np.eye(3)
    roots = np.linalg.eigvals(companion)
    with np.errstate(divide="ignore"):
        valid = (np.abs(np.log(np.abs(roots))) <= 1e-4) & ~none[:, None]
    theta = _polished(fourier[:, [6, 7, 0, 1, 2]], np.angle(roots))
    return np.stack([np.cos(theta), np.sin(theta)], axis=2), valid, alone


def _polished(a: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Newton's method on ``g = Re sum_k a_k exp(i k theta)`` (k = -2..2) from each angle (B, S).

    ``g`` is real, so ``a_-k`` is the conjugate of ``a_k`` and ``g = a_0 + 2 Re(a_1 z + a_2 z^2)``
    with ``z = exp(i theta)``. Each angle stops as the one-by-one path's does: at a zero slope,
    or once a step is below 1e-15; only the angles still moving are computed again.
    """
    # a_0, a_1, a_2 of every angle's problem, one row per angle.
    a = np.repeat(a[:, 2:], theta.shape[1], axis=0)
    theta = theta.ravel().copy()
    moving = np.arange(theta.size)
    for _ in range(NEWTON_STEPS):
        angle, c = theta[moving], a[moving]
        z1, z2 = np.exp(1j * angle), np.exp(2j * angle)
        value = c[:, 0].real + 2 * (c[:, 1] * z1 + c[:, 2] * z2).real
        slope = -2 * (c[:, 1] * z1 + 2 * c[:, 2] * z2).imag
        with np.errstate(divide="ignore", invalid="ignore"):
            step = value / slope
        going = (slope != 0.0) & ~(np.abs(step) < 1e-15)
        moving, step = moving[going], step[going]
        if not moving.size:
            break
        theta[moving] -= step
    return theta.reshape(-1, 4)


def _admissible(
    G: np.ndarray,
    bias: np.ndarray,
    mu: np.ndarray,
    P: np.ndarray,
    slack: np.ndarray,
    impulse: np.ndarray,
    tolerance: float,
) -> np.ndarray:
    """Whether each candidate (B, C) satisfies the law, as Whittaker checks it.

    ``slack`` (B,) is the tolerance on velocities, ``tolerance`` relative to the impulses.
    """
    u = bias[:, None, :] + np.einsum("kij,kcj->kci", G, P)
    Pn, Pt, wn, ut = P[:, :, 0], P[:, :, 1:], u[:, :, 0], u[:, :, 1:]
    with np.errstate(invalid="ignore"):
        tol_u = slack[:, None]
        tol_p = tolerance * np.maximum(impulse[:, None], np.abs(P).max(axis=2))
        bound = mu[:, None] * Pn
        slip, tangential = np.linalg.norm(ut, axis=2), np.linalg.norm(Pt, axis=2)
        direction = np.linalg.norm(ut * bound[:, :, None] + slip[:, :, None] * Pt, axis=2)
        return (
            np.isfinite(P).all(axis=2)
            & (Pn >= -tol_p)
            & (wn >= -tol_u)
            & ((Pn <= tol_p) | (np.abs(wn) <= tol_u))
            & (tangential <= bound + tol_p)
            & (direction <= tol_u * np.maximum(bound + tangential, impulse[:, None]))
        )


def _distinct(G: np.ndarray, P: np.ndarray, kept: np.ndarray, T_minus: np.ndarray) -> np.ndarray:
    """``kept`` without a candidate whose velocity an earlier kept one has (kinetic metric).

    Two candidates move the system alike when ``|dP|_G = sqrt(dP.G dP)`` is at most 1e-8 of
    ``sqrt(2 T-)``, Whittaker's count.
    """
    norm = np.maximum(np.sqrt(2 * T_minus), 1e-300)
    kept = kept.copy()
    for c in range(1, P.shape[1]):
        for earlier in range(c):
            dP = np.nan_to_num(P[:, c] - P[:, earlier])
            distance = np.sqrt(np.einsum("ki,kij,kj->k", dP, G, dP).clip(0.0))
            kept[:, c] &= ~(kept[:, earlier] & (distance <= 1e-8 * norm))
    return kept
