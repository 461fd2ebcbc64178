"""The engines as laws: the scenes' geometry, PyBullet and MuJoCo against Moreau's law, Drake
against the compliant law.

Measured (this repository's scenes, the engines' default and tuned settings): PyBullet tuned
equals Moreau's law to rounding (1e-15) on the chain, the sphere on a wall and the rocking
block; MuJoCo tuned is 5e-5 from it on the elastic chain and 3e-6 on the block; Drake tuned is
the compliant law's linear-spring chain to 1.4e-6. The defaults are the traps: PyBullet
multiplies the two bodies' coefficients (a contact of e = 0.8 acts with 0.64), MuJoCo and Drake
ignore e (the elastic chain keeps a third of its energy).
"""

import importlib
import sys

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

import lawbench
from lawbench.core.geometry import Body, ContactPair, Geometry, Joint
from lawbench.core.law import Law
from lawbench.core.registry import Registry
from lawbench.core.transforms import duplicated
from lawbench.fitting import kharaz_curves
from lawbench.measurements import MEASUREMENTS
from lawbench.views import cli

pybullet = pytest.importorskip("pybullet")
mujoco = pytest.importorskip("mujoco")
pydrake = pytest.importorskip("pydrake")

# Imported once the engines are known to be installed.
from lawbench.laws.engines import _base  # noqa: E402
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
]


def relative(a, b, scale):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(scale).max())


def against_moreau(law, case, settings, **params):
    """The engine's answer, Moreau's, and their distance relative to the largest velocity."""
    problem = lawbench.CASES.get(case).build(**params)
    engine = lawbench.LAWS.get(law).resolve(problem, settings=settings)
    moreau = lawbench.LAWS.get("moreau").resolve(problem)
    return engine, moreau, relative(engine.v_plus, moreau.v_plus, problem.v)


# 1. The geometry: the scene's problem is its geometry's linear algebra, and the engine's.


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
        lawbench.solve("mujoco", "lamina")


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
    coefficients = pybullet_law._coefficients(geometry, True)
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
                for uid, (position, (w, *q)) in zip(
                    scene.ids, geometry.poses(start + h * np.eye(geometry.n)[i]), strict=True
                ):
                    pybullet.resetBasePositionAndOrientation(
                        uid, list(position), [*q, w], physicsClientId=scene.client.id
                    )
                moved.append(_closest(scene, problem, points))
            for j, (plus, minus) in enumerate(zip(*moved, strict=True)):
                Wn[i, j] = (plus[0] - minus[0]) / (2 * step)
                for k, tangent in enumerate(geometry.pairs[j].directions[1:]):
                    Wt[i, j * problem.d + k] = (plus[1] - minus[1]) @ tangent / (2 * step)
    finally:
        scene.close()
    return Wn, Wt


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
            frames = [
                pybullet.getBasePositionAndOrientation(u, physicsClientId=client) for u in (a, b)
            ]
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


# 2. PyBullet: tuned is Moreau's law; the defaults multiply the coefficients.


@pytest.mark.parametrize(
    ("case", "params"),
    [
        ("three_ball_chain", {}),
        ("ball_chain", {"wall": True, "e": [0.5]}),
        ("sphere_wall", {"spin": [0.0, 0.0, 0.0]}),
        ("sphere_wall", {"mu": 0.03}),
        ("rocking_block", {}),
    ],
)
def test_pybullet_tuned_is_moreau_s_law(case, params):
    """Measured to 1e-15; asked to 1e-9 (the brief's bound, 2 % on the block, is far looser)."""
    _, _, error = against_moreau("pybullet", case, "tuned", **params)
    assert error < 1e-9


def test_pybullet_tuned_from_the_command_line(capsys):
    args = ["solve", "pybullet", "three_ball_chain", "--option", "settings=tuned", "--json"]
    assert cli.main(args) == 0
    out = capsys.readouterr()
    assert out.err == ""
    np.testing.assert_allclose(
        __import__("json").loads(out.out)["v_plus"], [-1 / 3, 2 / 3, 2 / 3], atol=1e-9
    )


def test_pybullet_defaults_multiply_the_coefficients_and_keep_a_little_energy():
    """The trap witnesses: e -> e^2 and mu -> mu^2; the chain at 1/240 s, (-0.331, 0.664, 0.664)."""
    chain = lawbench.solve("pybullet", "three_ball_chain")
    np.testing.assert_allclose(chain.v_plus, [-0.331, 0.664, 0.664], atol=2e-3)
    assert chain.T_plus / chain.T_minus == pytest.approx(0.995, abs=1e-3)
    problem = lawbench.CASES.get("sphere_wall").build(spin=[0.0, 0.0, 0.0], mu=0.03)
    sphere = lawbench.LAWS.get("pybullet").resolve(problem)
    # e^2 = 0.64 of the approach (0.8 tuned), less the 0.3 % the contact slop takes.
    assert sphere.v_plus[1] / -problem.v[1] == pytest.approx(0.8**2, abs=0.005)
    assert np.linalg.norm(sphere.Pt) == pytest.approx(0.03**2 * sphere.Pn[0], rel=1e-9)


def test_pybullet_meets_gaps_event_by_event():
    """Contact 1 open by a millimetre: Newton's cradle, as rigid binary impacts give."""
    outcome = lawbench.solve(
        "pybullet", "three_ball_chain", gaps=[0.0, 1e-3], options={"settings": "tuned"}
    )
    np.testing.assert_allclose(outcome.v_plus, [0.0, 0.0, 1.0], atol=1e-9)


def test_pybullet_refuses_coefficients_no_per_body_values_multiply_to():
    geometry = lawbench.CASES.get("ball_chain").build(n=3, e=[0.0, 1.0]).geometry
    assert pybullet_law._factors(geometry, [0.0, 1.0]) == [0.0, 1.0, 1.0]
    assert pybullet_law._factors(geometry, [0.5, 0.5]) == [1.0, 0.5, 1.0]
    assert pybullet_law._factors(geometry, [1.0, 0.0]) == [1.0, 1.0, 0.0]
    three = lawbench.CASES.get("ball_chain").build(n=4, e=[0.5, 0.0, 0.5]).geometry
    assert pybullet_law._factors(three, [0.5, 0.0, 0.5]) is None


# 3. MuJoCo: tuned approaches Moreau's law; its defaults ignore e.


def test_mujoco_tuned_approaches_moreau_s_law():
    """Measured 5.2e-5 on the chain and 3.3e-6 on the block; asked 1e-4 and 1e-5."""
    chain = against_moreau("mujoco", "three_ball_chain", "tuned")
    assert chain[2] < 1e-4
    assert against_moreau("mujoco", "rocking_block", "tuned")[2] < 1e-5


def test_mujoco_tuned_contacts_leave_at_e():
    """e mapped to the damping of an oscillator released at zero force: within 1 %."""
    for e in (0.0, 0.5, 0.8):
        problem = lawbench.CASES.get("sphere_wall").build(spin=[0, 0, 0], mu=0.0, e=e, angle=0.0)
        outcome = lawbench.LAWS.get("mujoco").resolve(problem, settings="tuned")
        assert outcome.v_plus[1] / -problem.v[1] == pytest.approx(e, abs=0.01)


def test_mujoco_tuned_friction_of_an_elastic_contact_takes_part_of_the_rebound():
    """The finding of the module's docstring: 18 % of the rebound lost where Moreau rolls."""
    engine, moreau, _ = against_moreau("mujoco", "sphere_wall", "tuned", spin=[0.0, 0.0, 0.0])
    assert engine.v_plus[1] == pytest.approx(0.93, abs=0.01)
    assert moreau.v_plus[1] == pytest.approx(1.131, abs=1e-3)
    assert engine.v_plus[5] == pytest.approx(moreau.v_plus[5], rel=0.01)


def test_mujoco_defaults_ignore_e():
    """The trap witness: (0.23, 0.37, 0.39) and 35 % of the energy as first measured, with the
    contacts found from the first step (0.25, 0.37, 0.38) and 34 %: within 0.03 and 0.02."""
    chain = lawbench.solve("mujoco", "three_ball_chain")
    np.testing.assert_allclose(chain.v_plus, [0.23, 0.37, 0.39], atol=0.03)
    assert chain.T_plus / chain.T_minus == pytest.approx(0.35, abs=0.02)


def test_the_damping_ratio_inverts_the_restitution_of_a_released_oscillator():
    for e in (1e-3, 0.05, np.exp(-2.0), 0.3, 0.9):
        zeta = mujoco_law.damping_ratio(e)
        assert mujoco_law.released_restitution(zeta) == pytest.approx(e, rel=1e-9)
    assert mujoco_law.damping_ratio(1.0) == 0.0


# 4. Drake: tuned is the compliant law's linear springs; its defaults ignore e.


def linear_spring_chain(v1=1.0):
    """The elastic three-ball chain of equal unit masses and linear springs of equal stiffness.

    Brogliato 2010 (linear-spring model of the three-ball chain), solved by hand: while both
    springs are compressed the chain is the linear system ``x'' = -K x`` (K the springs' unit
    stiffness matrix; the answer does not depend on a common stiffness), so its state is
    ``expm(A t)`` of the start; contact 0 lets go first, where its compression returns to
    zero, and balls 2 and 3 then leave their spring as a two-body oscillator does, with their
    relative speed of that moment's energy, ``sqrt(d'^2 + 2 d^2)``; ball 1 never catches up.
    """
    K = np.array([[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-K, np.zeros((3, 3))]])
    start = np.array([0.0, 0.0, 0.0, v1, 0.0, 0.0])

    def state(t):
        return scipy.linalg.expm(A * t) @ start

    def compression_0(t):
        x = state(t)
        return x[0] - x[1]

    times = np.linspace(1e-3, 4.0, 4000)
    first = next(t for t in times if compression_0(t) < 0)
    release = scipy.optimize.brentq(compression_0, first - 1e-3, first, xtol=1e-15)
    x = state(release)
    d, rate = x[1] - x[2], x[4] - x[5]
    assert d > 0, "contact 1 is still compressed when contact 0 lets go"
    centre, leaving = (x[4] + x[5]) / 2, np.sqrt(rate**2 + 2 * d**2)
    answer = np.array([x[3], centre - leaving / 2, centre + leaving / 2])
    assert answer[0] < answer[1]
    return answer


def test_drake_tuned_is_the_compliant_law_s_linear_springs():
    """Drake tuned, compliant and the hand solution of the linear-spring chain agree to 1e-3.

    The answer (-0.1303, 0.1502, 0.9800) is `linear_spring_chain`'s (measured: Drake 1.4e-6
    from the compliant law at tol 1e-10); the chain's contacts given exponent 1 (its parameter
    ``exponent``, stiffness 1 N/m and ratio 1), e = 1 by default, so the compliant law's
    Hunt-Crossley model is a linear undamped spring.
    """
    expected = linear_spring_chain()
    np.testing.assert_allclose(expected, [-0.1303, 0.1502, 0.9800], atol=1e-4)
    problem = lawbench.CASES.get("three_ball_chain").build(exponent=1.0)
    compliant = lawbench.LAWS.get("compliant").resolve(problem, tol=1e-10)
    np.testing.assert_allclose(compliant.v_plus, expected, atol=1e-8)
    outcome = lawbench.solve(
        "drake", "three_ball_chain", exponent=1.0, options={"settings": "tuned"}
    )
    np.testing.assert_allclose(outcome.v_plus, compliant.v_plus, atol=1e-3)
    assert outcome.diagnostics["engine_velocity_gap"] < 1e-9


def test_drake_tuned_approaches_moreau_s_law_on_the_block_and_leaves_at_e():
    """Measured 7e-4 on the block (e = 0: its corners leave at 1e-3 of their approach); head-on
    a sphere leaves at e to 1e-4 (asked 1e-3), e = 0 at `LEAST_RESTITUTION`."""
    assert against_moreau("drake", "rocking_block", "tuned")[2] < 2e-3
    for e in (0.0, 0.5, 0.8):
        problem = lawbench.CASES.get("sphere_wall").build(spin=[0, 0, 0], mu=0.0, e=e, angle=0.0)
        outcome = lawbench.LAWS.get("drake").resolve(problem, settings="tuned")
        wanted = max(e, _base.LEAST_RESTITUTION)
        assert outcome.v_plus[1] / -problem.v[1] == pytest.approx(wanted, abs=1e-3)


def test_drake_defaults_make_the_elastic_chain_plastic_like():
    """The trap witness: measured (0.314, 0.334, 0.353), a third of the energy; asked within
    0.025 m/s of the plastic chain's common 1/3 m/s and 0.01 of its third of the energy."""
    chain = lawbench.solve("drake", "three_ball_chain")
    np.testing.assert_allclose(chain.v_plus, [1 / 3] * 3, atol=0.025)
    assert chain.T_plus / chain.T_minus == pytest.approx(1 / 3, abs=0.01)


def test_drake_defaults_let_a_flat_box_gain_energy_where_its_contact_point_jumps():
    """The finding's witness: a flat rocking block 10 m wide and 1 m high (e = 0, mu = 0)
    lands on Drake's one point contact, which moves from the middle of the face to a corner
    within the default 1 ms step. It leaves with more energy than it brought, a law property
    of the defaults, not unexplained; at dt = 1e-4 s it keeps less than a quarter, and tuned,
    with a small sphere at each corner, it is Moreau's answer to 1e-2."""
    block = lawbench.CASES.get("rocking_block").build(width=10.0, height=1.0, e=0.0, mu=0.0)
    trial = lawbench.evaluate("drake", block)
    assert trial.outcome.T_plus > 1.1 * block.T_minus
    verdict = lawbench.run_checks(trial, checks=["energy_gain"])["energy_gain"].verdict
    assert str(verdict) == "law property"
    finer = lawbench.solve("drake", block, {"dt": 1e-4})
    assert finer.T_plus < 0.25 * block.T_minus
    tuned = lawbench.solve("drake", block, {"settings": "tuned"})
    moreau = lawbench.solve("moreau", block)
    assert relative(tuned.v_plus, moreau.v_plus, block.v) < 1e-2


def test_drake_defaults_leave_a_contact_at_one_over_its_dissipation_times_speed():
    """Drake's default dissipation, 50 s/m: struck at 3.9 m/s the sphere leaves at 0.005 of it,
    whatever e (the relation's large-u end, e = 1 / u, measured to 1 %)."""
    problem = lawbench.CASES.get("sphere_wall").build(
        spin=[0, 0, 0], mu=0.0, e=0.8, angle=0.0, speed=3.9
    )
    outcome = lawbench.LAWS.get("drake").resolve(problem)
    assert outcome.v_plus[1] / 3.9 == pytest.approx(1 / (50 * 3.9), rel=0.02)
    assert drake_law.released_restitution(50 * 3.9) == pytest.approx(1 / (50 * 3.9), rel=1e-2)


def test_the_dissipation_inverts_the_restitution_of_a_linear_hunt_crossley_contact():
    for e in (1e-3, 0.1, 0.5, 0.9, 0.999):
        u = drake_law.dissipation_speed(e)
        assert drake_law.released_restitution(u) == pytest.approx(e, rel=1e-9)
    assert drake_law.dissipation_speed(1.0) == 0.0
    assert drake_law.dissipation_speed(0.0) == drake_law.dissipation_speed(1e-3)
    # Hunt and Crossley's first order, 1 - e = 2 u / 3, holds only as u vanishes.
    assert 1 - drake_law.released_restitution(1e-4) == pytest.approx(2e-4 / 3, rel=1e-3)
    assert 1 - drake_law.released_restitution(1.0) != pytest.approx(2 / 3, rel=0.1)


# 5. What every engine shares: its budget, its determinism, its listing, its absence.


@pytest.mark.parametrize("engine", ["mujoco", "pybullet", "drake"])
def test_an_engine_that_runs_out_of_steps_names_its_budget(engine):
    with pytest.raises(lawbench.BudgetExceeded, match="max_steps"):
        lawbench.solve(engine, "three_ball_chain", options={"max_steps": 2})


def test_an_engine_s_own_converged_answer_is_one_it_reaches_within_its_step_bound():
    """The numerical error's reference and a sweep's finest step stop at the engines' finest
    step: at 1e-12 s, the generic tightest value, MuJoCo ran into its step bound and had no
    reference at all."""
    from lawbench.checks.knobs import knob_values, tightest
    from lawbench.checks.measures import numerical_error
    from lawbench.core.trial import make_trial

    law = lawbench.LAWS.get("mujoco")
    finest = law.tags.finest_knob
    assert tightest(law) == {"dt": finest}
    assert knob_values(law, [1e-2, 1e-4, 1e-6, 1e-12])[1] == [1e-2, 1e-4]
    trial = make_trial("mujoco", "rocking_block", options={"dt": 1e-4})
    assert 0.0 < numerical_error(trial) < 1e-2


@pytest.mark.parametrize("engine", ["mujoco", "pybullet", "drake"])
def test_an_engine_answers_the_same_twice_and_reports_its_own_velocity(engine):
    first = lawbench.solve(engine, "sphere_wall", options={"settings": "tuned"})
    second = lawbench.solve(engine, "sphere_wall", options={"settings": "tuned"})
    np.testing.assert_array_equal(first.v_plus, second.v_plus)
    assert first.diagnostics["engine_velocity_gap"] < 1e-3


def test_the_engines_are_listed_and_described(capsys):
    assert cli.main(["list"]) == 0
    listed = capsys.readouterr().out
    assert "  mujoco " in listed and "  pybullet " in listed and "  drake " in listed
    assert cli.main(["describe", "mujoco"]) == 0
    described = capsys.readouterr().out
    for setting in ("settings = 'default'", "solref", "solimp", "elliptic", "dt = 0.0"):
        assert setting in described
    assert cli.main(["describe", "drake"]) == 0
    described = capsys.readouterr().out
    for setting in ("settings = 'default'", "MultibodyPlantConfig", "time_step 0", "dt = 0.0"):
        assert setting in described
    assert "Hunt-Crossley" in described and "lagged" in described


def test_an_engine_that_is_not_installed_is_listed_with_its_install_command(monkeypatch):
    """The missing packages simulated: their imports blocked (None in sys.modules)."""
    fresh = Registry("law", "lawbench.laws", Law)
    monkeypatch.setattr("lawbench.core.law.LAWS", fresh)
    monkeypatch.setitem(sys.modules, "pybullet", None)
    monkeypatch.setitem(sys.modules, "pydrake", None)
    for engine in ("mujoco", "pybullet", "drake"):
        monkeypatch.delitem(sys.modules, f"lawbench.laws.engines.{engine}")
    monkeypatch.delitem(sys.modules, "lawbench.laws.engines")
    monkeypatch.delattr("lawbench.laws.engines")
    importlib.import_module("lawbench.laws.engines")
    assert "mujoco" in fresh._entries
    for engine in ("pybullet", "drake"):
        assert engine not in fresh._entries
        assert "pip install 'lawbench[engines]'" in fresh.unavailable[engine]
