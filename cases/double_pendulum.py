"""A double pendulum whose free end strikes a rough floor (Kane and Levinson's example).

Generalized coordinates: the angles ``theta1``, ``theta2`` of the two links from the downward
vertical (counter-clockwise positive); the velocities are their rates ``omega1``, ``omega2``
(rad/s). Link 1 turns about a fixed pin O, link 2 about a pin at the far end of link 1; both
are uniform slender rods. The free end of link 2, at
``l1 (sin theta1, -cos theta1) + l2 (sin theta2, -cos theta2)`` from O, touches a horizontal
floor (normal ``(0, 1)``, tangent ``(1, 0)``): its gap rate is
``l1 omega1 sin theta1 + l2 omega2 sin theta2`` and its slip
``l1 omega1 cos theta1 + l2 omega2 cos theta2``. Gravity and the pins' friction play no part
in the impact.
The scene declares no geometry, so the engines refuse it: link 2 turns on a pin carried by
link 1, and a geometry's joints hold a body to the world (free, planar, hinge, slide, fixed).

Parameters (defaults): ``lengths`` (1, 1) m, ``masses`` (1, 1) kg, ``angles`` (60, 45)
degrees, ``omegas`` (0, -4) rad/s, ``e`` 0.9, ``mu`` 0.5.

Source: T.R. Kane and D.A. Levinson, *Dynamics: Theory and Applications* (McGraw-Hill, 1985):
Newton's coefficient with Coulomb friction at the impulse level (Whittaker's law) can end a
frictional impact of this pendulum with more kinetic energy than it started with; also
J.B. Keller, "Impact with friction", J. Appl. Mech. 53 (1986) 1-4, and W.J. Stronge,
*Impact Mechanics* (2000); Brogliato, *An introduction to impact dynamics* (2010), remark
after equation (9). The published numbers of the example could not be checked here, so the
defaults are a documented choice in the regime where that law is known to gain energy:
``e`` close to 1, moderate ``mu``, and strong normal-tangential coupling at the free end (the
links inclined, the lower one swinging into the floor while sliding). There, with the friction
opposing the post-impact slip, the slip reverses: the energy change is +11 % of the pre-impact
energy (the tests solve that law by hand).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._friction import springs_with_friction
from lawbench.core.case import CASES, Case, Params, exactly
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.numerics.rigid import planar_column, planar_tangent

FLOOR = np.array([0.0, 1.0])


def _direction(angle: float) -> np.ndarray:
    """Unit vector along a link at ``angle`` from the downward vertical."""
    return np.array([math.sin(angle), -math.cos(angle)])


def link_jacobians(p: Params) -> list[np.ndarray]:
    """Map ``(omega1, omega2)`` to each link's ``(vx, vy, omega)`` of its centre of mass."""
    (l1, l2), angles = p["lengths"], [math.radians(a) for a in p["angles"]]
    d1, d2 = (_direction(a) for a in angles)
    # d/dt of l d(angle) is l omega (cos, sin) = l omega (-d_y, d_x).
    turn1, turn2 = np.array([-d1[1], d1[0]]), np.array([-d2[1], d2[0]])
    link1 = np.column_stack([np.append(l1 / 2 * turn1, 1.0), [0.0, 0.0, 0.0]])
    link2 = np.column_stack([np.append(l1 * turn1, 0.0), np.append(l2 / 2 * turn2, 1.0)])
    return [link1, link2]


def free_end(p: Params) -> np.ndarray:
    """The free end of link 2 relative to that link's centre of mass."""
    return p["lengths"][1] / 2 * _direction(math.radians(p["angles"][1]))


def mass_matrix(p: Params) -> np.ndarray:
    """Kinetic metric in ``(omega1, omega2)``: sum of the links' ``J.T diag(m, m, I) J``."""
    M = np.zeros((2, 2))
    for jacobian, mass, length in zip(link_jacobians(p), p["masses"], p["lengths"], strict=True):
        M += jacobian.T @ np.diag([mass, mass, mass * length**2 / 12]) @ jacobian
    return M


class DoublePendulum(Case):
    """Two uniform links pinned at O; the free end strikes a rough floor."""

    name = "double_pendulum"
    summary = "double pendulum striking a rough floor (Kane and Levinson 1985)"
    params = (
        _specs.positives("lengths", [1.0, 1.0], "lengths of links 1 and 2", "m"),
        _specs.positives("masses", [1.0, 1.0], "masses of links 1 and 2", "kg"),
        Spec(
            "angles",
            [60.0, 45.0],
            "angles of links 1 and 2 from the downward vertical, counter-clockwise",
            unit="deg",
            kind="floats",
            low=-180.0,
            high=180.0,
        ),
        Spec(
            "omegas",
            [0.0, -4.0],
            "pre-impact angular velocities of links 1 and 2, counter-clockwise",
            unit="rad/s",
            kind="floats",
        ),
        _specs.restitution(0.9),
        _specs.friction(0.5),
    )
    requires = Tags(friction=True)
    ground_truth = springs_with_friction(
        "Kane and Levinson's pendulum is the classic case where an impulse-level law gains "
        "energy, which the springs cannot"
    )
    examples = {
        "default": {},
        "plastic": {"e": 0.0},
        "hanging": {"angles": [10.0, -20.0], "omegas": [1.0, 3.0], "e": 0.5, "mu": 0.2},
        "frictionless": {"mu": 0.0},
    }

    def _check(self, params: dict[str, Any]) -> None:
        for name in ("lengths", "masses", "angles", "omegas"):
            exactly(params, name, 2, "link")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        body = link_jacobians(params)[1]
        r = free_end(params)
        return ImpactProblem(
            M=mass_matrix(params),
            Wn=(body.T @ planar_column(r, FLOOR))[:, None],
            Wt=(body.T @ planar_column(r, planar_tangent(FLOOR)))[:, None],
            v=np.asarray(params["omegas"], dtype=float),
            contacts=[Contact(e=params["e"], mu=params["mu"])],
            bodies={"pendulum": (0, 1)},
        )

    def coordinates(self, params: Params) -> list[str]:
        """Angular velocities of the two links."""
        return ["omega1 [rad/s]", "omega2 [rad/s]"]


CASES.register(DoublePendulum())

# The studies this scene declares, as data.
DoublePendulum.studies = (
    {"shape": "energy_map", "x": ("e", 0.0, 1.0), "y": ("mu", 0.0, 1.5)},
    {"shape": "large_friction"},
    {"shape": "speed_accuracy"},
)
