"""A pencil falling tip first onto a table: Jia's bouncing-pencil example.

Generalized coordinates: the velocity of the pencil's centre of mass (vx, vy, vz, m/s) and its
angular velocity (wx, wy, wz, rad/s), world frame, x and y along the table, z up. The pencil is
a uniform solid: a circular cylinder (radius ``radius``, length ``cylinder_length``) ending in a
cone (height ``cone_height``) whose apex touches the table; one spatial contact at the apex,
normal z, tangents x and y. Its axis lies in the x-z plane at ``tilt`` above the table, the
upper end towards +x: ``a = (cos tilt, 0, sin tilt)`` from the apex.

The scene declares no geometry, so the engines refuse it: at the defaults the cone's base rim
lies h2 sin(tilt) - r cos(tilt) = -67 mm below the table, so no solid of these proportions
touches the table at its apex alone.

Parameters (defaults are the talk's values where it gives them): ``mass`` 1 kg, ``radius`` 1 m,
``cylinder_length`` (h1) 3 m, ``cone_height`` (h2) 0.5 m, ``e`` 0.5 (energetic), ``mu`` 0.8,
``tangential_stiffness_ratio`` (eta0^2) 1.2, ``velocity`` 5 (cos 30°, 0, -sin 30°) m/s and
``angular_velocity`` (1, 0.5, 0.5) rad/s before the impact. The pencil's orientation did not
survive the extraction of the talk; ``tilt`` 60° reads a stray "3" of the slide as pi/3.

Invariant: ``momentum_axes`` is the angular momentum about the contact point. Because the apex
lies on the pencil's axis of symmetry, an impulse ``I`` at the apex changes the angular velocity
by ``J^-1 (rho x I)``, perpendicular to both the axis and ``I``, whatever the shape's proportions.

Source: Y.-B. Jia, *Simultaneous three-dimensional impacts with friction and compliance* (talk,
2012), "Bounce of a pencil", and Jia, IJRR 32(1) 2013. The talk reports after the impact
V = (0.3681, 0.3908, 3.0302), w = (0.2362, 1.8021, 0.5) and the impulse (3.962, 0.3908, 5.5302)
at the end of its impulse curve (x reversed): V and the impulse agree with m dV, but the change of
the angular velocity, (-0.7638, 1.3021, 0), has a component 3.5 (cosine 0.34) along the
impulse, which no impulse at an apex on the axis of symmetry can produce. The analytic reference
below is the frictionless bounce.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases.bouncing_ball import (
    COORDINATES,
    TANGENTIAL_COMPLIANCE,
    body_on_table,
    contact_point_momentum,
    contact_specs,
    frictionless_reference,
    vector_spec,
)
from lawbench.core.case import CASES, Case, Params, exactly
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags

SPEED = 5.0
DESCENT = math.pi / 6


def pencil_geometry(params: Params) -> tuple[np.ndarray, np.ndarray]:
    """Inertia about the centre of mass (3, 3) and the apex from it (3,), world frame."""
    mass, r = params["mass"], params["radius"]
    h1, h2 = params["cylinder_length"], params["cone_height"]
    tilt = math.radians(params["tilt"])
    axis = np.array([math.cos(tilt), 0.0, math.sin(tilt)])
    cylinder, cone = mass * h1 / (h1 + h2 / 3), mass * (h2 / 3) / (h1 + h2 / 3)
    # Centres of mass along the axis, from the apex.
    cylinder_at, cone_at = h2 + h1 / 2, 3 * h2 / 4
    centre = (cylinder * cylinder_at + cone * cone_at) / mass
    axial = cylinder * r**2 / 2 + 3 * cone * r**2 / 10
    transverse = (
        cylinder * (3 * r**2 + h1**2) / 12
        + cylinder * (cylinder_at - centre) ** 2
        + cone * (3 * r**2 / 20 + 3 * h2**2 / 80)
        + cone * (cone_at - centre) ** 2
    )
    inertia = transverse * np.eye(3) + (axial - transverse) * np.outer(axis, axis)
    return inertia, -centre * axis


class BouncingPencil(Case):
    """A pencil falling tip first onto a table (Jia 2012)."""

    name = "bouncing_pencil"
    summary = "pencil falling tip first onto a table (Jia's bouncing-pencil example)"
    params = (
        vector_spec(
            "velocity",
            [SPEED * math.cos(DESCENT), 0.0, -SPEED * math.sin(DESCENT)],
            "velocity of the centre of mass before impact",
            "m/s",
        ),
        vector_spec("angular_velocity", [1.0, 0.5, 0.5], "angular velocity before impact", "rad/s"),
        _specs.mass(1.0, "mass of the pencil"),
        _specs.positive("radius", 1.0, "radius of the cylinder and the cone's base", "m"),
        _specs.positive("cylinder_length", 3.0, "length of the cylinder (h1)", "m"),
        _specs.positive("cone_height", 0.5, "height of the cone at the tip (h2)", "m"),
        Spec(
            "tilt",
            60.0,
            "angle between the pencil's axis and the table",
            unit="deg",
            low=0.0,
            high=90.0,
            low_open=True,
        ),
        *contact_specs(0.5, 0.8, 1.2),
    )
    requires = Tags(friction=True, spatial=True)
    ground_truth = TANGENTIAL_COMPLIANCE
    references = ()  # set after the class: the reference builds the scene itself
    examples = {
        "default": {},
        "steep": {"tilt": 85.0, "angular_velocity": [0.0, 0.0, 0.0]},
        "frictionless": {"mu": 0.0},
    }

    def _check(self, params: dict[str, Any]) -> None:
        exactly(params, "velocity", 3, "component")
        exactly(params, "angular_velocity", 3, "component")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        inertia, apex = pencil_geometry(params)
        return body_on_table(
            params["mass"],
            inertia,
            apex,
            np.asarray(params["velocity"]),
            np.asarray(params["angular_velocity"]),
            params,
            "pencil",
        )

    def coordinates(self, params: Params) -> list[str]:
        """Velocity of the centre of mass and angular velocity, world frame."""
        return list(COORDINATES)

    def momentum_axes(self, params: Params) -> np.ndarray:
        """Angular momentum about the contact point, kept by any impulse applied there."""
        return contact_point_momentum(pencil_geometry(params)[1])


BouncingPencil.references = (frictionless_reference(BouncingPencil),)
CASES.register(BouncingPencil())
# The studies this scene declares, as data.
BouncingPencil.studies = ({"shape": "large_friction"}, {"shape": "speed_accuracy"})
