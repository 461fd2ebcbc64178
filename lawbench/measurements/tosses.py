"""Impacts extracted from tracked tosses of a rigid polyhedron onto a horizontal table.

A toss is sampled at a fixed rate: the centre's position and the body's orientation. Its first
impact is where the centre's vertical acceleration, by second differences, first exceeds
`Extraction.jump` (free flight gives ``-g``). Free flight is then fitted on each side, leaving
out `Extraction.skip` samples next to the impact (the tracker smooths across it):

- the centre follows ``p(t) = p0 + v0 (t - t0) - g (t - t0)^2 e_z / 2`` with g = 9.81 m/s^2;
- the orientation turns at a constant angular velocity in the world frame, ``R(t) = exp((t -
  t0) [omega]) R0``: torque-free rotation keeps omega constant for a body of spherical inertia
  (a cube's), and over a few frames for any body. The rotation vectors of ``R_i R_ref^T`` are
  fitted by a line in time.

The samples after the impact stop before the next jump. The impact instant is where the
fit before it brings the lowest vertex to the table; both fits are evaluated there, giving
the velocities before and after and the pose. The contacts are the vertices within
`Extraction.contact` of the table at that pose. The generalized velocity is
``(v_centre, omega)``, both in the world frame, with ``M = diag(m, m, m, I, I, I)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from lawbench.core.problem import ImpactProblem

GRAVITY = 9.81
AXES = np.eye(3)


@dataclass(frozen=True)
class Extraction:
    """The rules that find and measure a toss's first impact.

    Attributes
    ----------
    rate : float
        Samples per second.
    jump : float
        Vertical acceleration of the centre (m/s^2, by second differences) that marks an
        impact; free flight gives -g, noise a few m/s^2.
    skip : int
        Samples left out on each side of an impact.
    least, most : int
        Fewest and most samples a free-flight fit uses on each side.
    contact : float
        Height above the table (m) within which a vertex is a contact at the impact.
    position_fit, rotation_fit : float
        Largest root-mean-square residual of a good fit: of the centre (m), of the
        orientation (rad).
    """

    rate: float = 148.0
    jump: float = 20.0
    skip: int = 1
    least: int = 4
    most: int = 12
    contact: float = 2e-3
    position_fit: float = 1e-3
    rotation_fit: float = 0.02


@dataclass(frozen=True)
class Flight:
    """Free flight fitted to samples: the state at ``time`` and the fit's residuals."""

    time: float
    position: np.ndarray
    velocity: np.ndarray
    rotation: Rotation
    omega: np.ndarray
    position_residual: float
    rotation_residual: float

    def at(self, time: float) -> tuple[np.ndarray, np.ndarray, Rotation]:
        """The centre's position and velocity and the orientation at ``time``."""
        tau = time - self.time
        fall = np.array([0.0, 0.0, GRAVITY])
        position = self.position + self.velocity * tau - fall * tau**2 / 2
        turned = Rotation.from_rotvec(self.omega * tau) * self.rotation
        return position, self.velocity - fall * tau, turned


def fit_flight(times: np.ndarray, positions: np.ndarray, rotations: Rotation) -> Flight:
    """Fit free flight to samples, stated at the last sample's time.

    The centre's fit is linear least squares once gravity's known fall is added back; the
    orientation's is a line through the rotation vectors relative to the middle sample.
    """
    t0 = float(times[-1])
    tau = times - t0
    basis = np.column_stack([np.ones_like(tau), tau])
    lifted = positions + np.outer(tau**2, [0.0, 0.0, GRAVITY / 2])
    coefficients, *_ = np.linalg.lstsq(basis, lifted, rcond=None)
    position_residual = np.sqrt(np.mean(np.sum((lifted - basis @ coefficients) ** 2, axis=1)))
    middle = len(times) // 2
    relative = (rotations * rotations[middle].inv()).as_rotvec()
    turn, *_ = np.linalg.lstsq(basis, relative, rcond=None)
    rotation_residual = np.sqrt(np.mean(np.sum((relative - basis @ turn) ** 2, axis=1)))
    rotation = Rotation.from_rotvec(turn[0]) * rotations[middle]
    return Flight(
        t0,
        coefficients[0],
        coefficients[1],
        rotation,
        turn[1],
        float(position_residual),
        float(rotation_residual),
    )


@dataclass(frozen=True)
class TossImpact:
    """The first impact of a toss: when, the pose, and the velocities on either side.

    ``v_before`` and ``v_after`` are ``(v_centre, omega)`` in the world frame; ``touching``
    marks the vertices that are contacts.
    """

    time: float
    position: np.ndarray
    rotation: Rotation
    v_before: np.ndarray
    v_after: np.ndarray
    touching: np.ndarray
    facts: dict[str, Any] = field(default_factory=dict)


def _windows(z: np.ndarray, rules: Extraction) -> tuple[slice, slice] | str:
    """The samples of free flight before and after the first impact, or why there are none.

    The impact is the first run of jumps, a run going on while the next jump comes within
    two samples: the tracker spreads one impact over a few frames, and a second vertex that
    lands at once makes it longer.
    """
    acceleration = np.diff(z, 2) * rules.rate**2
    jumps = np.flatnonzero(acceleration > rules.jump) + 1
    if jumps.size == 0:
        return "no impact found"
    first = last = int(jumps[0])
    for jump in jumps[1:]:
        if jump > last + 2:
            break
        last = int(jump)
    end_before = first - rules.skip
    start_after = last + 1 + rules.skip
    later = jumps[jumps > last]
    end_after = int(later[0]) - rules.skip if later.size else z.size
    if end_before - max(0, end_before - rules.most) < rules.least:
        return "too few samples before the impact"
    if end_after - start_after < rules.least:
        return "too few samples between the impact and the next"
    before = slice(max(0, end_before - rules.most), end_before)
    return before, slice(start_after, min(end_after, start_after + rules.most))


def _landing(
    flight: Flight, vertices: np.ndarray, table: float, start: float, end: float
) -> float | None:
    """The first time in [start, end] the fitted flight brings a vertex to the table, or None."""
    for time in np.linspace(start, end, 241):
        position, _, rotation = flight.at(time)
        if (rotation.apply(vertices)[:, 2] + position[2]).min() <= table:
            return float(time)
    return None


def first_impact(
    times: np.ndarray,
    positions: np.ndarray,
    rotations: Rotation,
    vertices: np.ndarray,
    table: float = 0.0,
    rules: Extraction = Extraction(),
) -> TossImpact | str:
    """The first impact of a toss, or the reason it cannot be measured.

    Parameters
    ----------
    times : array (k,)
        Sample times (s).
    positions : array (k, 3)
        The centre's positions in the world frame (m), z up.
    rotations : scipy Rotation of k orientations
        Body to world.
    vertices : array (c, 3)
        The body's vertices in its own frame, from the centre (m).
    table : float
        The table's height (m).
    rules : Extraction
        Detection, windows and thresholds.
    """
    windows = _windows(positions[:, 2], rules)
    if isinstance(windows, str):
        return windows
    before, after = windows
    ahead = fit_flight(times[before], positions[before], rotations[before])
    behind = fit_flight(times[after], positions[after], rotations[after])
    if ahead.position_residual > rules.position_fit or ahead.rotation_residual > rules.rotation_fit:
        return "poor free-flight fit before the impact"
    if (
        behind.position_residual > rules.position_fit
        or behind.rotation_residual > rules.rotation_fit
    ):
        return "poor free-flight fit after the impact"
    time = _landing(ahead, vertices, table, ahead.time, float(times[after.start]))
    if time is None:
        return "no vertex reaches the table"
    position, velocity, rotation = ahead.at(time)
    _, velocity_after, _ = behind.at(time)
    offsets = rotation.apply(vertices)
    heights = offsets[:, 2] + position[2] - table
    near = heights <= rules.contact
    # A vertex that lands before the samples after the impact begin takes part in it: the
    # impact is compound, and the rigid laws meet it as simultaneous.
    approach = -(velocity[2] + np.cross(ahead.omega, offsets)[:, 2])
    landing = np.maximum(approach, 0.0) * (float(times[after.start - rules.skip]) - time)
    compound = (~near) & (heights < landing)
    touching = near | compound
    facts = {
        "fit_residuals_m": (ahead.position_residual, behind.position_residual),
        "fit_residuals_rad": (ahead.rotation_residual, behind.rotation_residual),
        "windows": (before.start, before.stop, after.start, after.stop),
        "compound": bool(compound.any()),
    }
    return TossImpact(
        time,
        position,
        rotation,
        np.concatenate([velocity, ahead.omega]),
        np.concatenate([velocity_after, behind.omega]),
        touching,
        facts,
    )


def vertex_problem(
    mass: float, inertia: float, offsets: np.ndarray, v: np.ndarray
) -> ImpactProblem:
    """The impact of a body on the table z = const at vertices ``offsets`` from its centre.

    ``offsets`` are world-frame vectors from the centre to the contact vertices; ``v`` is
    ``(v_centre, omega)`` in the world frame. Each contact's normal column is ``(e_z, r x
    e_z)`` and its tangent columns ``(e_x, r x e_x)``, ``(e_y, r x e_y)``: the contact
    point's velocity ``v + omega x r`` along each axis. Coefficients are the placeholders
    ``e = 0``, ``mu = 0`` a fit replaces.
    """
    M = np.diag([mass] * 3 + [inertia] * 3)

    def column(r: np.ndarray, axis: np.ndarray) -> np.ndarray:
        return np.concatenate([axis, np.cross(r, axis)])

    Wn = np.column_stack([column(r, AXES[2]) for r in offsets])
    Wt = np.column_stack([column(r, AXES[a]) for r in offsets for a in (0, 1)])
    return ImpactProblem.from_arrays(M, Wn, v, Wt, e=0.0, mu=0.0)
