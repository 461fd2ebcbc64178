"""The scenes' geometry, as the engines build it: a scene's problem is its geometry's linear
algebra, and each engine's contact Jacobians at the initial pose are the scene's Wn and Wt.
"""

import numpy as np
import pytest

import lawbench
from lawbench.core.geometry import Body, ContactPair, Geometry, Joint
from lawbench.core.transforms import duplicated
from lawbench.fitting import kharaz_curves
from lawbench.measurements import MEASUREMENTS

pybullet = pytest.importorskip("pybullet")
mujoco = pytest.importorskip("mujoco")
pydrake = pytest.importorskip("pydrake")

# Imported once the engines are known to be installed.
from lawbench.laws.engines import _base, _bullet_coefficients  # noqa: E402
from lawbench.laws.engines import drake as drake_law  # noqa: E402
from lawbench.laws.engines import mujoco as mujoco_law  # noqa: E402
from lawbench.laws.engines import pybullet as pybullet_law  # noqa: E402

# The scenes that declare their geometry, at their defaults and one other example each.
SCENES = [
    ("three_ball_chain", {}),
    ("three_ball_chain", {"velocities": [1.0, 0.0, -1.0], "e": [0.5, 1.0]}),
    ("two_balls_wall", {}),
    ("ball_chain", {"wall": True}),
    ("bead_column", {"n": 3}),
    ("sphere_wall", {}),
    ("rocking_block", {}),
    ("rocking_block", {"width": 2.0, "height": 1.0}),
    ("bouncing_ball", {}),
    ("bouncing_ball", {"angular_velocity": [6.0, 6.0, 0.0], "radius": 0.2}),
    ("falling_rod", {}),
    ("falling_rod", {"angle": 80.0, "velocities": [0.5, -1.0, 2.0], "e": 0.8, "mu": 0.5}),
    ("lamina", {}),
    ("lamina", {"f0": -1.0, "h0": -0.5, "omega": 1.0}),
    ("billiard", {}),
    ("billiard", {"elevation": 0.0, "offset_side": 0.01, "offset_height": 0.0}),
]


@pytest.mark.parametrize(("case", "params"), SCENES)
def test_a_scene_s_problem_is_its_geometry_s(case, params):
    problem = lawbench.CASES.get(case).build(**params)
    assert problem.geometry is not None
    assert _base.geometry_mismatch(problem.geometry, problem) is None


def test_a_transformed_problem_is_refused_as_no_longer_its_geometry_s():
    problem = lawbench.CASES.get("three_ball_chain").build()
    with pytest.raises(lawbench.NotApplicable, match="3 contacts, its geometry 3 and 2"):
        lawbench.LAWS.get("pybullet").resolve(duplicated(problem))
    with pytest.raises(lawbench.NotApplicable, match="the problem's M is not its geometry's"):
        lawbench.LAWS.get("mujoco").resolve(problem.in_units(2.0, 1.0, 1.0))
    with pytest.raises(lawbench.NotApplicable, match="the scene declares no geometry"):
        lawbench.solve("mujoco", "double_pendulum")


def engine_columns_mujoco(problem):
    """Wn and Wt from MuJoCo's contacts at the initial pose: mj_jac at each contact point."""
    geometry = problem.geometry
    poses = geometry.poses(_base._displacement(problem, geometry))
    scene = mujoco_law._MuJoCoScene(
        _base.Start(problem, poses, np.zeros((len(poses), 6)), "tuned", 1e-5, 1.0)
    )
    model, data = scene.model, scene.data
    mujoco.mj_forward(model, data)
    # qvel of each generalized velocity: the joints' velocities are linear in the bodies'.
    Q = np.empty((model.nv, geometry.n))
    for i, column in enumerate(np.eye(geometry.n)):
        scene._set_velocities(geometry.body_velocities(column))
        Q[:, i] = data.qvel
    Wn, Wt = np.zeros_like(problem.Wn), None if problem.Wt is None else np.zeros_like(problem.Wt)
    seen = set()
    for contact in data.contact[: data.ncon]:
        bodies = [int(model.geom_bodyid[g]) for g in contact.geom]
        jacobians = []
        for body in bodies:
            jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
            mujoco.mj_jac(model, data, jacp, jacr, contact.pos, body)
            jacobians.append(jacp)
        first, second = (scene.owner[int(g)] for g in contact.geom)
        force = _base.Force(second, first, np.array(contact.pos), np.zeros(3))
        j, sign = _base.pair_of(geometry, force)
        relative_jacobian = sign * (jacobians[1] - jacobians[0]) @ Q
        directions = geometry.pairs[j].directions
        np.testing.assert_allclose(directions[0] @ contact.frame[:3] * sign, 1.0, atol=1e-9)
        Wn[:, j] = relative_jacobian.T @ directions[0]
        for k, tangent in enumerate(directions[1:]):
            Wt[:, j * problem.d + k] = relative_jacobian.T @ tangent
        seen.add(j)
    assert seen == set(range(problem.m)), "MuJoCo finds every declared contact"
    return Wn, Wt


def engine_columns_pybullet(problem, step=1e-7):
    """Wn and Wt from Bullet's contact points, by central differences in each coordinate.

    A normal column is the rate of Bullet's contact distance (getClosestPoints); a tangential
    one the rate of the material point of each body at Bullet's contact point along the tangent.
    """
    geometry = problem.geometry
    start = _base._displacement(problem, geometry)
    coefficients = _bullet_coefficients.body_coefficients(geometry, True)
    velocities = np.zeros((len(geometry.bodies), 6))
    scene = pybullet_law._BulletScene(
        _base.Start(problem, geometry.poses(start), velocities, "tuned", 1e-4, 1.0), coefficients
    )
    try:
        points = _closest(scene, problem)
        Wn, Wt = (
            np.zeros_like(problem.Wn),
            None if problem.Wt is None else np.zeros_like(problem.Wt),
        )
        for i in range(geometry.n):
            moved = []
            for h in (step, -step):
                _place(scene, geometry, start, h * np.eye(geometry.n)[i])
                moved.append(_closest(scene, problem, points))
            for j, (plus, minus) in enumerate(zip(*moved, strict=True)):
                Wn[i, j] = (plus[0] - minus[0]) / (2 * step)
                for k, tangent in enumerate(geometry.pairs[j].directions[1:]):
                    Wt[i, j * problem.d + k] = (plus[1] - minus[1]) @ tangent / (2 * step)
    finally:
        scene.close()
    return Wn, Wt


def _place(scene, geometry, start, displacement):
    """Each body at its pose ``displacement`` from ``start``: a base by its pose, a link on a
    hinge or slide by its joint's coordinate (zero at ``start``)."""
    moves = geometry.body_velocities(displacement)
    poses = geometry.poses(start + displacement)
    for k, (uid, (position, (w, *q))) in enumerate(zip(scene.ids, poses, strict=True)):
        link = scene.links[uid]
        if link < 0:
            pybullet.resetBasePositionAndOrientation(
                uid, list(position), [*q, w], physicsClientId=scene.client.id
            )
            continue
        joint = geometry.joint(geometry.bodies[k].name)
        along = moves[k][3:] if joint.kind == "hinge" else moves[k][:3]
        pybullet.resetJointState(
            uid, link, float(along @ joint.axis), physicsClientId=scene.client.id
        )


def _frame(scene, uid):
    """A world position and orientation of a frame fixed in body ``uid``.

    A link's from its base and its joint's coordinate (getLinkState reports in single
    precision): the base turned about a hinge's axis, or moved along a slide's.
    """
    link, client = scene.links[uid], scene.client.id
    base = pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)
    if link < 0:
        return base
    geometry = scene.geometry
    joint = geometry.joint(geometry.bodies[scene.ids.index(uid)].name)
    value, axis = pybullet.getJointState(uid, link, physicsClientId=client)[0], joint.axis
    if joint.kind == "slide":
        return np.asarray(base[0]) + value * np.asarray(axis), (0.0, 0.0, 0.0, 1.0)
    return base[0], (*(np.sin(value / 2) * np.asarray(axis)), np.cos(value / 2))


def _closest(scene, problem, points=None):
    """Per pair: Bullet's distance, and where the material points found first now are.

    Without ``points``, the material points at Bullet's contact points, in each body's frame.
    """
    geometry, client = problem.geometry, scene.client.id
    found = {}
    for pair in geometry.pairs:
        a, b = (scene.ids[geometry.index[name]] for name in (pair.a, pair.b))
        for point in pybullet.getClosestPoints(a, b, 1.0, physicsClientId=client):
            force = _base.Force(pair.a, pair.b, np.asarray(point[5]), np.zeros(3))
            j, _ = _base.pair_of(geometry, force)
            frames = [_frame(scene, u) for u in (a, b)]
            if points is None:
                on = [np.asarray(point[5]), np.asarray(point[6])]
                local = [_to_body(frame, p) for frame, p in zip(frames, on, strict=True)]
                found[j] = (point[8], local)
            else:
                world = [_to_world(f, p) for f, p in zip(frames, points[j][1], strict=True)]
                found[j] = (point[8], world[0] - world[1])
    return found if points is None else [found[j] for j in range(problem.m)]


def _to_body(frame, point):
    R = np.array(pybullet.getMatrixFromQuaternion(frame[1])).reshape(3, 3)
    return R.T @ (point - np.asarray(frame[0]))


def _to_world(frame, local):
    R = np.array(pybullet.getMatrixFromQuaternion(frame[1])).reshape(3, 3)
    return np.asarray(frame[0]) + R @ local


def engine_columns_drake(problem):
    """Wn and Wt from Drake's point pairs at the initial pose (tuned: a geometry per pair).

    CalcJacobianTranslationalVelocity of each body's material point at the pair's contact point
    (midway between Drake's two witness points), along the pair's normal and tangents.
    """
    geometry = problem.geometry
    poses = geometry.poses(_base._displacement(problem, geometry))
    tuning = drake_law._tuning(problem, 1e-5)
    start = _base.Start(problem, poses, np.zeros((len(poses), 6)), "tuned", 1e-5, 1.0)
    scene = drake_law.DrakeScene(start, tuning)
    plant, context = scene.plant, scene.context
    # Drake's generalized velocity of each of the scene's: linear in the bodies' velocities.
    Q = np.empty((plant.num_velocities(), geometry.n))
    for i, column in enumerate(np.eye(geometry.n)):
        scene._place(poses, geometry.body_velocities(column))
        Q[:, i] = plant.GetVelocities(context)
    query = scene.scene_graph.get_query_output_port().Eval(scene.graph_context)
    sides, world = scene._sides(), plant.world_frame()
    kV = pydrake.multibody.tree.JacobianWrtVariable.kV
    Wn, Wt = np.zeros_like(problem.Wn), None if problem.Wt is None else np.zeros_like(problem.Wt)
    seen = set()
    for found in query.ComputePointPairPenetration():
        j, sign = sides[(found.id_A.get_value(), found.id_B.get_value())]
        point = (found.p_WCa + found.p_WCb) / 2
        relative = np.zeros((3, plant.num_velocities()))
        for geometry_id, side in ((found.id_A, -sign), (found.id_B, sign)):
            frame = plant.GetBodyFromFrameId(
                scene.scene_graph.model_inspector().GetFrameId(geometry_id)
            ).body_frame()
            X_WB = frame.CalcPoseInWorld(context)
            J = plant.CalcJacobianTranslationalVelocity(
                context, kV, frame, X_WB.inverse().multiply(point), world, world
            )
            relative += side * J
        directions = geometry.pairs[j].directions
        # nhat_BA_W points from B into A, and A's force is the pair's a's when sign is -1.
        np.testing.assert_allclose(-sign * directions[0] @ found.nhat_BA_W, 1.0, atol=1e-9)
        Wn[:, j] = (relative @ Q).T @ directions[0]
        for k, tangent in enumerate(directions[1:]):
            Wt[:, j * problem.d + k] = (relative @ Q).T @ tangent
        seen.add(j)
    assert seen == set(range(problem.m)), "Drake finds every declared contact"
    return Wn, Wt


COLUMNS = {
    "mujoco": engine_columns_mujoco,
    "pybullet": engine_columns_pybullet,
    "drake": engine_columns_drake,
}


def assert_engine_columns(engine, problem):
    """The engine's contact Jacobians at the problem's pose are its ``Wn`` and ``Wt`` to 1e-9."""
    Wn, Wt = COLUMNS[engine](problem)
    np.testing.assert_allclose(Wn, problem.Wn, atol=1e-9 * np.abs(problem.Wn).max())
    if problem.Wt is not None:
        np.testing.assert_allclose(Wt, problem.Wt, atol=1e-9 * np.abs(problem.Wt).max())


@pytest.mark.parametrize(("case", "params"), SCENES)
@pytest.mark.parametrize("engine", list(COLUMNS))
def test_the_engine_s_contact_jacobians_are_the_scene_s(engine, case, params):
    assert_engine_columns(engine, lawbench.CASES.get(case).build(**params))


@pytest.mark.parametrize("engine", list(COLUMNS))
def test_the_engine_s_contact_jacobians_are_kharaz_s_sphere_s(engine):
    """Kharaz's alumina sphere on the glass anvil at 45 degrees, moving in its plane."""
    assert_engine_columns(engine, kharaz_curves.impact_problem(45.0))


@pytest.mark.parametrize(
    ("measured", "index"), [("cube", 50), ("cube", 473), ("ellipse", 0), ("ellipse", 267)]
)
@pytest.mark.parametrize("engine", list(COLUMNS))
def test_the_engine_s_contact_jacobians_are_a_measured_impact_s(engine, measured, index):
    """One-corner cube tosses, the box turned to its measured orientation; ellipse bounces near
    upright (0) and touching 10 mm off the centre (267), each engine finding the contact at the
    ellipse's lowest point."""
    impact = next(i for i in MEASUREMENTS.get(measured).impacts if i.index == index)
    assert impact.problem.m == 1
    assert_engine_columns(engine, impact.problem)


@pytest.mark.parametrize(
    ("field", "change", "message"),
    [
        ("bodies", {"shape": "cone"}, "shape = 'cone'"),
        ("bodies", {"size": (0.1, 0.1)}, "size has 2 entries"),
        ("bodies", {"quaternion": (1.0, 1.0, 0.0, 0.0)}, "quaternion .* norm 1"),
        ("pairs", {"normal": (1.0, 1.0, 0.0)}, "normal .* norm 1"),
        ("pairs", {"e": 1.5}, "e = 1.5 must lie in"),
        ("joints", {"kind": "ball"}, "kind = 'ball'"),
    ],
)
def test_a_bad_geometry_field_is_refused_by_name(field, change, message):
    geometry = lawbench.CASES.get("sphere_wall").build().geometry
    parts = {"bodies": geometry.bodies, "joints": geometry.joints, "pairs": geometry.pairs}
    with pytest.raises(lawbench.InvalidProblem, match=message):
        first = type(parts[field][0])(**{**vars(parts[field][0]), **change})
        Geometry(**{**parts, field: (first, *parts[field][1:])}, **_maps(geometry))


def _maps(geometry):
    return {"to_bodies": geometry.to_bodies, "to_generalized": geometry.to_generalized}


def test_a_map_that_moves_a_body_against_its_joint_is_refused():
    geometry = lawbench.CASES.get("rocking_block").build().geometry
    B = geometry.to_bodies.copy()
    B[2, 0] = 1.0  # vx drives the block out of its plane
    with pytest.raises(lawbench.InvalidProblem, match="against its planar joint"):
        Geometry(geometry.bodies, geometry.joints, geometry.pairs, B, geometry.to_generalized)
    ball = Body("ball", "sphere", (0.1,), 1.0, (0.004,) * 3)
    wall = Body("wall", "plane", ())
    pair = ContactPair("ball", "wall", (0, 0, 0), (0, 0, 1))
    with pytest.raises(lawbench.InvalidProblem, match="'wall' moves"):
        Geometry((ball, wall), (Joint("free", "ball"), Joint("free", "wall")), (pair,), B, B.T)
