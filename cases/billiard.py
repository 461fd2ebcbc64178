"""A cue strikes a billiard ball resting on the table: two simultaneous frictional contacts.

Generalized coordinates ``(u, vx, vy, vz, wx, wy, wz)``: the cue's speed ``u`` (m/s) along its
axis, a rigid stick translating along ``d = (cos(elevation), 0, -sin(elevation))`` (the shot
goes along +x, tilted down by the elevation); the velocity (m/s) of the ball's centre and its
angular velocity (rad/s, world frame). The table is the plane ``z = 0``; the ball, a uniform
solid sphere of radius R (``I = 2 m R^2 / 5``), rests on it with its centre at height R.

Contacts. 1, cue-ball: the cue's axis passes at ``offset_side`` (along y) and ``offset_height``
(along ``e = (sin(elevation), 0, cos(elevation))``, perpendicular to the cue in the vertical
plane) from the centre; its tip meets the sphere at ``p = a y + b e - h d`` from the centre
(``a``, ``b`` the offsets, ``h = sqrt(R^2 - a^2 - b^2)``), where the normal pointing from the
cue into the ball is ``n = -p / R``. The ball's point moves at ``v + w x p``, the tip at ``u d``,
so the gap rate is ``n . (v + w x p) - u (d . n)`` and each tangent ``t`` (two unit vectors
orthogonal to ``n``) gets ``t . (v + w x p) - u (d . t)``: the column is ``(-d . t,
spatial_column(p, t))``. 2, ball-table: the point ``r = (0, 0, -R)`` with normal ``(0, 0, 1)``
and tangents x and y: gap rate ``vz``, slip ``(vx - R wy, vy + R wx)``. Before the shot the
ball is at rest on the table (contact 2 closed, neither approaching nor separating) and the cue
moves at ``speed``. Geometry, for the engines: the ball a solid sphere on a free joint on the
fixed table plane; the cue its tip, a sphere of radius `TIP_RADIUS` of the ball's on a slide
joint along ``d``, touching the ball at ``p`` (its centre on the ball's radius through ``p``).

Parameters (defaults, a masse shot on a pool table): ball ``mass`` 0.17 kg and ``radius``
0.028575 m (57.15 mm diameter), ``cue_mass`` 0.54 kg, ``speed`` 3 m/s, ``elevation`` 70
degrees, ``offset_side`` 12 mm and ``offset_height`` 5 mm; per contact (cue-ball, ball-table):
``e`` (0.8, 0.5), ``mu`` (0.6, 0.2) (a chalked tip, cloth), ``stiffness_ratio`` 1 (ball-table
over cue-ball) and ``exponent`` 1.5.

Source: Jia, *Energy-based modeling of tangential compliance in 3-dimensional impact* (2012
talk) and Jia, Mason and Erdmann, IJRR 32(1) (2013): the billiard shot as two simultaneous
contacts whose normal impulses drive the tangential ones, the example being the masse shot of
a mechanical cue stick at a steep elevation, struck off the centre. The talk gives no numbers
for it; the defaults are a steep masse stroke as players play it (cue about 70 degrees up, the
tip under half a radius off the centre), where the cue presses the ball into the cloth and
both contacts take friction. The straight shot below is the example ``straight``.

Straight shot: horizontal and through the centre, the cue's normal (x) and the table's (z) are
orthogonal in the kinetic metric and no contact point slips, so friction cannot act and the
shot is the frictionless binary impact of the cue on the ball:
``P = (1 + e1) u m mc / (m + mc)``, ball ``v = P / m`` along x, cue ``u - P / mc``, no spin.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._chains import exponent_spec, stiffness_ratio_spec
from lawbench.cases._friction import springs_with_friction
from lawbench.cases._geometry import picked, plane, solid_sphere
from lawbench.core.case import CASES, Case, Params, Reference, per_item
from lawbench.core.errors import InvalidProblem
from lawbench.core.geometry import ContactPair, Geometry, Joint
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.core.trial import Trial
from lawbench.numerics.rigid import spatial_column

TABLE_NORMAL = np.array([0.0, 0.0, 1.0])
TABLE_TANGENTS = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
GRAVITY = 9.81  # m/s^2
# Relative size below which a vertical velocity or a slip counts as none.
TOUCHING = 1e-9
# The ball's path on the cloth after the shot: how long, how many points.
PATH_SECONDS = 1.0
PATH_POINTS = 101
# The cue's tip radius over the ball's (a 13 mm tip on a 57 mm ball).
TIP_RADIUS = 0.23
COORDINATES = ["u [m/s]"] + [f"v{a} [m/s]" for a in "xyz"] + [f"w{a} [rad/s]" for a in "xyz"]


def cue_geometry(p: Params) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:
    """The cue's geometry at the tip.

    Returns the cue's direction ``d``, the tip's point ``r`` from the centre, the normal ``n``
    from the cue into the ball and two tangents orthogonal to it.
    """
    elevation = math.radians(p["elevation"])
    d = np.array([math.cos(elevation), 0.0, -math.sin(elevation)])
    up = np.array([math.sin(elevation), 0.0, math.cos(elevation)])
    side = np.array([0.0, 1.0, 0.0])
    a, b, radius = p["offset_side"], p["offset_height"], p["radius"]
    offset = math.hypot(a, b)
    h = math.sqrt((radius - offset) * (radius + offset))
    r = a * side + b * up - h * d
    n = -r / radius
    first = np.cross(n, side)
    first /= np.linalg.norm(first)
    return d, r, n, (first, np.cross(n, first))


def shot_geometry(p: Params) -> Geometry:
    """The cue's tip on a slide joint along ``d``, the ball on a free joint, the table plane.

    The generalized velocity ``(u, v, w)`` gives the cue ``u d`` and the ball ``(v, w)``.
    """
    d, r, n, tangents = cue_geometry(p)
    radius, tip = p["radius"], TIP_RADIUS * p["radius"]
    centre = np.array([0.0, 0.0, radius])
    ball = solid_sphere("ball", p["mass"], radius, centre)
    cue = solid_sphere("cue", p["cue_mass"], tip, centre + r - tip * n)
    table = plane("table", (0.0, 0.0, 0.0), TABLE_NORMAL)
    pairs = [
        ContactPair("ball", "cue", centre + r, n, tangents, p["e"][0], p["mu"][0]),
        ContactPair(
            "ball", "table", (0, 0, 0), TABLE_NORMAL, TABLE_TANGENTS, p["e"][1], p["mu"][1]
        ),
    ]
    joints = [Joint("free", "ball"), Joint("slide", "cue", d), Joint("fixed", "table")]
    to_bodies = picked([ball, cue, table], [(1, 0)] + [(0, k) for k in range(6)])
    to_bodies[6:9, 0] = d
    return Geometry((ball, cue, table), tuple(joints), tuple(pairs), to_bodies, to_bodies.T)


def _straight_shot(p: Params) -> np.ndarray:
    """The frictionless binary impact of the cue on the ball, along x."""
    m, mc, u = p["mass"], p["cue_mass"], p["speed"]
    impulse = (1 + p["e"][0]) * u * m * mc / (m + mc)
    return np.array([u - impulse / mc, impulse / m, 0.0, 0.0, 0.0, 0.0, 0.0])


def _straight_condition(p: Params) -> str | None:
    if p["elevation"] != 0 or p["offset_side"] != 0 or p["offset_height"] != 0:
        return "needs a horizontal shot through the centre"
    cue, table = p["mu"]
    if cue * table >= 1:
        # The cue's friction can press the ball into the table and the table's friction
        # hold it back: the two cones, at right angles, meet (atan mu_cue + atan mu_table
        # >= 90 degrees), and the rigid problem also has the wedged answer.
        return "needs mu_cue mu_table < 1: otherwise the ball can wedge between cue and table"
    return None


class Billiard(Case):
    """A cue strikes a ball on the table: cue-ball and ball-table contacts, both frictional."""

    name = "billiard"
    summary = "cue striking a billiard ball on the table: two frictional contacts (Jia 2013)"
    params = (
        _specs.mass(0.17, "ball mass"),
        _specs.positive("radius", 0.028575, "ball radius", "m"),
        _specs.positive("cue_mass", 0.54, "cue mass", "kg"),
        _specs.positive("speed", 3.0, "cue speed along its axis", "m/s"),
        Spec("elevation", 70.0, "cue elevation above the table", unit="deg", low=0.0, high=89.0),
        Spec("offset_side", 0.012, "sideways offset of the cue's axis (english)", unit="m"),
        Spec(
            "offset_height",
            0.005,
            "offset of the cue's axis perpendicular to it, upward (follow > 0, draw < 0)",
            unit="m",
        ),
        _specs.restitution([0.8, 0.5], "restitution, cue-ball then ball-table"),
        _specs.friction([0.6, 0.2], "friction, cue-ball then ball-table"),
        stiffness_ratio_spec("stiffness of the ball-table contact over the cue-ball one"),
        exponent_spec(),
    )
    requires = Tags(friction=True, several_contacts=True, spatial=True)
    # Stepping the engines through this scene's studies adds seconds to the quick report.
    quick_engines = False
    ground_truth = springs_with_friction(
        "the cue's compliance against the table's decides how the two contacts share the "
        "impact, and the cue's tip grips or slides on the ball (Jia 2013)"
    )
    references = (
        Reference(
            "straight shot",
            "frictionless binary impact of the cue on the ball (friction cannot act)",
            "moreau",
            _straight_shot,
            condition=_straight_condition,
        ),
    )
    examples = {
        "default": {},
        "straight": {"elevation": 0.0, "offset_side": 0.0, "offset_height": 0.0},
        "side spin": {"elevation": 0.0, "offset_side": 0.01, "offset_height": 0.0},
    }

    def _check(self, params: dict[str, Any]) -> None:
        for name in ("e", "mu"):
            per_item(params, name, 2, "contact: cue-ball, ball-table")
        offset = math.hypot(params["offset_side"], params["offset_height"])
        if offset >= params["radius"]:
            raise InvalidProblem(
                f"offset_side = {params['offset_side']:g} m, offset_height = "
                f"{params['offset_height']:g} m: the cue's axis misses the ball (offset "
                f"{offset:g} m >= radius {params['radius']:g} m)"
            )

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        m, radius = params["mass"], params["radius"]
        inertia = 2 * m * radius * radius / 5
        d, r, n, tangents = cue_geometry(params)
        table = np.array([0.0, 0.0, -radius])
        Wn = np.column_stack(
            [
                np.concatenate([[-d @ n], spatial_column(r, n)]),
                np.concatenate([[0.0], spatial_column(table, TABLE_NORMAL)]),
            ]
        )
        Wt = np.column_stack(
            [np.concatenate([[-d @ t], spatial_column(r, t)]) for t in tangents]
            + [np.concatenate([[0.0], spatial_column(table, t)]) for t in TABLE_TANGENTS]
        )
        contacts = [
            Contact(
                e=params["e"][j],
                mu=params["mu"][j],
                stiffness=(1.0, params["stiffness_ratio"])[j],
                exponent=params["exponent"],
            )
            for j in range(2)
        ]
        problem = ImpactProblem(
            M=np.diag([params["cue_mass"], m, m, m, inertia, inertia, inertia]),
            Wn=Wn,
            Wt=Wt,
            v=np.array([params["speed"], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            contacts=contacts,
            bodies={"cue": (0,), "ball": tuple(range(1, 7))},
        )
        # The geometry once the problem's numbers are checked: a radius whose formulas leave
        # double precision is refused by the problem's field, not by a shape built from it.
        return dataclasses.replace(problem, geometry=shot_geometry(params))

    def coordinates(self, params: Params) -> list[str]:
        """The cue's speed, the ball's velocity and angular velocity."""
        return list(COORDINATES)


CASES.register(Billiard())


def ball_velocity(trial: Trial) -> dict[str, float]:
    """The velocity of the ball's centre after the shot (m/s, world frame)."""
    return dict(zip(("vx", "vy", "vz"), map(float, trial.outcome.v_plus[1:4]), strict=True))


def ball_speed(trial: Trial) -> float:
    """Speed of the ball's centre after the shot (m/s)."""
    return float(np.linalg.norm(trial.outcome.v_plus[1:4]))


def spin(trial: Trial) -> dict[str, float]:
    """The ball's angular velocity after the shot (rad/s, world frame)."""
    return dict(zip(("wx", "wy", "wz"), map(float, trial.outcome.v_plus[4:]), strict=True))


def spin_axis_tilt(trial: Trial) -> float | None:
    """Angle of the spin axis above the table (degrees); None without spin."""
    w = trial.outcome.v_plus[4:]
    size = float(np.linalg.norm(w))
    return None if size == 0 else math.degrees(math.asin(abs(w[2]) / size))


def path_curvature(trial: Trial) -> float | None:
    """Curvature of the ball's path on the table just after the shot (1/m), > 0 turning left.

    The ball slides on the cloth: friction ``mu2 m g`` (``mu2`` the ball-table coefficient,
    ``g`` = 9.81 m/s^2) opposes the slip ``s = (vx - R wy, vy + R wx)`` of its contact point,
    a horizontal acceleration ``a = -mu2 g s / |s|``, and the path bends with curvature
    ``(v x a)_z / |v|^3``. Spin about the vertical (english) keeps ``s`` along ``v`` and the
    path straight; a spin axis tilted out of the plane of the shot (masse) curves it. None
    when the ball leaves the table (``vz > 0``), stands still or rolls without slipping.
    """
    v, w = trial.outcome.v_plus[1:4], trial.outcome.v_plus[4:]
    radius, mu = trial.params["radius"], trial.params["mu"][1]
    speed = math.hypot(v[0], v[1])
    slip = np.array([v[0] - radius * w[1], v[1] + radius * w[0]])
    size = float(np.linalg.norm(slip))
    if v[2] > TOUCHING * speed or speed == 0 or size <= TOUCHING * speed:
        return None
    a = -mu * GRAVITY * slip / size
    return float((v[0] * a[1] - v[1] * a[0]) / speed**3)


def table_path(trial: Trial) -> dict[str, Any] | None:
    """The ball's path on the cloth after the shot (m): hop, sliding, then rolling, for 1 s.

    A ball struck down into the table leaves it at ``vz > 0``: it flies for ``2 vz / g`` at its
    horizontal velocity and spin and lands keeping them (the landing's friction neglected).
    On the cloth the slip of the contact point ``s = (vx - R wy, vy + R wx)`` keeps its
    direction while the ball slides: friction ``mu2 m g`` against it accelerates the centre by
    ``a = -mu2 g s0 / |s0|`` and reduces the slip at ``(7/2) mu2 g`` (a solid sphere; spin about
    the vertical leaves the slip alone), so the path is a parabola, the masse curve, until
    ``t_roll = 2 |s0| / (7 mu2 g)`` after landing, then a straight line at the rolling velocity
    (rolling resistance neglected). None when the ball does not move on the table.
    """
    v, w = trial.outcome.v_plus[1:4], trial.outcome.v_plus[4:]
    radius, mu = trial.params["radius"], trial.params["mu"][1]
    if math.hypot(v[0], v[1]) == 0:
        return None
    flight = 2 * max(float(v[2]), 0.0) / GRAVITY
    slip = np.array([v[0] - radius * w[1], v[1] + radius * w[0]])
    size = float(np.linalg.norm(slip))
    sliding = size > TOUCHING * float(np.linalg.norm(v)) and mu > 0
    a = -mu * GRAVITY * slip / size if sliding else np.zeros(2)
    rolling = 2 * size / (7 * mu * GRAVITY) if sliding else 0.0
    t = np.linspace(0.0, PATH_SECONDS, PATH_POINTS)
    on_cloth = np.maximum(t - flight, 0.0)
    slid = np.minimum(on_cloth, rolling)[:, None]
    rolled = (on_cloth - np.minimum(on_cloth, rolling))[:, None]
    position = (
        v[:2] * np.minimum(t, flight)[:, None]
        + v[:2] * slid
        + 0.5 * a * slid**2
        + (v[:2] + a * rolling) * rolled
    )
    return {
        "t": t.tolist(),
        "x": position[:, 0].tolist(),
        "y": position[:, 1].tolist(),
        "t_land": flight,
        "t_roll": flight + rolling,
    }


MEASURES = {
    "velocity": ball_velocity,
    "ball_speed": ball_speed,
    "spin": spin,
    "spin_tilt": spin_axis_tilt,
    "curvature": path_curvature,
}
UNITS = {
    "velocity": "m/s",
    "ball_speed": "m/s",
    "spin": "rad/s",
    "spin_tilt": "deg",
    "curvature": "1/m",
}

# The studies this scene declares, as data.
Billiard.studies = (
    {
        "shape": "sweep",
        "name": "billiard",
        "title": "billiard shot with a side offset of 12 mm: the ball's velocity (vx, vy, vz; "
        "m/s), speed (m/s), spin (wx, wy, wz; rad/s) and the tilt of its spin axis above the "
        "table (degrees) and the curvature of its path on the cloth (1/m) against the cue's "
        "elevation (degrees)",
        "grid": {"elevation": [0.0, 30.0, 60.0, 75.0]},
        "params": {"offset_side": 0.012, "offset_height": 0.0},
        "measures": MEASURES,
        "axes": ("elevation",),
        "units": UNITS,
        "full": {"grid": {"elevation": [0.0, 15.0, 30.0, 45.0, 60.0, 70.0, 75.0, 80.0]}},
    },
    {
        "shape": "sweep",
        "name": "billiard_offset",
        "title": "masse shot at 60 degrees of elevation: the ball's velocity (m/s), speed (m/s), "
        "spin (rad/s), spin-axis tilt (degrees) and path curvature (1/m) against the cue's "
        "sideways offset (m), -12 mm (left english) to 12 mm",
        "grid": {"offset_side": [-0.012, 0.0, 0.012]},
        "params": {"elevation": 60.0, "offset_height": 0.0},
        "measures": MEASURES,
        "axes": ("offset_side",),
        "units": UNITS,
        "full": {
            "grid": {
                "offset_side": [-0.012, -0.009, -0.006, -0.003, 0.0, 0.003, 0.006, 0.009, 0.012]
            }
        },
    },
    {
        "shape": "table_path",
        "name": "billiard_masse",
        "title": "masse shot (elevation 70 degrees, offsets 12 mm sideways and 5 mm up): the "
        "ball's path on the cloth (m) during its first second, sliding on a parabola until it "
        "rolls, for every law that treats the shot, as the cue's compliance changes (stiffness "
        "of the ball-table contact over the cue-ball one, 0.1 to 10: a soft tip to a hard one)",
        "grid": {"stiffness_ratio": [0.1, 1.0, 10.0]},
        "params": {"elevation": 70.0, "offset_side": 0.012, "offset_height": 0.005},
        "measures": {"table_path": table_path, "curvature": path_curvature},
        "axes": ("stiffness_ratio",),
        "units": {"table_path": "m", "curvature": "1/m"},
    },
    {"shape": "speed_accuracy"},
)
