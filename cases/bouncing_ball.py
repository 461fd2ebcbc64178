"""A spinning ball bouncing on a table: Jia's bouncing-ball example.

Generalized coordinates: the velocity of the ball's centre (vx, vy, vz, m/s) and its angular
velocity (wx, wy, wz, rad/s), both in the world frame: x and y along the table, z up, right-hand
rule for the spin. The ball (solid, uniform: inertia ``2/5 m r^2``) touches the table at
``(0, 0, -r)`` from its centre; one spatial contact, normal z, tangents x and y. Geometry, for
the engines: the ball on a free joint, the table the fixed plane z = 0.

Parameters (defaults are the talk's values): ``velocity`` (1, 0, -5) m/s and
``angular_velocity`` (0, 2, 0) rad/s before the impact; ``radius`` 1 m; ``mass`` 1 kg; ``e`` 0.5
(energetic restitution); ``mu`` 0.4; ``tangential_stiffness_ratio`` Jia's eta0^2 (normal over
tangential stiffness) 17/14, Mindlin's ``(2 - nu) / (2 (1 - nu))`` for Poisson's ratio 0.3,
which the talk writes as 1.2.

Invariant: any impulse applied at the contact point keeps the ball's angular momentum about
that point, ``L = I w + r e_z x m V``; ``momentum_axes`` gives it to the momentum check.

Source: Y.-B. Jia, *Simultaneous three-dimensional impacts with friction and compliance* (talk,
2012), "Bouncing ball", and Jia, IJRR 32(1) 2013. The talk reports after the first bounce
V = (0.570982, 0, 2.5) and w = (0, 1.92746, 0). Only vz = 2.5 is consistent with the stated
initial state: a sphere's normal and tangential directions are decoupled, so vz+ = -e vz- for
any friction. The tangential pair breaks the invariant above (L_y = I wy + m r vx is 1.8 before,
1.341966 after), and with the right-hand spin (0, 2, 0) the contact point slips at
vx - r wy = -1 m/s, so friction must raise vx, not lower it. The talk's appendix writes
``w = w0 + 5 / (2 m r) z x I``, the right-hand rule with the spin's sign reversed; read that way
(example "talk's spin sense", angular_velocity (0, -2, 0) here) the initial slip is +3 m/s, vx
falls, and the invariant holds when wy after is 0.92746 in the talk's sense (-0.92746 here),
one unit below the talk's 1.92746. The analytic reference below is the frictionless bounce.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._friction import springs_with_friction
from lawbench.cases._geometry import geometry, plane, solid_sphere
from lawbench.core.case import CASES, Case, Params, Reference, exactly
from lawbench.core.geometry import ContactPair, Geometry, Joint
from lawbench.core.problem import MINDLIN_RATIO, Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.numerics.rigid import spatial_column

# Jia's scenes are stated in his model: its tangential compliance at the scene's eta0^2.
TANGENTIAL_COMPLIANCE = springs_with_friction(
    "the tangential spring's stiffness ratio eta0^2 is a parameter of the scene, which rigid "
    "Coulomb laws do not read"
)
COORDINATES = ["vx [m/s]", "vy [m/s]", "vz [m/s]", "wx [rad/s]", "wy [rad/s]", "wz [rad/s]"]


def body_on_table(
    mass: float,
    inertia: np.ndarray,
    contact: np.ndarray,
    velocity: np.ndarray,
    angular_velocity: np.ndarray,
    params: Params,
    name: str,
    geometry: Geometry | None = None,
) -> ImpactProblem:
    """A rigid body touching the table z = 0 at one point: the spatial impact problem.

    Parameters
    ----------
    mass : float
        Mass (kg).
    inertia : array (3, 3)
        Inertia about the centre of mass in the world frame (kg m^2).
    contact : array (3,)
        Contact point from the centre of mass (m).
    velocity, angular_velocity : arrays (3,)
        Pre-impact velocity of the centre (m/s) and angular velocity (rad/s).
    params : mapping
        With ``e``, ``mu`` and ``tangential_stiffness_ratio``.
    name : str
        The body's name.
    geometry : Geometry or None
        What the body and the table look like, for the engines.
    """
    Wn = spatial_column(contact, np.array([0.0, 0.0, 1.0]))[:, None]
    Wt = np.column_stack([spatial_column(contact, t) for t in np.eye(3)[:2]])
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[3:, 3:] = inertia
    return ImpactProblem(
        M=M,
        Wn=Wn,
        Wt=Wt,
        v=np.concatenate([velocity, angular_velocity]),
        contacts=[
            Contact(
                e=params["e"],
                mu=params["mu"],
                tangential_stiffness_ratio=params["tangential_stiffness_ratio"],
            )
        ],
        bodies={name: range(6)},
        geometry=geometry,
    )


@functools.lru_cache(maxsize=64)
def _geometry(mass: float, radius: float, e: float, mu: float) -> Geometry:
    """The ball on a free joint, touching the table z = 0 at the origin.

    Cached: a geometry is immutable, and a sweep of the velocities keeps it.
    """
    ball = solid_sphere("ball", mass, radius, (0.0, 0.0, radius))
    table = plane("table", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    contact = ContactPair("ball", "table", (0, 0, 0), (0, 0, 1), ((1, 0, 0), (0, 1, 0)), e, mu)
    joints = [Joint("free", "ball"), Joint("fixed", "table")]
    return geometry([ball, table], joints, [contact], [(0, k) for k in range(6)])


def contact_point_momentum(contact: np.ndarray) -> np.ndarray:
    """Axes (3, 6) of the angular momentum about the contact point: ``axes @ M @ v``."""
    x, y, z = -np.asarray(contact, dtype=float)
    # L = I w + rho x (m V), rho from the contact point to the centre of mass.
    skew = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.hstack([skew, np.eye(3)])


def frictionless_bounce(problem: ImpactProblem, e: float) -> np.ndarray:
    """Post-impact velocity of a frictionless bounce: ``un+ = -e un-`` (all laws agree)."""
    G = problem.delassus[0, 0]
    return problem.v + problem.solve_mass(problem.Wn[:, 0]) * (-(1 + e) * problem.un[0] / G)


def frictionless(params: Params) -> str | None:
    """The condition of the frictionless reference."""
    return None if params["mu"] == 0 else "needs mu = 0"


def frictionless_reference(case: type[Case]) -> Reference:
    """The frictionless bounce of a body on the table, as the reference of ``case``."""
    return Reference(
        "frictionless bounce",
        "un+ = -e un- at one frictionless contact (energetic = kinematic coefficient)",
        "jia",
        lambda p: frictionless_bounce(case().build(**p), p["e"]),
        condition=frictionless,
    )


def vector_spec(name: str, default: list[float], doc: str, unit: str) -> Spec:
    """A three-component parameter."""
    return Spec(name, default, doc, unit=unit, kind="floats")


def contact_specs(e: float, mu: float, ratio: float) -> tuple[Spec, ...]:
    """The contact parameters ``e``, ``mu`` and ``tangential_stiffness_ratio``."""
    return (
        _specs.restitution(e, "energetic restitution coefficient"),
        _specs.friction(mu),
        Spec(
            "tangential_stiffness_ratio",
            ratio,
            "Jia's eta0^2: normal (compression) over tangential stiffness",
            low=0.0,
            low_open=True,
        ),
    )


class BouncingBall(Case):
    """A spinning solid ball bouncing on a table (Jia 2012)."""

    name = "bouncing_ball"
    summary = "spinning ball bouncing on a table (Jia's bouncing-ball example)"
    params = (
        vector_spec("velocity", [1.0, 0.0, -5.0], "velocity of the centre before impact", "m/s"),
        vector_spec("angular_velocity", [0.0, 2.0, 0.0], "angular velocity before impact", "rad/s"),
        _specs.positive("radius", 1.0, "radius of the ball", "m"),
        _specs.mass(1.0, "mass of the ball"),
        *contact_specs(0.5, 0.4, MINDLIN_RATIO),
    )
    requires = Tags(friction=True, spatial=True)
    ground_truth = TANGENTIAL_COMPLIANCE
    references = ()  # set after the class: the reference builds the scene itself
    examples = {
        "default": {},
        "talk's spin sense": {"angular_velocity": [0.0, -2.0, 0.0]},
        "skewed spin": {"angular_velocity": [6.0, 6.0, 0.0]},
        "frictionless": {"mu": 0.0},
        "elastic, rough": {"e": 1.0, "mu": 2.0},
    }

    def _check(self, params: dict[str, Any]) -> None:
        exactly(params, "velocity", 3, "component")
        exactly(params, "angular_velocity", 3, "component")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        mass, radius = params["mass"], params["radius"]
        return body_on_table(
            mass,
            0.4 * mass * radius**2 * np.eye(3),
            np.array([0.0, 0.0, -radius]),
            np.asarray(params["velocity"]),
            np.asarray(params["angular_velocity"]),
            params,
            "ball",
            _geometry(mass, radius, params["e"], params["mu"]),
        )

    def coordinates(self, params: Params) -> list[str]:
        """Velocity of the centre and angular velocity, world frame."""
        return list(COORDINATES)

    def momentum_axes(self, params: Params) -> np.ndarray:
        """Angular momentum about the contact point, kept by any impulse applied there."""
        return contact_point_momentum(np.array([0.0, 0.0, -params["radius"]]))


BouncingBall.references = (frictionless_reference(BouncingBall),)
CASES.register(BouncingBall())
# The studies this scene declares, as data.
BouncingBall.studies = ({"shape": "large_friction"}, {"shape": "speed_accuracy"})
