"""A rectangular block rocking on one bottom corner lands on the other.

Generalized coordinates: the velocity ``vx``, ``vy`` (m/s) of the centre of mass and the
angular velocity ``omega`` (rad/s, counter-clockwise positive) of a planar rectangular block,
at the instant it is flat on the floor (``y`` up, the floor ``y = 0``). Before the impact the
block rotates about its right bottom corner, the pivot, with angular velocity ``omega > 0``
(counter-clockwise), so its left bottom corner comes down onto the floor:
``v- = (-omega height / 2, -omega width / 2, omega)``. Contact 0 is the left (landing) corner,
gap rate ``vy - omega width / 2`` (``-omega width`` before the impact); contact 1 is the right
corner, the pivot, gap rate ``vy + omega width / 2`` (zero before). Both have the floor's normal
``(0, 1)`` and the tangent ``(1, 0)``, and the same ``e`` and ``mu``. The moment of inertia
about the centre of mass is ``mass (width^2 + height^2) / 12``. Geometry, for the engines: a
box as deep as it is wide on a planar joint (the x-y plane), on the fixed floor plane ``y = 0``,
the contacts at the middles of its bottom edges.

Parameters (defaults): ``width`` 0.5 m, ``height`` 1 m, ``mass`` 10 kg, ``omega`` 1 rad/s,
``e`` 0 (Newton's coefficient of both corners: Housner's plastic impact), ``mu`` 0.5.

Source: Brogliato, *An introduction to impact dynamics* (2010), the rocking block (its
constraints ``h1``, ``h2``; kinetic angle) and the one-contact Moreau formulas after
equation (24), in the notation ``L`` = width, ``l`` = height; G.W. Housner, "The behavior of
inverted pendulum structures during earthquakes", Bull. Seismol. Soc. Am. 53 (1963) 403-417.

References. Housner: the landing corner sticks without rebound, the pivot lifts off, and the
angular momentum about the landing corner is kept, so
``omega+ / omega- = 1 - 3 width^2 / (2 (width^2 + height^2))`` (``1 - 3/2 sin^2 alpha``,
``alpha`` the slenderness angle). Moreau's law gives it with ``e = 0`` when ``mu`` is large
enough to stick and the block is not too wide, and so does Whittaker's law (Newton's rule with
Coulomb's friction on the post-impact slip, the same law at these contacts). The lectures'
one-contact formulas (frictionless Newton rule at the landing corner alone, tangential velocity
kept)::

    vy+ = (2 L^2 - l^2 - 2 e (L^2 + l^2)) / (l^2 + 4 L^2) vy-
    omega+ = (l^2 - 2 L^2 - 6 e L^2) / (l^2 + 4 L^2) omega-

The first is printed in the lectures; the second is derived again here, the printed one
(``(3 - 2 e)(L^2 + l^2) / (4 l^2 + 16 L^2)``) does not conserve the energy at ``e = 1``. They
are Moreau's (and Whittaker's) law with ``mu = 0`` when the pivot separates, that is for
``l >= sqrt(2) L`` (the Delassus coupling of the corners, ``(l^2 - 2 L^2) / (m (L^2 + l^2))``,
is then >= 0).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._geometry import geometry, plane, solid_box
from lawbench.core.case import CASES, Case, GroundTruth, Params, Reference
from lawbench.core.geometry import ContactPair, Geometry, Joint
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.tags import Tags
from lawbench.core.trial import Trial
from lawbench.numerics.rigid import planar_column, planar_tangent

FLOOR = np.array([0.0, 1.0])


def corners(width: float, height: float) -> list[np.ndarray]:
    """Landing (left) and pivot (right) bottom corners, relative to the centre of mass."""
    return [np.array([-width / 2, -height / 2]), np.array([width / 2, -height / 2])]


def pre_impact_velocity(p: Params) -> np.ndarray:
    """Rotation about the pivot corner at ``omega``: ``(vx, vy, omega)``."""
    omega = p["omega"]
    return np.array([-omega * p["height"] / 2, -omega * p["width"] / 2, omega])


def housner_ratio(width: float, height: float) -> float:
    """Housner's ``omega+ / omega-``: angular momentum kept about the landing corner."""
    return 1.0 - 1.5 * width**2 / (width**2 + height**2)


def sticking_ratio(width: float, height: float) -> float:
    """``|Pt| / Pn`` at the landing corner in Housner's impact (the friction it needs)."""
    return 3.0 * width * height / (width**2 + 4.0 * height**2)


def _housner(p: Params) -> np.ndarray:
    """Rotation about the landing corner at Housner's angular velocity."""
    omega = housner_ratio(p["width"], p["height"]) * p["omega"]
    return np.array([-omega * p["height"] / 2, omega * p["width"] / 2, omega])


def _housner_holds(p: Params) -> str | None:
    if p["e"] != 0:
        return "needs e = 0 (no rebound of the landing corner)"
    if p["mu"] < sticking_ratio(p["width"], p["height"]):
        return f"needs mu >= {sticking_ratio(p['width'], p['height']):.4g} to stick"
    if housner_ratio(p["width"], p["height"]) < 0:
        return "needs width <= sqrt(2) height: a wider block pushes its pivot into the floor"
    return None


def _one_contact(p: Params) -> np.ndarray:
    """The lectures' frictionless one-contact formulas (after eq. 24), L = width, l = height."""
    L2, l2, e = p["width"] ** 2, p["height"] ** 2, p["e"]
    vx, vy, omega = pre_impact_velocity(p)
    return np.array(
        [
            vx,
            (2 * L2 - l2 - 2 * e * (L2 + l2)) / (l2 + 4 * L2) * vy,
            (l2 - 2 * L2 - 6 * e * L2) / (l2 + 4 * L2) * omega,
        ]
    )


def _one_contact_holds(p: Params) -> str | None:
    if p["mu"] != 0:
        return "needs mu = 0 (the formulas keep the tangential velocity)"
    if p["height"] < math.sqrt(2) * p["width"]:
        return "needs height >= sqrt(2) width: otherwise the pivot is pushed into the floor"
    return None


@functools.lru_cache(maxsize=64)
def _geometry(width: float, height: float, mass: float, e: float, mu: float) -> Geometry:
    """The block as a box on a planar joint in the x-y plane, on the floor plane y = 0.

    The box is as deep (along z) as it is wide; its bottom corners touch the floor along the
    lines ``x = -+width/2``, and the contact points are their middles, in the plane of motion.
    Cached: a geometry is immutable, and a sweep of omega keeps it.
    """
    block = solid_box("block", mass, (width / 2, height / 2, width / 2), (0, height / 2, 0))
    floor = plane("floor", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    x, y = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    pairs = [
        ContactPair("block", "floor", (corner, 0.0, 0.0), y, (x,), e, mu)
        for corner in (-width / 2, width / 2)
    ]
    joints = [Joint("planar", "block", (0.0, 0.0, 1.0)), Joint("fixed", "floor")]
    return geometry([block, floor], joints, pairs, [(0, 0), (0, 1), (0, 5)])


class RockingBlock(Case):
    """A rectangular block, rocking on its right corner, lands on its left corner."""

    name = "rocking_block"
    summary = "rectangular block landing on its other corner (Housner 1963; Brogliato 2010)"
    params = (
        _specs.positive("width", 0.5, "block width (L in the lectures)", "m"),
        _specs.positive("height", 1.0, "block height (l in the lectures)", "m"),
        _specs.mass(10.0, "block mass"),
        _specs.positive(
            "omega",
            1.0,
            "pre-impact angular velocity about the right (pivot) corner, counter-clockwise: "
            "the left corner comes down",
            "rad/s",
        ),
        _specs.restitution(0.0, "Newton's restitution coefficient of both corners"),
        _specs.friction(0.5, "Coulomb friction coefficient of both corners"),
    )
    # A frictional impact of a box at two corners: the engines' cost per impact with friction.
    bench_roles = ("engine_cost",)
    requires = Tags(friction=True, several_contacts=True)
    ground_truth = GroundTruth(
        why="Housner's plastic impact is exact where its premises hold (e = 0, the landing "
        "corner sticks, the pivot lifts off: width <= sqrt(2) height): angular momentum about "
        "the landing corner is kept. Elsewhere compliant contact with friction at both "
        "corners, integrated in time (Hunt-Crossley with Flores' damping from e, tangential "
        "springs and Coulomb sliders, plastic corners at e = 0), which decides whether the "
        "pivot lifts off and the landing corner slides; with tangential springs much stiffer "
        "than the normal ones its plastic corners reach Housner's ratio",
        reference="Housner",
        law="compliant",
        options={"tol": 1e-10},
    )
    # Both laws hold the landing corner with Newton's normal rule and Coulomb's friction on the
    # post-impact slip; without friction whittaker is moreau's unilateral law.
    references = tuple(
        Reference(name, source, law, v_plus, condition=condition)
        for name, source, v_plus, condition in (
            (
                "Housner",
                "Housner 1963: angular momentum about the landing corner, "
                "omega+/omega- = 1 - 3/2 sin^2(alpha)",
                _housner,
                _housner_holds,
            ),
            (
                "one contact",
                "Brogliato 2010, after eq. (24): frictionless Newton rule at the landing corner "
                "(the omega+ formula derived again)",
                _one_contact,
                _one_contact_holds,
            ),
        )
        for law in ("moreau", "whittaker")
    )
    # "wide block": width > sqrt(2) height, outside Housner's premise; the corners' kinetic
    # angle is 114 degrees, so with e > 0 the rigid laws are discontinuous in the initial gaps
    # there (Paoli's condition), which the continuity check reports.
    examples = {
        "default": {},
        "elastic frictionless": {"e": 1.0, "mu": 0.0, "height": 1.5},
        "slipping": {"width": 0.8, "height": 1.0, "mu": 0.1},
        "wide block": {"width": 2.0, "height": 1.0, "e": 0.5, "mu": 0.8},
    }

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        mass, width, height = params["mass"], params["width"], params["height"]
        tangent = planar_tangent(FLOOR)
        points = corners(width, height)
        contact = Contact(e=params["e"], mu=params["mu"])
        return ImpactProblem(
            M=np.diag([mass, mass, mass * (width**2 + height**2) / 12.0]),
            Wn=np.column_stack([planar_column(r, FLOOR) for r in points]),
            Wt=np.column_stack([planar_column(r, tangent) for r in points]),
            v=pre_impact_velocity(params),
            contacts=[contact, contact],
            bodies={"block": (0, 1, 2)},
            geometry=_geometry(width, height, mass, params["e"], params["mu"]),
        )

    def coordinates(self, params: Params) -> list[str]:
        """Centre-of-mass velocity and angular velocity of the block."""
        return ["vx [m/s]", "vy [m/s]", "omega [rad/s]"]

    def momentum_axes(self, params: Params) -> np.ndarray | None:
        """Without friction the horizontal momentum is kept."""
        return np.array([[1.0, 0.0, 0.0]]) if params["mu"] == 0 else None


CASES.register(RockingBlock())


def omega_ratio(trial: Trial) -> float:
    """``omega+ / omega-``."""
    return float(trial.outcome.v_plus[2] / trial.problem.v[2])


def housner(trial: Trial) -> float:
    """Housner's ``omega+ / omega-`` at the trial's width and height."""
    return housner_ratio(trial.params["width"], trial.params["height"])


def from_housner(trial: Trial) -> float:
    """``omega+ / omega-`` minus Housner's."""
    return omega_ratio(trial) - housner(trial)


# The studies this scene declares, as data.
RockingBlock.studies = (
    {
        "shape": "sweep",
        "name": "rocking_block",
        "title": "rocking block: omega+/omega- against Housner's 1 - 3/2 sin^2(alpha), e = 0, "
        "height 1 m, width 0.1 to 10 m (so width/height 0.1 to 10), mu in {0, 1}; Housner's "
        "formula holds for width <= sqrt(2) height (wider, the pivot cannot lift off)",
        "laws": "every",
        "grid": {"mu": [0.0, 1.0], "width": np.logspace(-1.0, 1.0, 5).tolist()},
        "params": {"height": 1.0, "e": 0.0},
        "measures": {"omega_ratio": omega_ratio, "housner": housner, "difference": from_housner},
        "axes": ("width", "omega_ratio", "difference"),
        "units": {"omega_ratio": "", "difference": ""},
        "full": {"grid": {"mu": [0.0, 1.0], "width": np.logspace(-1.0, 1.0, 17).tolist()}},
    },
    {"shape": "large_friction"},
    {"shape": "speed_accuracy"},
)
