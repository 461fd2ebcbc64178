"""A spinning sphere strikes a rough wall obliquely.

Generalized coordinates: the velocity ``(vx, vy, vz)`` (m/s) of the centre and the angular
velocity ``(wx, wy, wz)`` (rad/s, world frame) of a uniform solid sphere. The wall is the plane
``y = 0`` with normal ``n = (0, 1, 0)``; the sphere touches it at ``r = -radius n`` from its
centre. Its tangents are ``t1 = (1, 0, 0)`` (in the plane of incidence) and
``t2 = (0, 0, 1)``. Before the impact the centre moves in the ``x-y`` plane at ``speed`` and
``angle`` from the wall normal: ``v- = speed (sin(angle), -cos(angle), 0)``; the contact point
slips at ``ut- = (vx + radius wz, vz - radius wx)`` along ``(t1, t2)``. The spin about the
normal (``wy``) does not move the contact point. ``I = 2 mass radius^2 / 5``. Geometry, for
the engines: the sphere on a free joint, centred at ``radius n``, touching the fixed plane
``y = 0`` at the origin.

Parameters (defaults): ``radius`` 0.1 m, ``mass`` 1 kg, ``angle`` 45 degrees, ``speed``
2 m/s, ``spin`` (5, 2, -10) rad/s (the contact point slips at (0.414, -0.5) m/s, out of the
plane of incidence), ``e`` 0.8, ``e_t`` 0.2 (Brach's tangential coefficient), ``mu`` 0.3.

Source: the oblique impact of a sphere, Maw, Barber and Fawcett (Wear 38, 1976); Brach,
*Mechanical Impact Dynamics* (1991); Brogliato, *An introduction to impact dynamics* (2010),
equation (11) and the sphere/plane experiments it cites.

Invariants: any impulse at the contact point keeps the angular momentum about that point,
``I w + mass radius n x v`` (three axes); without friction the tangential momentum too.
Reference: Brach's law on the sphere is equation (11) with the effective normal mass ``mass``
and tangential mass ``2 mass / 7`` (``1 / m_t = 1 / mass + radius^2 / I``), no coupling.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._friction import springs_with_friction
from lawbench.cases._geometry import geometry, plane, solid_sphere
from lawbench.core.case import CASES, Case, Params, Reference, exactly
from lawbench.core.geometry import ContactPair, Geometry, Joint
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.core.trial import Trial
from lawbench.numerics.rigid import spatial_column

NORMAL = np.array([0.0, 1.0, 0.0])
TANGENTS = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]))


def pre_impact_velocity(p: Params) -> np.ndarray:
    """``(vx, vy, vz, wx, wy, wz)`` before the impact."""
    angle = math.radians(p["angle"])
    velocity = p["speed"] * np.array([math.sin(angle), -math.cos(angle), 0.0])
    return np.concatenate([velocity, p["spin"]])


def _equation_11(p: Params) -> np.ndarray:
    """Brach's eq. (11) with the sphere's effective masses m and 2 m / 7."""
    m, radius = p["mass"], p["radius"]
    v = pre_impact_velocity(p)
    velocity, spin = v[:3], v[3:]
    contact = velocity + np.cross(spin, -radius * NORMAL)
    vn, vt = contact @ NORMAL, contact - (contact @ NORMAL) * NORMAL
    pn = -(1 + p["e"]) * m * vn
    slip = float(np.linalg.norm(vt))
    size = min(p["mu"] * pn, (1 + p["e_t"]) * 2 * m / 7 * slip)
    impulse = pn * NORMAL - (size * vt / slip if slip > 0 else 0.0)
    inertia = 2 * m * radius**2 / 5
    torque = np.cross(-radius * NORMAL, impulse)
    return np.concatenate([velocity + impulse / m, spin + torque / inertia])


@functools.lru_cache(maxsize=64)
def _geometry(mass: float, radius: float, e: float, mu: float) -> Geometry:
    """The sphere touching the plane y = 0 at the origin, on a free joint.

    Cached: a geometry is immutable, and a sweep of the angle, speed or spin keeps it.
    """
    sphere = solid_sphere("sphere", mass, radius, radius * NORMAL)
    wall = plane("wall", (0.0, 0.0, 0.0), NORMAL)
    tangents = tuple(map(tuple, TANGENTS))
    contact = ContactPair("sphere", "wall", (0.0, 0.0, 0.0), tuple(NORMAL), tangents, e, mu)
    joints = [Joint("free", "sphere"), Joint("fixed", "wall")]
    return geometry([sphere, wall], joints, [contact], [(0, k) for k in range(6)])


class SphereWall(Case):
    """A spinning sphere strikes a rough wall obliquely (spatial, one contact)."""

    name = "sphere_wall"
    summary = "spinning sphere striking a rough wall obliquely (spatial)"
    params = (
        _specs.positive("radius", 0.1, "sphere radius", "m"),
        _specs.mass(1.0, "sphere mass"),
        Spec(
            "angle",
            45.0,
            "angle of incidence of the centre's velocity, from the wall normal",
            unit="deg",
            low=0.0,
            high=90.0,
        ),
        _specs.positive("speed", 2.0, "speed of the centre before the impact", "m/s"),
        Spec(
            "spin",
            [5.0, 2.0, -10.0],
            "pre-impact angular velocity wx, wy, wz",
            unit="rad/s",
            kind="floats",
        ),
        _specs.restitution(0.8),
        Spec(
            "e_t",
            0.2,
            "Brach's tangential restitution: ut+ = -e_t ut- while |Pt| < mu Pn",
            low=-1.0,
            high=1.0,
        ),
        _specs.friction(0.3),
    )
    requires = Tags(friction=True, spatial=True)
    ground_truth = springs_with_friction("on the sphere the slip direction turns during the impact")
    references = (
        Reference(
            "eq. (11)",
            "Brogliato 2010, eq. (11) (Brach 1991) with the sphere's effective masses m, 2m/7",
            "brach",
            _equation_11,
        ),
    )
    examples = {
        "default": {},
        "planar topspin": {"spin": [0.0, 0.0, 30.0], "angle": 30.0, "e_t": 0.5},
        "grazing": {"angle": 80.0, "spin": [0.0, 0.0, 0.0]},
        "head-on": {"angle": 0.0, "spin": [0.0, 0.0, 0.0], "e": 1.0, "e_t": 1.0},
        "sticking": {"angle": 20.0, "spin": [0.0, 0.0, 0.0], "mu": 0.9, "e_t": 0.0},
    }

    def _check(self, params: dict[str, Any]) -> None:
        exactly(params, "spin", 3, "axis: wx, wy, wz")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        m, radius = params["mass"], params["radius"]
        r = -radius * NORMAL
        inertia = 2 * m * radius**2 / 5
        contact = Contact(e=params["e"], e_t=params["e_t"], mu=params["mu"])
        return ImpactProblem(
            M=np.diag([m, m, m, inertia, inertia, inertia]),
            Wn=spatial_column(r, NORMAL)[:, None],
            Wt=np.column_stack([spatial_column(r, t) for t in TANGENTS]),
            v=pre_impact_velocity(params),
            contacts=[contact],
            bodies={"sphere": tuple(range(6))},
            geometry=_geometry(m, radius, params["e"], params["mu"]),
        )

    def coordinates(self, params: Params) -> list[str]:
        """Velocity of the centre and angular velocity."""
        return [f"v{a} [m/s]" for a in "xyz"] + [f"w{a} [rad/s]" for a in "xyz"]

    def momentum_axes(self, params: Params) -> np.ndarray:
        """Angular momentum about the contact point; tangential momentum without friction."""
        radius = params["radius"]
        # L_k = I w_k + m radius (n x v)_k and (n x v)_k = v . (e_k x n).
        axes = [np.concatenate([radius * np.cross(e_k, NORMAL), e_k]) for e_k in np.eye(3)]
        if params["mu"] == 0:
            axes += [np.concatenate([t, np.zeros(3)]) for t in TANGENTS]
        return np.array(axes)


CASES.register(SphereWall())


def _slip_direction(trial: Trial) -> np.ndarray:
    return trial.problem.ut / np.linalg.norm(trial.problem.ut)


def slip_before(trial: Trial) -> float:
    """Pre-impact slip speed of the contact point (m/s)."""
    return float(np.linalg.norm(trial.problem.ut))


def slip_after(trial: Trial) -> float:
    """Post-impact slip of the contact point along the pre-impact slip (m/s; < 0 reversed)."""
    return float(trial.problem.Wt.T @ trial.outcome.v_plus @ _slip_direction(trial))


def spin_after(trial: Trial) -> float:
    """Post-impact spin about n x s (rad/s; rolling along s is radius spin = vt)."""
    slip = _slip_direction(trial)
    axis = np.cross(NORMAL, slip[0] * TANGENTS[0] + slip[1] * TANGENTS[1])
    return float(trial.outcome.v_plus[3:] @ axis)


def impulse_ratio(trial: Trial) -> float:
    """Tangential over normal impulse along the pre-impact slip, ``-Pt.s / Pn``."""
    return float(-trial.outcome.Pt @ _slip_direction(trial) / trial.outcome.Pn[0])


_DEFAULTS = SphereWall().parameters()
# The studies this scene declares, as data. The quick report grazes at 1e-12 m/s alone: from
# 1e-4 to 1e-8 m/s the spatial slip of the integrating laws turns stiffly and takes seconds a
# cell (every decade in the full report).
SphereWall.studies = (
    {
        "shape": "sweep",
        "name": "sphere_wall",
        "title": "sphere on a wall, no pre-impact spin, incidence 5 to 85 degrees: post-impact "
        "slip ut_plus (m/s) along the pre-impact slip, spin about n x s (rad/s), impulse ratio "
        f"-Pt.s/Pn; e = {_DEFAULTS['e']:g}, e_t = {_DEFAULTS['e_t']:g}, "
        f"mu = {_DEFAULTS['mu']:g}, speed = {_DEFAULTS['speed']:g} m/s, "
        f"radius = {_DEFAULTS['radius']:g} m",
        "laws": ("brach", "whittaker", "darboux_keller"),
        "grid": {"angle": np.linspace(5.0, 85.0, 9).tolist()},
        "params": {"spin": [0.0, 0.0, 0.0]},
        "measures": {
            "ut_minus": slip_before,
            "ut_plus": slip_after,
            "spin_plus": spin_after,
            "impulse_ratio": impulse_ratio,
        },
        "axes": ("angle", "ut_plus", "spin_plus", "impulse_ratio"),
        "units": {"ut_plus": "m/s", "spin_plus": "rad/s", "impulse_ratio": ""},
    },
    {"shape": "large_friction"},
    {"shape": "grazing", "e": [0.0, 1.0], "values": (1e-12,)},
    {"shape": "speed_accuracy"},
)
