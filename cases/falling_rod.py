"""A rod strikes a rough floor with its lower end (Brogliato's falling rod, eqs. 7-9).

Generalized coordinates: ``q = (x, y, theta)``, the centre of mass of a uniform planar rod and
its angle; the velocities are ``vx``, ``vy`` (m/s) and ``omega`` (rad/s, counter-clockwise
positive). The rod makes the angle ``angle`` with the floor (``y = 0``, normal ``(0, 1)``,
tangent ``(1, 0)``); its lower end, the contact, is to the right of the centre of mass, at
``l (cos(angle), -sin(angle))`` with ``l = length / 2``. In the lectures' notation
``theta = 90 deg - angle`` is measured from the vertical, ``h(q) = y - l cos(theta)``, and
the Jacobian columns are ``(0, 1, l sin(theta))`` (normal) and ``(1, 0, l cos(theta))``
(tangent), equation (7). The moment of inertia is ``I = mass length^2 / 12 = m l^2 / 3``.
Geometry, for the engines: the rod a thin capsule on a planar joint (the x-y plane) whose lower
hemisphere touches the fixed floor plane ``y = 0`` at the contact end, a point contact.

Parameters (defaults): ``length`` 1 m, ``mass`` 1 kg, ``angle`` 45 degrees, ``velocities``
``(vx, vy, omega) = (1, -2, 0)`` (m/s, m/s, rad/s), ``e`` 0.5, ``mu`` 0.3.

Source: Brogliato, *An introduction to impact dynamics* (2010), the rod falling on the ground,
equations (7)-(9).

References, from the impact equations (8) at one contact with an impulse ratio
``mu_r = pt / pn`` and Newton's normal law ``un+ = -e un-``::

    pn = -(1 + e) un- / (Gnn + mu_r Gnt)
    m Gnn = 1 + 3 sin^2(theta), m Gnt = 3 sin(theta) cos(theta), m Gtt = 1 + 3 cos^2(theta)
    vx+ = vx- + pt / m, vy+ = vy- + pn / m, omega+ = omega- + l (sin(theta) pn + cos(theta) pt) / I

- eq. (8) itself, friction opposing the post-impact slip ``ut+`` (Whittaker's law; at one
  contact it is also Moreau's): ``mu_r = -mu sgn(ut+)``, or ``ut+ = 0`` with ``|mu_r| <= mu``.
  The reference holds where exactly one of the three modes is consistent;
- Brach's law, equation (11) with the rod's Delassus matrix: ``ut+ = 0`` (e_t = 0 here) when
  the impulse ratio fits in ``mu``, else ``mu_r = -mu sgn(ut-)``.

The energy change for a ratio ``mu_r`` (equation 9, whose printed form in terms of
``N(theta, mu)`` and ``M(theta, mu)`` is garbled in the extraction; derived again here) is
``dT = pn ((1 - e) un- + mu_r (2 ut- + (Gnt + mu_r Gtt) pn)) / 2``. It needs
``Gnn + mu_r Gnt > 0`` (a positive normal impulse: the denominator of the lectures' ``N``).
A slipping impact (``|mu_r| = mu``) can gain energy only when the slip reverses
(``sgn(ut+) = -sgn(ut-)``, the remark after eq. 9); a sticking one (``ut+ = 0``,
``dT = pn ((1 - e) un- + mu_r ut-) / 2``) when the coupling makes the impulse push along the
pre-impact slip. The example "energy gain" is a slipping gain for Brach (+9.3 %) and for
Whittaker's law (+1.5 %).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._friction import springs_with_friction
from lawbench.cases._geometry import geometry, plane, z_onto
from lawbench.core.case import CASES, Case, Params, Reference, exactly
from lawbench.core.geometry import Body, ContactPair, Geometry, Joint
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.numerics.rigid import planar_column, planar_tangent

FLOOR = np.array([0.0, 1.0])
# The radius of the capsule's end, over the height of the rod's centre above the floor: the
# end touches the floor at one point, and the rest of the rod stays above it.
END_RADIUS = 1e-3


def lower_end(length: float, angle_deg: float) -> np.ndarray:
    """Position of the contact end relative to the centre of mass."""
    angle = math.radians(angle_deg)
    return length / 2 * np.array([math.cos(angle), -math.sin(angle)])


def _rates(p: Params) -> tuple[float, float, float, float, float]:
    """Pre-impact ``un, ut`` of the lower end and the rod's ``Gnn, Gnt, Gtt`` (eq. 8)."""
    m, half = p["mass"], p["length"] / 2
    theta = math.radians(90.0 - p["angle"])
    s, c = math.sin(theta), math.cos(theta)
    vx, vy, omega = p["velocities"]
    return (
        vy + half * s * omega,
        vx + half * c * omega,
        (1 + 3 * s * s) / m,
        3 * s * c / m,
        (1 + 3 * c * c) / m,
    )


def impulse_response(p: Params, ratio: float) -> tuple[float, np.ndarray, float]:
    """Equation (8) with Newton's normal law and ``pt / pn = ratio``: ``(pn, v+, ut+)``."""
    m, half = p["mass"], p["length"] / 2
    theta = math.radians(90.0 - p["angle"])
    un, ut, g_nn, g_nt, g_tt = _rates(p)
    pn = -(1 + p["e"]) * un / (g_nn + ratio * g_nt)
    pt = ratio * pn
    inertia = m * half**2 / 3
    turn = half * (math.sin(theta) * pn + math.cos(theta) * pt) / inertia
    v_plus = np.asarray(p["velocities"], dtype=float) + np.array([pt / m, pn / m, turn])
    return pn, v_plus, ut + (g_nt + ratio * g_tt) * pn


def _sticking_ratio(p: Params) -> tuple[float, float]:
    """Impulses ``(pn, pt)`` that give ``un+ = -e un-`` and ``ut+ = 0`` (Cramer's rule)."""
    un, ut, g_nn, g_nt, g_tt = _rates(p)
    rhs_n, rhs_t = -(1 + p["e"]) * un, -ut
    # In units of the rod's mass (m G is dimensionless), where the determinant cannot underflow.
    m = p["mass"]
    g_nn, g_nt, g_tt = g_nn * m, g_nt * m, g_tt * m
    det = g_nn * g_tt - g_nt * g_nt
    return m * (rhs_n * g_tt - g_nt * rhs_t) / det, m * (g_nn * rhs_t - g_nt * rhs_n) / det


def whittaker_modes(p: Params) -> list[np.ndarray]:
    """Post-impact velocities of every consistent mode of eq. (8) (slip right, left, stick)."""
    mu, modes = p["mu"], []
    for ratio in (mu, -mu):
        pn, v_plus, ut_plus = impulse_response(p, ratio)
        # Friction opposes the post-impact slip: pt = ratio pn has the sign of -ut+.
        if pn > 0 and ratio != 0 and ratio * ut_plus < 0:
            modes.append(v_plus)
    pn, pt = _sticking_ratio(p)
    if pn > 0 and abs(pt) <= mu * pn:
        modes.append(impulse_response(p, pt / pn)[1])
    return modes


def _equation_8(p: Params) -> np.ndarray:
    return whittaker_modes(p)[0]


def _equation_8_holds(p: Params) -> str | None:
    if _rates(p)[0] >= 0:
        return "needs the end to approach the floor"
    if p["mu"] == 0:
        return "needs mu > 0"
    count = len(whittaker_modes(p))
    return None if count == 1 else f"eq. (8) has {count} consistent modes here"


def brach_ratio(p: Params) -> float:
    """Brach's impulse ratio on the rod: the sticking ratio if it fits in mu, else -mu sgn(ut-)."""
    pn, pt = _sticking_ratio(p)
    if pn >= 0 and abs(pt) <= p["mu"] * pn:
        return pt / pn
    return -p["mu"] * math.copysign(1.0, _rates(p)[1])


def _brach(p: Params) -> np.ndarray:
    return impulse_response(p, brach_ratio(p))[1]


def _brach_holds(p: Params) -> str | None:
    un, ut, g_nn, g_nt, _ = _rates(p)
    if un >= 0:
        return "needs the end to approach the floor"
    if abs(ut) <= 1e-12 * abs(un):
        return "needs a pre-impact slip (its sign picks the friction direction)"
    if g_nn + brach_ratio(p) * g_nt <= 0:
        return "Brach's slip branch has no positive normal impulse here"
    return None


@functools.lru_cache(maxsize=64)
def _geometry(length: float, mass: float, angle: float, e: float, mu: float) -> Geometry:
    """The rod as a capsule on a planar joint in the x-y plane, on the floor plane y = 0.

    The lower end touches the floor at the origin. The capsule's axis runs from the centre of
    mass to the centre of its lower hemisphere, a radius above the contact end, so that the
    hemisphere touches the floor there, at the end's point of the rod; its moments of inertia
    are the rod's, ``mass length^2 / 12`` about every axis across it. Cached: a geometry is
    immutable, and a sweep of the velocities keeps it.
    """
    end = lower_end(length, angle)
    radius = END_RADIUS * -end[1]
    axis = np.array([end[0], end[1] + radius, 0.0])
    half = float(np.linalg.norm(axis))
    across = mass * length**2 / 12.0
    rod = Body(
        "rod",
        "capsule",
        (radius, half),
        mass,
        (across, across, mass * radius**2 / 2.0),
        (-end[0], -end[1], 0.0),
        z_onto(axis),
    )
    floor = plane("floor", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    pair = ContactPair("rod", "floor", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), ((1.0, 0.0, 0.0),), e, mu)
    joints = [Joint("planar", "rod", (0.0, 0.0, 1.0)), Joint("fixed", "floor")]
    return geometry([rod, floor], joints, [pair], [(0, 0), (0, 1), (0, 5)])


class FallingRod(Case):
    """A uniform rod strikes a rough floor with its lower end."""

    name = "falling_rod"
    summary = "rod striking a rough floor with one end (Brogliato 2010, eqs. 7-9)"
    params = (
        _specs.positive("length", 1.0, "length of the whole rod", "m"),
        _specs.mass(1.0, "rod mass"),
        Spec(
            "angle",
            45.0,
            "angle between the rod and the floor (the lower end right of the centre)",
            unit="deg",
            low=0.0,
            high=90.0,
            low_open=True,
        ),
        Spec(
            "velocities",
            [1.0, -2.0, 0.0],
            "pre-impact vx, vy of the centre of mass and omega (counter-clockwise)",
            unit="m/s, m/s, rad/s",
            kind="floats",
        ),
        _specs.restitution(0.5),
        _specs.friction(0.3),
    )
    requires = Tags(friction=True)
    # Stepping the engines through this scene's studies adds seconds to the quick report.
    quick_engines = False
    ground_truth = springs_with_friction(
        "on the rod the normal-tangential coupling can reverse the slip (the remark after eq. 9)"
    )
    references = (
        *(
            Reference(
                "eq. (8)",
                "Brogliato 2010, eq. (8): Newton's normal law, Coulomb on the post-impact slip",
                law,
                _equation_8,
                condition=_equation_8_holds,
            )
            for law in ("whittaker", "moreau")
        ),
        Reference(
            "eq. (8) with eq. (11)",
            "Brogliato 2010, eq. (8) with Brach's impulses, eq. (11), e_t = 0",
            "brach",
            _brach,
            condition=_brach_holds,
        ),
    )
    examples = {
        "default": {},
        "steep": {"angle": 80.0, "velocities": [0.5, -1.0, 2.0], "e": 0.8, "mu": 0.5},
        "sticking": {"angle": 30.0, "velocities": [0.2, -2.0, 0.0], "mu": 1.0},
        "energy gain": {"angle": 55.0, "velocities": [-0.5, -1.0, 0.0], "e": 0.9, "mu": 0.3},
    }

    def _check(self, params: dict[str, Any]) -> None:
        exactly(params, "velocities", 3, "coordinate: vx, vy, omega")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        mass, length = params["mass"], params["length"]
        r = lower_end(length, params["angle"])
        return ImpactProblem(
            M=np.diag([mass, mass, mass * length**2 / 12.0]),
            Wn=planar_column(r, FLOOR)[:, None],
            Wt=planar_column(r, planar_tangent(FLOOR))[:, None],
            v=np.asarray(params["velocities"], dtype=float),
            contacts=[Contact(e=params["e"], mu=params["mu"])],
            bodies={"rod": (0, 1, 2)},
            geometry=_geometry(length, mass, params["angle"], params["e"], params["mu"]),
        )

    def coordinates(self, params: Params) -> list[str]:
        """Centre-of-mass velocity and angular velocity of the rod."""
        return ["vx [m/s]", "vy [m/s]", "omega [rad/s]"]

    def momentum_axes(self, params: Params) -> np.ndarray:
        """Angular momentum about the contact end; horizontal momentum too without friction."""
        rx, ry = lower_end(params["length"], params["angle"])
        axes = [[ry, -rx, 1.0]]
        if params["mu"] == 0:
            axes.append([1.0, 0.0, 0.0])
        return np.array(axes)


CASES.register(FallingRod())


_GAIN = {k: v for k, v in FallingRod.examples["energy gain"].items() if k not in ("angle", "mu")}
# The studies this scene declares, as data.
FallingRod.studies = (
    {"shape": "speed_accuracy"},
    {"shape": "energy_map", "x": ("angle", 5.0, 85.0), "y": ("mu", 0.0, 1.5), "params": _GAIN},
    {"shape": "large_friction"},
    {"shape": "grazing", "e": [0.0, 1.0]},
    {"shape": "duplicated_contact", "e": [0.0, 1.0]},
)
