"""PyBullet (Bullet Physics) as an impact law: the scene built in Bullet and stepped through.

Source: Bullet Physics through PyBullet 3.2 (E. Coumans and Y. Bai, PyBullet Quickstart Guide,
https://docs.google.com/document/d/10sXEhzFRSnvFcl3XxNGhnD4N2SedqwdAvK3dsihxVUA: stepSimulation,
changeDynamics, setPhysicsEngineParameter, getContactPoints); the solver is Bullet's sequential
impulse method (projected Gauss-Seidel on the contact impulses of each step,
btSequentialImpulseConstraintSolver), and each contact's coefficients are those of its two
bodies combined (btManifoldResult.cpp: calculateCombinedRestitution and
calculateCombinedFriction, the products of the bodies' coefficients, friction clamped to 10).

Conventions: the common stepping rule of the engine laws (`lawbench.laws.engines._base`);
Bullet's positions and velocities are the bodies' centres of mass and its angular velocities
are in the world frame, as the geometry's. A contact point reports the forces of the step just
taken (getContactPoints): normalForce along contactNormalOnB (from B to A) and lateralFriction1
and 2 along lateralFrictionDir1 and 2, together the force on A; a step's impulse is that force
times the step. Gravity and Bullet's velocity damping (linearDamping, angularDamping, 0.04 by
default) are off: they act in flight, not in the impact. Solves share a client per thread and
setting (a client takes 50 ms to connect), which sorts its overlapping pairs
(deterministicOverlappingPairs) so that the solver meets the contacts in the same order whatever
the client solved before. Joints: a free joint is a Bullet base with mass, a fixed one a base
without; Bullet has no planar joint, so a planar body is a free one whose contact forces lie in
its plane of motion (the rocking block's contact points lie in the plane through its centre of
mass, so its motion stays planar); a hinge or a slide is a link of a fixed base without
shape, its revolute or prismatic joint at the hinge's anchor (at the body's centre of mass for a
slide) and its velocity motor off (PyBullet's joints are motorized by default).

Settings (option ``settings``):

- ``default``, what a user gets: Bullet's defaults (setPhysicsEngineParameter untouched but the
  step, 1/240 s, the documented default, and the order of the pairs), and each body given the
  scene's coefficients as the Quickstart describes them, a property of the body (changeDynamics'
  restitution and lateralFriction; a body in contacts of different coefficients takes their
  mean). Bullet then
  multiplies the two bodies' coefficients: a contact of restitution e and friction mu acts with
  e^2 and mu^2. Bullet's box-plane contact manifold gains one point per step, so a box lands on
  one corner point first. Bullet has no ellipsoid: an ellipsoid is the convex hull of points of
  its surface (`ellipsoid_points`).
- ``tuned``, as rigid and faithful to e and mu as Bullet allows: contactSlop 0 (the slop lets a
  closed contact approach at slop/dt, swallowing the restitution as the step shrinks), erp,
  contactERP and frictionERP 0 (the error reduction pushes penetrating bodies apart with
  velocity, which creates energy), restitutionVelocityThreshold 0 (restitution at every
  speed), 1000 solver iterations with solverResidualThreshold 0 (the solver stops at neither),
  a step of 1e-4 s, and per-body coefficients whose products are the scene's (where a fixed body
  takes part, it keeps 1 and the moving body the scene's value); a box or an ellipsoid touches
  through small spheres (radius `CORNER_RADIUS` of its smallest size) at its declared contact
  points.
  Bullet's restitution is then Moreau's per-contact rule on each step's velocities,
  ``0 <= un+ + e un- _|_ Pn >= 0``, with Coulomb's friction on the impulses in its circular
  cone (enableConeFriction, on by default; off, a pyramid lets |Pt| reach sqrt(2) mu Pn).

Measured against Moreau's law, relative to the largest pre-impact velocity: tuned, 1e-15 on the
chains, the sphere on a wall (with and without spin, sticking or sliding) and the rocking block.
At the defaults the elastic three-ball chain ends at (-0.331, 0.665, 0.665), keeping 99.5 % of
its energy; the sphere on a wall rebounds at 0.64 of its approach where e = 0.8, and slides with
mu^2; the rocking block (e = 0, mu = 0.5, which sticks in Moreau's law) slides with mu^2 = 0.25
and lands on one corner point, 34 % off.
"""

from __future__ import annotations

import functools
import threading
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np

from lawbench.checks.regions import (
    coupled_friction,
    oblique_contacts,
    option,
    separating_contact,
)
from lawbench.core.errors import NotApplicable
from lawbench.core.geometry import Body, rotation_matrix
from lawbench.core.law import LAWS
from lawbench.core.verdicts import Claim, Region
from lawbench.laws._claims import RIGID_DISPERSION
from lawbench.laws.engines._base import (
    EngineLaw,
    Force,
    Scene,
    Start,
    corner,
    engine_options,
    pair_of,
    quietly,
    require,
)
from lawbench.laws.engines._bullet_coefficients import MAX_FRICTION, body_coefficients
from lawbench.laws.engines._bullet_coefficients import means as body_means
from lawbench.laws.engines._bullet_shapes import SIZES, ellipsoid_points
from lawbench.laws.engines._regions import (
    slopped,
)

require("pybullet")

_QUICKSTART = (
    "PyBullet Quickstart Guide (Coumans and Bai), "
    "https://docs.google.com/document/d/10sXEhzFRSnvFcl3XxNGhnD4N2SedqwdAvK3dsihxVUA"
)
_SOLVER = "Bullet's btSequentialImpulseConstraintSolver (https://github.com/bulletphysics/bullet3)"
_COMBINED = (
    "Bullet's btManifoldResult.cpp, calculateCombinedRestitution and calculateCombinedFriction "
    "(https://github.com/bulletphysics/bullet3)"
)
# The tuned engine parameters (setPhysicsEngineParameter).
TUNED = {
    "contactSlop": 0.0,
    "erp": 0.0,
    "contactERP": 0.0,
    "frictionERP": 0.0,
    "restitutionVelocityThreshold": 0.0,
    "numSolverIterations": 1000,
    "solverResidualThreshold": 0.0,
}
_NO_FORCE = np.zeros(3)


@functools.cache
def _bullet() -> ModuleType:
    """The pybullet module, imported on first use (it writes its build time to stderr)."""
    return quietly("pybullet")


# Each thread's PyBullet clients, one per setting: connecting a client costs some 50 ms, a
# thousand times a step, so a solve borrows its setting's client and leaves it as it found it.
_CLIENTS = threading.local()


@dataclass
class _Client:
    """A PyBullet client (DIRECT mode: in process, no window) and what solves leave in it.

    PyBullet keeps a collision shape once a body used it (removeCollisionShape refuses), so the
    shapes are kept by their description and used again; a plane body takes some 10 ms to make,
    so the planes stay too, moved where the next scene wants them.
    """

    id: int
    shapes: dict[tuple, int] = field(default_factory=dict)
    planes: list[int] = field(default_factory=list)


def _client(settings: str) -> _Client:
    """The PyBullet client of ``settings`` in this thread.

    Made on first use, with gravity off and, tuned, the `TUNED` parameters set.
    """
    clients = _CLIENTS.__dict__
    if settings not in clients:
        bullet = _bullet()
        client = bullet.connect(bullet.DIRECT)
        bullet.setGravity(0.0, 0.0, 0.0, physicsClientId=client)
        bullet.setPhysicsEngineParameter(deterministicOverlappingPairs=1, physicsClientId=client)
        if settings == "tuned":
            bullet.setPhysicsEngineParameter(physicsClientId=client, **TUNED)
        clients[settings] = _Client(client)
    return clients[settings]


def _widened(trial: Any) -> bool:
    """Whether a contact's friction at the defaults, its bodies' product, exceeds its mu.

    Each body carries the mean mu of its pairs (`_means`), and Bullet gives a contact the
    product of its two bodies' coefficients, at most `MAX_FRICTION`.
    """
    geometry = getattr(trial.problem, "geometry", None)
    if geometry is None:
        return False
    means = body_means(geometry, [pair.mu for pair in geometry.pairs])
    index = geometry.index
    return any(
        min(means[index[pair.a]] * means[index[pair.b]], MAX_FRICTION) > pair.mu
        for pair in geometry.pairs
    )


widened_cone = Region(
    "a contact's friction, the product of its two bodies' coefficients, exceeds its mu", _widened
)

# Bullet's contactSlop at PyBullet's defaults (m): the defaults' outcome is the one with
# setPhysicsEngineParameter(contactSlop=1e-5), not 1e-4 or 1e-6.
SLOP = 1e-5
# What Bullet's solver leaves of a contact's speed when it stops at its defaults (50 iterations,
# solverResidualThreshold 1e-7): 4.5e-6 measured on the falling rod with contactSlop 0, none
# with 1000 iterations and no threshold.
UNSOLVED = 1e-4

within_slop = slopped(SLOP, UNSOLVED)


class PyBullet(EngineLaw):
    """Bullet Physics through PyBullet: the scene stepped with Bullet's impulse solver."""

    name = "pybullet"
    summary = (
        "PyBullet (Bullet Physics): the scene's bodies stepped through the impact with Bullet's "
        "sequential-impulse solver, at its defaults or tuned"
    )
    source = f"Bullet Physics / PyBullet 3.2: {_QUICKSTART}; {_COMBINED}"
    steps = {"default": 1.0 / 240.0, "tuned": 1e-4}
    settings_words = {
        "default": "PyBullet at its defaults (coefficients multiplied)",
        "tuned": "PyBullet tuned (no slop, no error reduction, coefficients as given)",
    }
    separating_rule = (
        "Bullet's own: a closed contact that separates takes an impulse only where its "
        "neighbours' push makes it approach during a step"
    )
    options = engine_options(
        steps,
        "Bullet's defaults, step 1/240 s, each body given its contacts' e and mu (Bullet "
        "multiplies the two bodies')",
        "contactSlop, erp, contactERP, frictionERP and restitutionVelocityThreshold 0, 1000 "
        "solver iterations, step 1e-4 s, per-body coefficients whose products are the scene's, "
        "boxes and ellipsoids touching through small spheres at their contact points",
    )
    findings = (
        RIGID_DISPERSION,
        Claim(
            "continuity",
            oblique_contacts,
            f"Paoli 2005; Brogliato 2010, kinetic angle and continuity; {_QUICKSTART}",
            "each step solves its contacts as impulses on the velocities, a rigid law: where a "
            "gap closes within the impact the contacts are met one after the other, and the two "
            "closing orders disagree at a kinetic angle other than 90 degrees (tuned, the "
            "three-ball chain goes from Moreau's (-1/3, 2/3, 2/3) to Newton's cradle (0, 0, 1) "
            "when contact 1 starts 1e-6 m open)",
            (("three_ball_chain", "default"),),
        ),
        *(
            Claim(
                check,
                separating_contact,
                f"Brogliato 2010, Moreau's law; {_SOLVER}",
                "Bullet restitutes each contact on its own from the velocities before the step, "
                "0 <= un+ + e un- _|_ Pn >= 0 with no restitution on a separating contact: "
                "Moreau's unilateral law, which gains Pn un- / 2 where a contact that separates "
                "is pushed back by its neighbours (+8 % on the three-ball chain)",
                (("three_ball_chain", "separating contact"),),
            )
            for check in ("energy_gain", "energy_kept")
        ),
        Claim(
            "energy_kept",
            option("settings", "default"),
            f"{_QUICKSTART}: contactSlop, erp, contactERP",
            "at its defaults Bullet lets a closed contact approach by its contact slop within a "
            "step and pushes overlapping bodies apart by its error reduction, so an elastic "
            "impact does not keep its energy: the three-ball chain keeps 99.5 % at 1/240 s, 81 % "
            "at 1e-4 s and a third (the plastic outcome) at 1e-5 s; the elastic rocking block "
            "keeps 88 %, its box landing on one point of its contact manifold, off its plane",
            (("three_ball_chain", "default"),),
        ),
        Claim(
            "energy_gain",
            coupled_friction,
            f"Kane and Levinson 1985; Brogliato 2010, eqs. (6)-(9); {_SOLVER}",
            "each step restitutes the contact by Newton's rule with Coulomb's friction on the "
            "slip after the step, at one contact Whittaker's law (Brogliato 2010, eq. 8): where "
            "inertia couples the normal and tangential directions the slip can reverse and the "
            "impact end with more energy than it began with (Kane and Levinson's paradox; tuned, "
            "the rod of falling_rod's example 'energy gain', +1.5 %, Moreau's answer to 1e-12; "
            "at the defaults, with Bullet's e^2 and mu^2, the rod at 43 degrees with e = 0.9 and "
            "mu >= 0.64 gains 0.24 %, where Moreau's law at e = 0.81 and mu^2 gains 0.43 %)",
        ),
        Claim(
            "friction_cone",
            option("settings", "default") & widened_cone,
            f"{_QUICKSTART}: changeDynamics (restitution and lateralFriction are a body's); "
            f"{_COMBINED}",
            "at its defaults each body carries the scene's coefficients, and Bullet gives a "
            "contact the product of its two bodies' (e1 e2 and mu1 mu2, the friction at most "
            "10): a contact of e and mu acts with e^2 and mu^2, and where mu > 1 a sliding "
            "contact's impulse leaves the scene's cone (the sphere grazing a wall at 80 degrees "
            "with mu = 1.2 and e = 0 slides with |Pt| = 1.44 Pn)",
        ),
        Claim(
            "admissible",
            option("settings", "default") & within_slop,
            f"{_QUICKSTART}: setPhysicsEngineParameter (contactSlop, numSolverIterations, "
            f"solverResidualThreshold); {_SOLVER}",
            "at its defaults Bullet asks a contact only that its distance plus the contact slop "
            "(1e-5 m) stay positive after the step, so a closed contact may go on approaching at "
            "up to slop / dt, and its solver stops at 50 iterations or a residual of 1e-7: the "
            "falling rod grazing the floor at 1e-2 m/s with e = 0 leaves at un+ = -2.40e-3 m/s "
            "= -slop / dt at 1/240 s (-1.6e-6 with contactSlop 0, none with 1000 iterations and "
            "no threshold besides), and at 1e-4 m/s takes no impulse at all",
        ),
    )
    guarantees = (
        Claim(
            "energy_kept",
            option("settings", "tuned") & ~separating_contact,
            f"Brogliato 2010, Moreau's law; {_SOLVER}",
            "tuned, each step restitutes every approaching contact at un+ = -un- and holds the "
            "others at un+ >= 0, as Moreau's law does, which keeps the energy at e = 1",
        ),
    )

    def _open(self, start: Start) -> Scene:
        return _BulletScene(start, body_coefficients(start.geometry, start.tuned))


class _BulletScene(Scene):
    """The geometry built in a PyBullet client of its own (DIRECT mode, no window)."""

    def __init__(self, start: Start, coefficients: list[tuple[float, float]]) -> None:
        self.bullet, self.geometry, self.reach = _bullet(), start.geometry, start.reach
        self.client = _client(start.settings)
        # The scene's bodies in the geometry's order, and those it made (the others are planes
        # the client keeps); the link that carries each body's shape, -1 for a base.
        self.ids: list[int] = []
        self.made: list[int] = []
        self.links: dict[int, int] = {}
        try:
            self._build(start, coefficients)
        except BaseException:
            self.close()
            raise

    def _call(self, function: str, *args: Any, **kwargs: Any) -> Any:
        return getattr(self.bullet, function)(*args, physicsClientId=self.client.id, **kwargs)

    def _build(self, start: Start, coefficients: list[tuple[float, float]]) -> None:
        poses, velocities, tuned = start.poses, start.velocities, start.tuned
        self._call("setPhysicsEngineParameter", fixedTimeStep=start.dt)
        for k, body in enumerate(self.geometry.bodies):
            kind = self.geometry.joint(body.name).kind
            position, (w, *q) = poses[k]
            place = {"posObj": list(position), "ornObj": [*q, w]}
            if body.shape == "plane":
                uid = self._plane(sum(b.shape == "plane" for b in self.geometry.bodies[:k]))
                self._call("resetBasePositionAndOrientation", uid, **place)
            elif kind in ("hinge", "slide"):
                uid = self._jointed(body, poses[k], tuned)
                self.made.append(uid)
            else:
                mass = body.mass if kind != "fixed" else 0.0
                shape = self._shape(body, tuned)
                uid = self._call(
                    "createMultiBody",
                    mass,
                    shape,
                    basePosition=place["posObj"],
                    baseOrientation=place["ornObj"],
                )
                self.made.append(uid)
            self.ids.append(uid)
            self.links.setdefault(uid, -1)
            self._dynamics(uid, body, coefficients[k], velocities[k])
        self._only_declared_pairs()

    def _jointed(self, body: Body, pose: tuple[np.ndarray, tuple[float, ...]], tuned: bool) -> int:
        """A fixed base without shape and one link, ``body``, on a revolute or prismatic joint.

        The link's frame is the joint's, at the hinge's anchor (the body's centre for a slide),
        turned as the body; its centre of mass and its shape sit at the body's centre.
        """
        joint = self.geometry.joint(body.name)
        position, (w, *q) = pose
        R = rotation_matrix((w, *q))
        origin = np.asarray(joint.anchor if joint.kind == "hinge" else position)
        offset = R.T @ (np.asarray(position) - origin)
        kinds = {"hinge": self.bullet.JOINT_REVOLUTE, "slide": self.bullet.JOINT_PRISMATIC}
        uid = self._call(
            "createMultiBody",
            0.0,
            -1,
            basePosition=origin.tolist(),
            linkMasses=[body.mass],
            linkCollisionShapeIndices=[self._shape(body, tuned, offset)],
            linkVisualShapeIndices=[-1],
            linkPositions=[[0.0, 0.0, 0.0]],
            linkOrientations=[[*q, w]],
            linkInertialFramePositions=[offset.tolist()],
            linkInertialFrameOrientations=[[0.0, 0.0, 0.0, 1.0]],
            linkParentIndices=[0],
            linkJointTypes=[kinds[joint.kind]],
            linkJointAxis=[(R.T @ np.asarray(joint.axis)).tolist()],
        )
        self._call("setJointMotorControl2", uid, 0, self.bullet.VELOCITY_CONTROL, force=0.0)
        self.links[uid] = 0
        return uid

    def _plane(self, number: int) -> int:
        """The client's plane body ``number``, made when the client has no such plane yet."""
        planes = self.client.planes
        while len(planes) <= number:
            shape = self._shape(Body("plane", "plane", ()), False)
            planes.append(self._call("createMultiBody", 0.0, shape))
        return planes[number]

    def _dynamics(
        self, uid: int, body: Body, coefficients: tuple[float, float], velocity: np.ndarray
    ) -> None:
        """Coefficients, no damping, inertia and velocity of a body (fixed ones keep still).

        A link on a joint takes the joint's rate that gives it its velocity.
        """
        moving, link = self.geometry.moving(body.name), self.links[uid]
        restitution, friction = coefficients
        self._call(
            "changeDynamics",
            uid,
            link,
            restitution=restitution,
            lateralFriction=friction,
            linearDamping=0.0,
            angularDamping=0.0,
            jointDamping=0.0,
            **({"localInertiaDiagonal": list(body.inertia)} if moving else {}),
        )
        if link >= 0:
            joint = self.geometry.joint(body.name)
            along = velocity[3:] if joint.kind == "hinge" else velocity[:3]
            self._call("resetJointState", uid, link, 0.0, float(along @ joint.axis))
        elif moving:
            self._call("resetBaseVelocity", uid, *np.split(velocity, 2))

    def _shape(self, body: Body, tuned: bool, offset: np.ndarray | None = None) -> int:
        """The collision shape of ``body`` (a tuned box or ellipsoid: spheres at its contacts).

        ``offset`` moves it in the frame it is attached to (a link's frame at its joint). Made
        once per description in the client (`_client`).
        """
        shift = np.zeros(3) if offset is None else offset
        if body.shape in ("box", "ellipsoid") and tuned:
            key: tuple = ("corners", *self._corners(body, shift))
            make = ("createCollisionShapeArray", [self.bullet.GEOM_SPHERE] * (len(key) // 2))
            arguments = {"radii": list(key[1::2]), "collisionFramePositions": list(key[2::2])}
        elif body.shape == "ellipsoid":
            key = (body.shape, body.size, *shift.tolist())
            make = ("createCollisionShape", self.bullet.GEOM_MESH)
            arguments = {
                "vertices": ellipsoid_points(body.size),
                "collisionFramePosition": list(shift),
            }
        elif body.shape in SIZES:
            key = (body.shape, body.size, *shift.tolist())
            make = ("createCollisionShape", getattr(self.bullet, f"GEOM_{body.shape.upper()}"))
            arguments = {**SIZES[body.shape](body.size), "collisionFramePosition": list(shift)}
        else:
            raise NotApplicable(f"pybullet: Bullet has no {body.shape} shape")
        shapes = self.client.shapes
        if key not in shapes:
            shapes[key] = self._call(*make, **arguments)
        return shapes[key]

    def _corners(self, body: Body, shift: np.ndarray) -> list:
        """Radius and position of a small sphere at each contact point of ``body``.

        `corner`'s, flattened; the positions in the body's frame, moved by ``shift``.
        """
        corners = []
        for pair in self.geometry.pairs:
            if body.name in (pair.a, pair.b):
                radius, local = corner(body, pair)
                corners += [radius, tuple((local + shift).tolist())]
        return corners

    def _only_declared_pairs(self) -> None:
        """Let the bodies of each declared pair collide, and no other two.

        Every two of the scene's bodies and the client's idle planes are set, so that a
        setting left by an earlier scene on a body id PyBullet gives again does not count.
        """
        index = self.geometry.index
        declared = {
            frozenset((self.ids[index[p.a]], self.ids[index[p.b]])) for p in self.geometry.pairs
        }
        every = self.ids + [uid for uid in self.client.planes if uid not in self.ids]
        links = [self.links.get(uid, -1) for uid in every]
        for i, first in enumerate(every):
            for k, second in enumerate(every[:i]):
                wanted = int(frozenset((first, second)) in declared)
                self._call("setCollisionFilterPair", first, second, links[i], links[k], wanted)

    def step(self) -> tuple[list[Force], np.ndarray]:
        """One stepSimulation: the forces of its contact points, and the bodies' velocities."""
        self._call("stepSimulation")
        names = {uid: body.name for uid, body in zip(self.ids, self.geometry.bodies, strict=True)}
        forces = []
        for point in self._call("getContactPoints"):
            on_a, on_b, normal = np.asarray(point[5]), np.asarray(point[6]), np.asarray(point[7])
            force = point[9] * normal + point[10] * np.asarray(point[11])
            force = force + point[12] * np.asarray(point[13])
            forces.append(Force(names[point[1]], names[point[2]], (on_a + on_b) / 2, force))
        return forces, np.array([self._velocity(k, uid) for k, uid in enumerate(self.ids)])

    def _velocity(self, k: int, uid: int) -> np.ndarray:
        """The velocity of body k's centre of mass and its angular velocity (6,).

        A link's from its joint's rate (getLinkState reports in single precision).
        """
        link = self.links[uid]
        if link < 0:
            return np.concatenate(self._call("getBaseVelocity", uid))
        joint = self.geometry.joint(self.geometry.bodies[k].name)
        axis, rate = np.asarray(joint.axis), self._call("getJointState", uid, link)[1]
        if joint.kind == "slide":
            return np.concatenate([rate * axis, np.zeros(3)])
        centre = self._call("getLinkState", uid, link, computeForwardKinematics=1)[0]
        arm = np.asarray(centre) - np.asarray(joint.anchor)
        return np.concatenate([rate * np.cross(axis, arm), rate * axis])

    def distances(self) -> np.ndarray:
        """Bullet's closest points of each two bodies that touch, each to its nearest pair."""
        geometry, found = self.geometry, np.full(len(self.geometry.pairs), self.reach)
        for first, second in {(p.a, p.b) for p in geometry.pairs}:
            a, b = self.ids[geometry.index[first]], self.ids[geometry.index[second]]
            for point in self._call("getClosestPoints", a, b, self.reach):
                j, _ = pair_of(geometry, Force(first, second, np.asarray(point[5]), _NO_FORCE))
                found[j] = min(found[j], point[8])
        return found

    def close(self) -> None:
        """Remove the bodies the scene made from the client, for the next solve."""
        for uid in self.made:
            self._call("removeBody", uid)
        self.ids, self.made, self.links = [], [], {}


LAWS.register(PyBullet())
