"""Drake's side of the Drake law: the scene built as a MultibodyPlant in a Simulator.

The law (`lawbench.laws.engines.drake`) chooses the settings; this module builds them in Drake
and steps them, by the conventions the law's docstring states. pydrake is imported on first use.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from lawbench.core.geometry import Body, Joint, rotation_matrix
from lawbench.laws.engines._base import Force, Scene, Start, corner, plane_axes, whole

# Drake's warning at every half space it is given, about deformable bodies this law never makes.
_HALF_SPACE_WARNING = "half spaces are not currently supported for deformable contact"
# The pydrake modules the law uses.
_MODULES = (
    "common.value",
    "geometry",
    "math",
    "multibody.math",
    "multibody.plant",
    "multibody.tree",
    "systems.analysis",
    "systems.framework",
)


@dataclass(frozen=True)
class Tuning:
    """The tuned settings of a scene.

    Attributes
    ----------
    springs : list of (float, float)
        Each pair's stiffness (N/m) and Hunt-Crossley dissipation (s/m).
    stiction : float
        Drake's stiction tolerance (m/s).
    accuracy : float
        The integrator's target accuracy.
    """

    springs: list[tuple[float, float]]
    stiction: float
    accuracy: float


@functools.cache
def _drake() -> SimpleNamespace:
    """The pydrake modules, imported on first use (some 0.8 s), and the impulses' system.

    Drake's warning at each half space is filtered out of its logger: it is about deformable
    bodies.
    """
    modules = {name.replace(".", "_"): whole(f"pydrake.{name}") for name in _MODULES}
    logging.getLogger("drake").addFilter(
        lambda record: _HALF_SPACE_WARNING not in record.getMessage()
    )
    drake = SimpleNamespace(**modules)
    drake.Impulses = _impulses_system(drake)
    return drake


def _impulses_system(drake: SimpleNamespace) -> type:
    """The system whose continuous state is each pair's impulse so far, ``dP/dt = f``.

    Integrated with the plant by the same error-controlled integrator, so that a step's impulse
    is the integral of the step's forces, not a sample of them.
    """

    class Impulses(drake.systems_framework.LeafSystem):
        """Pair impulses (three per pair, world frame, on the pair's ``a``) from contact results.

        ``pairs`` maps the two geometry ids of a Drake point pair to the pair and the sign of
        the force on the pair's ``a`` relative to the reported force, which acts on the second.
        """

        def __init__(self, pairs: dict[tuple[int, int], tuple[int, float]], count: int) -> None:
            super().__init__()
            self.pairs, self.count = pairs, count
            self.DeclareContinuousState(3 * count)
            empty = drake.common_value.AbstractValue.Make(drake.multibody_plant.ContactResults())
            self.results = self.DeclareAbstractInputPort("contact_results", empty)

        def DoCalcTimeDerivatives(self, context: Any, derivatives: Any) -> None:
            results = self.results.Eval(context)
            rates = np.zeros((self.count, 3))
            for i in range(results.num_point_pair_contacts()):
                info = results.point_pair_contact_info(i)
                ids = info.point_pair()
                j, sign = self.pairs[(ids.id_A.get_value(), ids.id_B.get_value())]
                rates[j] += sign * info.contact_force()
            derivatives.get_mutable_vector().SetFromVector(rates.ravel())

    return Impulses


def _transform(drake: SimpleNamespace, rotation: np.ndarray, position: Any) -> Any:
    """A RigidTransform from a rotation matrix and a position."""
    R = drake.math.RotationMatrix(np.asarray(rotation, dtype=float))
    return drake.math.RigidTransform(R, np.asarray(position, dtype=float))


def _shape(drake: SimpleNamespace, body: Body) -> Any:
    """The Drake shape of ``body`` (a plane is a half space, its normal the frame's z)."""
    g, size = drake.geometry, body.size
    shapes = {
        "sphere": lambda: g.Sphere(size[0]),
        "box": lambda: g.Box(*(2.0 * s for s in size)),
        "capsule": lambda: g.Capsule(size[0], 2.0 * size[1]),
        "cylinder": lambda: g.Cylinder(size[0], 2.0 * size[1]),
        "ellipsoid": lambda: g.Ellipsoid(*size),
        "plane": g.HalfSpace,
    }
    return shapes[body.shape]()


class DrakeScene(Scene):
    """The geometry as a MultibodyPlant in a Simulator, at the pre-impact state.

    ``tuning`` gives each pair its stiffness and dissipation, and builds a geometry per pair;
    None (the defaults) builds a geometry per body with Drake's defaults.
    """

    def __init__(self, start: Start, tuning: Tuning | None) -> None:
        drake = self.drake = _drake()
        geometry, poses, velocities, dt = start.geometry, start.poses, start.velocities, start.dt
        self.geometry, self.dt, self.reach = geometry, dt, start.reach
        self.tuned = tuning is not None
        plant_module = drake.multibody_plant
        if tuning is not None:
            config = plant_module.MultibodyPlantConfig(
                time_step=0.0, contact_model="point", stiction_tolerance=tuning.stiction
            )
        else:
            config = plant_module.MultibodyPlantConfig(time_step=dt)
        builder = drake.systems_framework.DiagramBuilder()
        plant, scene_graph = plant_module.AddMultibodyPlant(config, builder)
        plant.mutable_gravity_field().set_gravity_vector(np.zeros(3))
        self.plant, self.scene_graph = plant, scene_graph
        self.bodies = self._bodies(poses)
        self.pair_ids = self._geometries(poses, tuning and tuning.springs)
        plant.Finalize()
        self._only_declared_pairs()
        if self.tuned:
            self.impulses = builder.AddSystem(drake.Impulses(self._sides(), len(geometry.pairs)))
            builder.Connect(plant.get_contact_results_output_port(), self.impulses.get_input_port())
        self.diagram = builder.Build()
        self.simulator = drake.systems_analysis.Simulator(self.diagram)
        if self.tuned:
            integrator = drake.systems_analysis.ResetIntegratorFromFlags(
                self.simulator, "runge_kutta3", dt
            )
            integrator.set_target_accuracy(tuning.accuracy)
        root = self.simulator.get_mutable_context()
        self.context = plant.GetMyMutableContextFromRoot(root)
        self.graph_context = scene_graph.GetMyContextFromRoot(root)
        self._place(poses, velocities)
        self.simulator.Initialize()
        self.points = self._material_points()
        self.steps, self.impulse = 0, np.zeros(3 * len(geometry.pairs))
        if self.tuned:
            self.impulse_context = self.impulses.GetMyContextFromRoot(root)

    def _bodies(self, poses: list[tuple[np.ndarray, tuple[float, ...]]]) -> list[Any]:
        """Each body's Drake body (the world body for a fixed one), its joint made.

        A free body is Drake's floating body; the other joints are `_joint`'s.
        """
        plant, made = self.plant, []
        tree = self.drake.multibody_tree
        # Each jointed body's velocity setter: (context, v, w) -> None.
        self.jointed: dict[int, Callable[[Any, np.ndarray, np.ndarray], None]] = {}
        for k, body in enumerate(self.geometry.bodies):
            joint = self.geometry.joint(body.name)
            if joint.kind == "fixed":
                made.append(plant.world_body())
                continue
            inertia = tree.SpatialInertia.MakeFromCentralInertia(
                body.mass, np.zeros(3), tree.RotationalInertia(*body.inertia)
            )
            rigid = plant.AddRigidBody(f"b{k}", inertia)
            made.append(rigid)
            if joint.kind != "free":
                self.jointed[k] = self._joint(k, rigid, joint, poses[k])
        return made

    def _joint(
        self, k: int, rigid: Any, joint: Joint, pose: tuple[np.ndarray, tuple[float, ...]]
    ) -> Callable[[Any, np.ndarray, np.ndarray], None]:
        """Join body k to the world; return the setter of its velocity (context, v, w).

        A frame of the world, its z the joint's axis, at the hinge's anchor (at the body's
        centre for the other joints), is joined to the same frame fixed on the body, so that the
        joint's coordinates are zero at the pose: Drake's PlanarJoint moves the child frame in
        the parent's x-y plane and turns it about z, its RevoluteJoint turns it about z, its
        PrismaticJoint slides it along z.
        """
        drake, plant = self.drake, self.plant
        tree = drake.multibody_tree
        position, quaternion = pose
        axis = np.asarray(joint.axis)
        R_WF = np.column_stack([*plane_axes(axis), axis])
        origin = joint.anchor if joint.kind == "hinge" else position
        X_WF = _transform(drake, R_WF, origin)
        X_BW = _transform(drake, rotation_matrix(quaternion), position).inverse()
        F = plant.AddFrame(tree.FixedOffsetFrame(f"F{k}", plant.world_frame(), X_WF))
        M = plant.AddFrame(tree.FixedOffsetFrame(f"M{k}", rigid.body_frame(), X_BW.multiply(X_WF)))
        z = np.array([0.0, 0.0, 1.0])
        if joint.kind == "hinge":
            made = plant.AddJoint(tree.RevoluteJoint(f"J{k}", F, M, z))
            return lambda context, v, w: made.set_angular_rate(context, float(axis @ w))
        if joint.kind == "slide":
            made = plant.AddJoint(tree.PrismaticJoint(f"J{k}", F, M, z))
            return lambda context, v, w: made.set_translation_rate(context, float(axis @ v))
        made = plant.AddJoint(tree.PlanarJoint(f"J{k}", F, M))

        def planar(context: Any, v: np.ndarray, w: np.ndarray) -> None:
            made.set_translational_velocity(context, (R_WF.T @ v)[:2])
            made.set_angular_velocity(context, float(axis @ w))

        return planar

    def _geometries(
        self,
        poses: list[tuple[np.ndarray, tuple[float, ...]]],
        springs: list[tuple[float, float]] | None,
    ) -> list[tuple[Any, Any]]:
        """Register the collision geometries; return each pair's two geometry ids.

        Default: one per body, with the mean mu of its pairs (Drake combines two geometries'
        friction by ``2 mu1 mu2 / (mu1 + mu2)``). Tuned: one per pair on each of its bodies
        (a box touching through a small sphere at the pair's point, `corner`), each with the
        pair's mu, twice the pair's stiffness (Drake combines two geometries' stiffnesses in
        series, ``k1 k2 / (k1 + k2)``) and its dissipation (combined as
        ``(k2 d1 + k1 d2) / (k1 + k2)``, the same dissipation on both sides gives it).
        """
        geometry, index = self.geometry, self.geometry.index
        self.owner: dict[int, str] = {}
        self._shapes: dict[int, str] = {}
        if springs is None:
            ids = [
                self._register(k, poses, _shape(self.drake, body), np.zeros(3), f"g{k}", None)
                for k, body in enumerate(geometry.bodies)
            ]
            for k, body in enumerate(geometry.bodies):
                self.owner[ids[k].get_value()] = body.name
            return [(ids[index[pair.a]], ids[index[pair.b]]) for pair in geometry.pairs]
        pair_ids = []
        for j, pair in enumerate(geometry.pairs):
            stiffness, dissipation = springs[j]
            material = (2.0 * stiffness, dissipation, pair.mu)
            ids = []
            for name in (pair.a, pair.b):
                k = index[name]
                body = geometry.bodies[k]
                if body.shape == "box":
                    radius, local = corner(body, pair)
                    shape = self.drake.geometry.Sphere(radius)
                else:
                    shape, local = _shape(self.drake, body), np.zeros(3)
                ids.append(self._register(k, poses, shape, local, f"g{j} {name}", material))
            pair_ids.append((ids[0], ids[1]))
        return pair_ids

    def _register(
        self,
        k: int,
        poses: list[tuple[np.ndarray, tuple[float, ...]]],
        shape: Any,
        local: np.ndarray,
        label: str,
        material: tuple[float, float, float] | None,
    ) -> Any:
        """Register ``shape`` on body k at ``local`` (its frame); return its geometry id.

        A fixed body's geometry is the world body's, placed at the body's pose. ``material``
        is (stiffness, dissipation, mu); None leaves Drake's defaults but for the friction, the
        mean mu of the body's pairs.
        """
        drake, body = self.drake, self.geometry.bodies[k]
        g = drake.geometry
        properties = g.ProximityProperties()
        if material is None:
            mus = [p.mu for p in self.geometry.pairs if body.name in (p.a, p.b)]
            friction = drake.multibody_plant.CoulombFriction(np.mean(mus), np.mean(mus))
            g.AddContactMaterial(friction=friction, properties=properties)
        else:
            stiffness, dissipation, mu = material
            g.AddContactMaterial(
                dissipation=dissipation,
                point_stiffness=stiffness,
                friction=drake.multibody_plant.CoulombFriction(mu, mu),
                properties=properties,
            )
        place = _transform(drake, np.eye(3), local)
        if not self.geometry.moving(body.name):
            position, quaternion = poses[k]
            R = rotation_matrix(quaternion)
            place = _transform(drake, R, np.asarray(position) + R @ local)
        registered = self.plant.RegisterCollisionGeometry(
            self.bodies[k], place, shape, label, properties
        )
        self._shapes[registered.get_value()] = type(shape).__name__
        return registered

    def _only_declared_pairs(self) -> None:
        """Filter every two geometries out of contact but each pair's two."""
        g = self.drake.geometry
        every = {i.get_value(): i for ids in self.pair_ids for i in ids}
        declaration = g.CollisionFilterDeclaration().ExcludeWithin(
            g.GeometrySet(list(every.values()))
        )
        for a, b in self.pair_ids:
            declaration.AllowBetween(g.GeometrySet(a), g.GeometrySet(b))
        self.scene_graph.collision_filter_manager().Apply(declaration)

    def _sides(self) -> dict[tuple[int, int], tuple[int, float]]:
        """A point pair's geometry ids, in either order -> its pair and a sign.

        The sign of the force on the pair's ``a``: Drake reports the force on the point pair's
        second geometry.
        """
        sides = {}
        for j, (a, b) in enumerate(self.pair_ids):
            sides[(a.get_value(), b.get_value())] = (j, -1.0)
            sides[(b.get_value(), a.get_value())] = (j, 1.0)
        return sides

    def _place(
        self, poses: list[tuple[np.ndarray, tuple[float, ...]]], velocities: np.ndarray
    ) -> None:
        """Each free body at its pose, and every moving body at its velocity (B, 6)."""
        drake, plant, context = self.drake, self.plant, self.context
        for k, rigid in enumerate(self.bodies):
            v, w = velocities[k][:3], velocities[k][3:]
            if k in self.jointed:
                self.jointed[k](context, v, w)
            elif self.geometry.moving(self.geometry.bodies[k].name):
                position, quaternion = poses[k]
                pose = _transform(drake, rotation_matrix(quaternion), position)
                plant.SetFreeBodyPose(context, rigid, pose)
                velocity = drake.multibody_math.SpatialVelocity(w, v)
                plant.SetFreeBodySpatialVelocity(context, rigid, velocity)

    def step(self) -> tuple[list[Force], np.ndarray]:
        """Advance the simulator by dt: the step's contact forces, and the bodies' velocities.

        Tuned, each pair's force is its impulse over the step divided by dt; at the defaults,
        the point pairs' forces the plant samples for the step (constant over it). The k-th step
        ends at ``k dt``, the time of the plant's k-th discrete update to the float: a sum of
        dt's drifts from it, and an advance that stops short of an update time or passes it
        makes no update or two, of which the sampled results report the last.
        """
        self.steps += 1
        self.simulator.AdvanceTo(self.steps * self.dt)
        forces = self._integrated() if self.tuned else self._sampled()
        velocities = np.zeros((len(self.bodies), 6))
        for k, rigid in enumerate(self.bodies):
            if self.geometry.moving(self.geometry.bodies[k].name):
                V = self.plant.EvalBodySpatialVelocityInWorld(self.context, rigid)
                velocities[k] = np.concatenate([V.translational(), V.rotational()])
        return forces, velocities

    def _integrated(self) -> list[Force]:
        """Each pair's mean force over the step, from the integrated impulses."""
        impulse = self.impulse_context.get_continuous_state_vector().CopyToVector()
        step, self.impulse = (impulse - self.impulse).reshape(-1, 3), impulse
        return [
            Force(pair.a, pair.b, np.asarray(pair.point), step[j] / self.dt)
            for j, pair in enumerate(self.geometry.pairs)
            if step[j].any()
        ]

    def _sampled(self) -> list[Force]:
        """The point pairs' forces of the step just taken (Drake's sampled contact results)."""
        results = self.plant.get_contact_results_output_port().Eval(self.context)
        forces = []
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            ids = info.point_pair()
            first, second = (self.owner[i.get_value()] for i in (ids.id_B, ids.id_A))
            forces.append(Force(first, second, info.contact_point(), info.contact_force()))
        return forces

    def _material_points(self) -> list[tuple[Any, np.ndarray] | None]:
        """Per pair of a half space and a shape other than a sphere, the shape's point there.

        Its body and the pair's point in the body's frame: Drake computes the distance from a
        half space to a sphere only, and from a half space to a point.
        """
        points: list[tuple[Any, np.ndarray] | None] = []
        for pair in self.geometry.pairs:
            ids = self.pair_ids[len(points)]
            shapes = [self._shapes[i.get_value()] for i in ids]
            if "HalfSpace" not in shapes or "Sphere" in shapes:
                points.append(None)
                continue
            k = self.geometry.index[pair.b if shapes[0] == "HalfSpace" else pair.a]
            X_WB = self.plant.EvalBodyPoseInWorld(self.context, self.bodies[k])
            points.append((self.bodies[k], X_WB.inverse().multiply(np.asarray(pair.point))))
        return points

    def distances(self) -> np.ndarray:
        """Drake's signed distance of each pair's two geometries, at most the reach.

        For a half space and a shape other than a sphere (`_material_points`), the distance
        from the half space to the shape's material point at the pair's point.
        """
        query = self.scene_graph.get_query_output_port().Eval(self.graph_context)
        found = np.full(len(self.pair_ids), self.reach)
        for j, (a, b) in enumerate(self.pair_ids):
            point = self.points[j]
            if point is None:
                distance = query.ComputeSignedDistancePairClosestPoints(a, b).distance
            else:
                body, local = point
                X_WB = self.plant.EvalBodyPoseInWorld(self.context, body)
                plane = a if self._shapes[a.get_value()] == "HalfSpace" else b
                distance = next(
                    d.distance
                    for d in query.ComputeSignedDistanceToPoint(X_WB.multiply(local))
                    if d.id_G == plane
                )
            found[j] = min(found[j], distance)
        return found

    def close(self) -> None:
        """Nothing to free: the plant and its simulator go with the scene."""
