"""Jia's law on the examples of Jia's talk, its invariants, limits and numerical behaviour.

Sources: Y.-B. Jia, *Simultaneous three-dimensional impacts with friction and compliance*
(talk, 2012; shared/seeds/000): the bouncing ball, the pencil and the two-ball example of Jia,
Mason and Erdmann (IJRR 32(1), 2013); Jia, IJRR 32(1), 2013 for the tangential compliance.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lawbench
from lawbench import Contact, ImpactProblem
from lawbench.cases.bouncing_pencil import pencil_geometry

LAW = lawbench.LAWS.get("jia")
BALL = lawbench.CASES.get("bouncing_ball")
PENCIL = lawbench.CASES.get("bouncing_pencil")
# The talk's bouncing ball after the first impact, as extracted.
TALK_V = np.array([0.570982, 0.0, 2.5])
TALK_W = np.array([0.0, 1.92746, 0.0])


def ball_momentum_y(v):
    """Angular momentum about the contact point, y component: I wy + m r vx (m = r = 1)."""
    return 0.4 * v[4] + v[0]


# --- the bouncing ball --------------------------------------------------------------------------


def test_ball_rebounds_at_the_talks_normal_velocity():
    """Talk, bouncing ball: vz+ = 2.5 from vz- = -5 with e = 0.5. For a sphere the contact's
    normal direction is decoupled from the tangential ones (the Delassus matrix is diagonal),
    so the normal spring alone sets vz+ = -e vz-, whatever the friction: the one number of the
    talk's answer that the stated initial state determines by itself.
    """
    assert lawbench.solve("jia", "bouncing_ball").v_plus[2] == pytest.approx(TALK_V[2], abs=1e-9)
    for example in BALL.examples.values():
        params = BALL.parameters(**example)
        outcome = lawbench.solve("jia", "bouncing_ball", **params)
        expected = -params["e"] * params["velocity"][2]
        assert outcome.v_plus[2] == pytest.approx(expected, abs=1e-9)


def test_ball_tangential_numbers_of_the_talk_break_the_contact_point_invariant():
    """Derivation. Any impulse P applied at the contact point (0, 0, -r) keeps the angular
    momentum about that point, L = I w + (r e_z) x (m V), whose y component is
    L_y = I wy + m r vx (I = 2/5 m r^2 = 0.4 here). Before the talk's bounce
    L_y = 0.4 * 2 + 1 = 1.8; after it, with the talk's V and w, L_y = 0.4 * 1.92746 + 0.570982
    = 1.341966. No contact law can produce that pair from that initial state.

    Second argument: with the right-hand spin (0, 2, 0) the contact point slips at
    vx - r wy = -1 m/s; the tangential subsystem (effective mass 2/7 m) never gains energy, so
    the tangential impulse cannot point along the slip: vx must rise, while the talk's falls.

    The consistent reading: the talk's appendix writes w = w0 + 5/(2 m r) z x P, the right-hand
    rule with the spin reversed. In that sense (here w0 = (0, -2, 0)) the initial slip is +3 m/s
    and vx falls; the invariant then gives wy+ = (0.2 - 0.570982) / 0.4 = -0.927455, i.e.
    0.92746 in the talk's sense: the talk's 1.92746 less exactly one. The law itself, in that
    reading, ends with vx+ near -0.54 (the compliant contact reverses the tangential velocity),
    not 0.570982: that number is not reproduced, and the test states only the invariants.
    """
    before = ball_momentum_y(BALL.build().v)
    after_talk = 0.4 * TALK_W[1] + TALK_V[0]
    assert before == pytest.approx(1.8)
    assert abs(after_talk - before) > 0.45
    default = lawbench.solve("jia", "bouncing_ball")
    assert ball_momentum_y(default.v_plus) == pytest.approx(before, abs=1e-12)
    assert default.v_plus[0] > 1.0 > TALK_V[0]
    reversed_ = lawbench.solve("jia", "bouncing_ball", angular_velocity=[0.0, -2.0, 0.0])
    assert ball_momentum_y(reversed_.v_plus) == pytest.approx(0.2, abs=1e-12)
    assert reversed_.v_plus[0] < 1.0
    consistent_wy = (0.2 - TALK_V[0]) / 0.4
    assert -consistent_wy + 1.0 == pytest.approx(TALK_W[1], abs=1e-5)


@pytest.mark.parametrize("example", list(BALL.examples))
def test_ball_tangential_energy_never_grows(example):
    """Sphere on a plane: the tangential contact velocity changes by 7/(2m) Pt, decoupled from
    the normal one; sticking springs store energy, slipping dissipates it, and the springs are
    empty at the end, so |ut+| <= |ut-| and Pt . ut- <= 0 (the impulse opposes the first slip).
    """
    problem = BALL.build(**BALL.examples[example])
    outcome = LAW.resolve(problem)
    ut_after = problem.Wt.T @ outcome.v_plus
    assert np.linalg.norm(ut_after) <= np.linalg.norm(problem.ut) * (1 + 1e-9)
    assert outcome.Pt @ problem.ut <= 1e-12


def test_sphere_impulse_is_collinear_with_the_initial_slip():
    """Jia 2013 / talk, Theorem 1: for the sphere the tangential impulse stays collinear with
    the initial tangential contact velocity (the impulse curve lies in a vertical plane)."""
    problem = BALL.build(angular_velocity=[6.0, 6.0, 0.0])
    outcome = LAW.resolve(problem, path=True)
    direction = problem.ut / np.linalg.norm(problem.ut)
    normal = np.array([-direction[1], direction[0]])
    assert np.abs(outcome.path["Pt"] @ normal).max() <= 1e-9 * np.abs(outcome.Pt).max()


# --- the pencil ---------------------------------------------------------------------------------


def test_pencil_numbers_of_the_talk_cannot_come_from_an_impulse_at_its_tip():
    """Derivation. The pencil is symmetric about its axis a and touches the table with its tip,
    on that axis: rho = -l a from the centre of mass. An impulse P there changes the angular
    velocity by J^-1 (rho x P); rho x P is perpendicular to a, and J^-1 maps such vectors to
    themselves over the transverse inertia, so dw is perpendicular to a and to P, for any
    proportions and orientation. The talk's numbers: P = m dV = (-3.962, 0.3908, 5.5302)
    (matching its impulse curve's end (3.962, 0.3908, 5.5302) with x reversed) and
    dw = (0.2362, 1.8021, 0.5) - (1, 0.5, 0.5) = (-0.7638, 1.3021, 0), so dw . P = 3.54, a
    cosine of 0.34: not the change of an impulse at the tip. The law keeps dw . P = dw . a = 0.
    """
    v0 = 5 * np.array([math.cos(math.pi / 6), 0.0, -math.sin(math.pi / 6)])
    impulse = np.array([0.3681, 0.3908, 3.0302]) - v0
    np.testing.assert_allclose(np.abs(impulse), [3.962, 0.3908, 5.5302], atol=1e-4)
    dw = np.array([0.2362, 1.8021, 0.5]) - np.array([1.0, 0.5, 0.5])
    assert dw @ impulse / np.linalg.norm(dw) / np.linalg.norm(impulse) > 0.3
    for example in PENCIL.examples.values():
        params = PENCIL.parameters(**example)
        problem = PENCIL.build(**params)
        outcome = LAW.resolve(problem)
        impulse = problem.M[:3, :3] @ (outcome.v_plus - problem.v)[:3]
        dw = (outcome.v_plus - problem.v)[3:]
        axis = -pencil_geometry(params)[1]
        scale = np.linalg.norm(dw) * np.linalg.norm(impulse) + 1e-300
        assert abs(dw @ impulse) <= 1e-12 * scale
        assert abs(dw @ axis) <= 1e-12 * np.linalg.norm(dw) * np.linalg.norm(axis)


def test_pencil_slips_with_a_turning_direction():
    """Talk, bounce of a pencil: "slipping direction varies". At the default state the contact
    slips from the start and its impulse curve turns in the table's plane."""
    outcome = lawbench.solve("jia", "bouncing_pencil", {"path": True})
    assert outcome.diagnostics["sequence"][0] == "slip"
    Pt = outcome.path["Pt"]
    headings = np.arctan2(np.diff(Pt[:, 1]), np.diff(Pt[:, 0]))
    assert np.ptp(headings[np.linalg.norm(np.diff(Pt, axis=0), axis=1) > 1e-9]) > 0.05


# --- the two-ball example (Jia, Mason and Erdmann) ---------------------------------------------


def two_balls(m2, ratio, e=(1.0, 1.0), options=None):
    """The talk's scene on two_balls_wall: ball 1 (unit mass, unit speed) onto ball 2 at rest."""
    return lawbench.solve(
        "jia",
        "two_balls_wall",
        options,
        masses=[1.0, m2],
        velocities=[-1.0, 0.0],
        stiffness_ratio=ratio,
        e=list(e),
        exponent=1,
    )


def test_two_ball_numbers_of_the_talk_break_energy_conservation():
    """Derivation. The talk's example reads m1 = 1, m2 = 2/3, v0 = 1, k2/k1 = 1, e1 = e2 = 1
    and reports v1 = 0.94, v2 = 0.30 after. With e = 1 no stiffness ever changes, the model is
    two linear springs and conserves kinetic energy: T+ = T- = 1/2. The talk's pair gives
    T+ = 0.94^2 / 2 + (2/3) 0.30^2 / 2 = 0.4718, and at most 0.4775 within the rounding of
    its digits: 4.5 % short, so it cannot be the outcome of the stated example (it would need
    m2 between 1.15 and 1.44). The law conserves the energy on that scene and ends with
    ball 2 nearly at rest.
    """
    low, high = (0.945**2 + (2 / 3) * 0.305**2) / 2, 0.5
    assert low < high * 0.96
    outcome = two_balls(2 / 3, 1.0)
    assert outcome.dT == pytest.approx(0.0, abs=1e-9)
    assert outcome.v_plus[0] > 0.99 and 0 < outcome.v_plus[1] < 0.05


def spring_time_integration(m2, ratio):
    """Independent check: both linear springs integrated in time with the real gaps, e = 1."""

    def rate(t, s):
        ball_gap, wall_gap = s[0] - s[1], s[1]
        f1, f2 = max(0.0, -ball_gap), ratio * max(0.0, -wall_gap)
        return [s[2], s[3], f1, (f2 - f1) / m2]

    solution = solve_ivp(rate, (0, 60), [0, 0, -1.0, 0.0], rtol=1e-11, atol=1e-13, max_step=0.01)
    return solution.y[2:, -1]


@pytest.mark.parametrize(("m2", "ratio"), [(2 / 3, 1.0), (1.0, 3.0), (1.5, 3.0)])
def test_state_transitions_equal_linear_springs_in_time_when_no_gap_reopens(m2, ratio):
    """Jia, Mason and Erdmann: with e = 1 and no contact that opens and closes again, the state
    transitions are the two linear springs integrated in time (here with scipy, real gaps)."""
    outcome = two_balls(m2, ratio)
    assert "end of impact" in outcome.diagnostics["sequence"]
    np.testing.assert_allclose(outcome.v_plus, spring_time_integration(m2, ratio), atol=1e-5)


def test_reactivation_ignores_the_gap_the_springs_opened():
    """A contact reactivates as soon as its gap rate turns negative (the impact takes no time),
    while springs integrated in time wait for the gap they opened to close: with a soft wall
    (k2/k1 = 1/3, m2 = 2/3) contact 0 separates and returns, and the two answers differ, both
    conserving energy.
    """
    outcome = two_balls(2 / 3, 1 / 3)
    in_time = spring_time_integration(2 / 3, 1 / 3)
    assert outcome.diagnostics["sequence"].count("{0, 1}") >= 2
    assert np.abs(outcome.v_plus - in_time).max() > 0.05
    for v in (outcome.v_plus, in_time):
        assert (v[0] ** 2 + (2 / 3) * v[1] ** 2) / 2 == pytest.approx(0.5, abs=1e-6)


def test_two_balls_depend_on_stiffness_ratio_masses_ratio_and_linearly_on_speed():
    """Talk, Theorem 2: the outcome depends on the stiffness ratio, not on the stiffnesses; it
    does not change when both masses scale; the post/pre velocity ratio is constant."""
    base = two_balls(1.5, 2.0, e=(0.9, 0.7)).v_plus

    def problem(k1, masses, speed):
        return ImpactProblem(
            M=np.diag(masses),
            Wn=[[1.0, 0.0], [-1.0, 1.0]],
            v=[-speed, 0.0],
            contacts=[
                Contact(e=0.9, stiffness=k1, exponent=1),
                Contact(e=0.7, stiffness=2 * k1, exponent=1),
            ],
        )

    for k1, scale, speed in [(1e4, 1.0, 1.0), (1.0, 7.0, 1.0), (1.0, 1.0, 3.0)]:
        outcome = LAW.resolve(problem(k1, [scale, 1.5 * scale], speed))
        np.testing.assert_allclose(outcome.v_plus, speed * base, rtol=1e-8, atol=1e-10)


def test_two_ball_impulse_curve_stays_in_the_energy_ellipse():
    """Talk, Theorem 3: the impulses (I1, I2) stay in the ellipse
    I1^2 / (2 m1) + (I1 - I2)^2 / (2 m2) - v0 I1 <= 0 (kinetic energy never above T-), and
    ball 2, at rest on the table, is pushed only after ball 1 loads it.
    """
    m2 = 2 / 3
    outcome = two_balls(m2, 1.0, e=(0.9, 0.7), options={"path": True})
    I1, I2 = outcome.path["Pn"].T
    ellipse = I1**2 / 2 + (I1 - I2) ** 2 / (2 * m2) - I1
    assert ellipse.max() <= 1e-9
    assert outcome.diagnostics["sequence"][:2] == ["{0}", "{0, 1}"]
    assert outcome.path["En"][-1] == pytest.approx([0.0, 0.0], abs=1e-12)


@pytest.mark.parametrize(("case", "params"), [("three_ball_chain", {}), ("ball_chain", {})])
def test_plastic_chains_move_as_one(case, params):
    """e = 0: each contact becomes infinitely stiff at its end of compression and locks, so the
    balls it joins move as one; struck from one end, the free chain ends at the momentum
    average, the answer of every plastic law (Brogliato 2010, three-ball chain at e = 0)."""
    outcome = lawbench.solve("jia", case, e=[0.0], **params)
    problem = lawbench.CASES.get(case).build(e=[0.0], **params)
    common = problem.M.diagonal() @ problem.v / problem.M.diagonal().sum()
    np.testing.assert_allclose(outcome.v_plus, common, atol=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_chain_energy_balance(seed):
    """Frictionless chains lose kinetic energy only at the ends of compression (and at locks):
    -dT equals the recorded compression loss; no contact approaches after, no impulse pulls."""
    rng = np.random.default_rng(seed)
    n = 6
    params = {
        "n": n,
        "masses": (10 ** rng.uniform(-1, 1, n)).tolist(),
        "e": rng.uniform(0, 0.9, n - 1).tolist(),
        "velocities": np.sort(rng.normal(size=n))[::-1].tolist(),
    }
    outcome = lawbench.solve("jia", "ball_chain", **params)
    problem = lawbench.CASES.get("ball_chain").build(**params)
    assert -outcome.dT == pytest.approx(outcome.diagnostics["compression_loss"], rel=1e-8)
    assert (problem.Wn.T @ outcome.v_plus).min() >= -1e-8 * np.abs(problem.un).max()
    assert outcome.Pn.min() >= 0


@pytest.mark.parametrize("striker", [1e-6, 1e-3])
def test_a_light_striker_keeps_the_energy_at_the_default_tolerance(striker):
    """An elastic three-ball chain struck by a ball 1e3 or 1e6 times lighter: the springs are
    conservative, so the energy is kept to the checks' 1e-9. The integrator's absolute
    tolerance follows the impulse of the lightest contact (the striker's, of order 1e-6 N s
    here), not that of the heaviest: with the heaviest's it lost 3e-9 and created 2.2e-8."""
    outcome = lawbench.solve("jia", "three_ball_chain", masses=[striker, 1.0, 1.0], e=1.0)
    assert abs(outcome.dT) <= 1e-9 * outcome.T_minus


# The slowest approach integrates for seconds: it is in the slow profile.
@pytest.mark.parametrize("speed", [1e-4, 1e-6, pytest.param(1e-8, marks=pytest.mark.slow)])
def test_a_grazing_approach_under_a_fast_slip_keeps_the_friction_cone(speed):
    """The falling rod's end slides at about 1 m/s while it approaches the floor at ``speed``:
    the friction impulse stays within mu Pn, both of order ``speed`` times a mass. The
    integrator's absolute tolerance follows the normal approach; with the slip speed's it left
    |Pt| 1.7e-4 beyond the cone at 1e-8 m/s."""
    from lawbench.core.transforms import apply

    problem = apply(f"grazing={speed}", lawbench.CASES.get("falling_rod").build(e=1.0))
    outcome = lawbench.LAWS.get("jia").resolve(problem)
    Pt = np.abs(outcome.Pt).max()
    assert Pt <= problem.mu[0] * outcome.Pn[0] * (1 + 1e-9)
    assert outcome.Pn[0] > 0


def test_a_long_elastic_chain_keeps_energy_and_momentum_with_banded_products():
    """A 250-ball elastic chain, its Delassus matrix multiplied as a sparse, banded one: the
    springs keep the energy (to the tolerance) and the momentum, and no contact approaches."""
    params = {"n": 250, "e": 1.0, "velocities": [1.0]}
    outcome = lawbench.solve("jia", "ball_chain", **params)
    problem = lawbench.CASES.get("ball_chain").build(**params)
    assert abs(outcome.dT) <= 1e-9 * outcome.T_minus
    assert abs(problem.M.diagonal() @ (outcome.v_plus - problem.v)) <= 1e-10
    assert (problem.Wn.T @ outcome.v_plus).min() >= -1e-8 * np.abs(problem.un).max()


# --- invariants on random problems --------------------------------------------------------------


def random_contact(rng, d, e, mu, ratio):
    """A random single-contact problem: SPD mass matrix, random Jacobians, approaching."""
    n = 6
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    Wn, Wt = rng.normal(size=(n, 1)), rng.normal(size=(n, d))
    v = rng.normal(size=n)
    v -= Wn[:, 0] * (Wn[:, 0] @ v + rng.uniform(0.5, 2)) / (Wn[:, 0] @ Wn[:, 0])
    contact = Contact(e=e, mu=mu, tangential_stiffness_ratio=ratio)
    return ImpactProblem(M=M, Wn=Wn, Wt=Wt, v=v, contacts=[contact])


@pytest.mark.parametrize("seed", range(12))
def test_random_contacts_keep_energy_cone_and_admissibility(seed):
    """For e <= 1 the springs only lose energy (the ends of compression and slip), every
    increment of tangential impulse lies in the cone, and the contact leaves separating."""
    rng = np.random.default_rng(seed)
    d = 1 + seed % 2
    problem = random_contact(rng, d, rng.uniform(0, 1), rng.uniform(0.05, 1.5), rng.uniform(0.3, 3))
    outcome = LAW.resolve(problem, path=True)
    assert outcome.dT <= 1e-9 * outcome.T_minus
    assert np.linalg.norm(outcome.Pt) <= problem.mu[0] * outcome.Pn[0] * (1 + 1e-9)
    steps_t = np.linalg.norm(np.diff(outcome.path["Pt"], axis=0), axis=1)
    steps_n = np.diff(outcome.path["Pn"][:, 0])
    assert np.all(steps_t <= problem.mu[0] * steps_n * (1 + 1e-6) + 1e-12)
    assert (problem.Wn.T @ outcome.v_plus)[0] >= -1e-9 * abs(problem.un[0])
    assert outcome.Pn[0] > 0


def test_energy_balance_of_the_compression_loss():
    """Frictionless, one contact: the only loss is at the end of compression, (1 - e^2) E_max,
    which is the kinetic energy lost."""
    problem = BALL.build(mu=0.0, e=0.3)
    outcome = LAW.resolve(problem, path=True)
    assert outcome.diagnostics["compression_loss"] == pytest.approx(-outcome.dT, rel=1e-9)


# --- limits with a closed form ------------------------------------------------------------------


@pytest.mark.parametrize("case", ["bouncing_ball", "bouncing_pencil"])
def test_frictionless_limit_is_the_closed_form(case):
    """mu = 0: no tangential impulse, the normal spring gives un+ = -e un- (the frictionless
    bounce reference of the case); the integrated impulse curve (option path) agrees."""
    entry = lawbench.CASES.get(case)
    params = entry.parameters(mu=0.0)
    expected = entry.references[0].v_plus(params)
    closed = lawbench.solve("jia", case, mu=0.0)
    integrated = lawbench.solve("jia", case, {"path": True}, mu=0.0)
    assert closed.diagnostics["formulation"] == "closed form"
    np.testing.assert_allclose(closed.v_plus, expected, atol=1e-12)
    np.testing.assert_allclose(integrated.v_plus, expected, atol=1e-8)


def test_gross_slip_is_rigid_coulomb_at_any_tangential_stiffness():
    """A slip that never stops: dPt = -mu dPn along the initial slip direction throughout, so
    Pt = -mu (1 + e) m |vz-| (the rigid Coulomb answer) for any eta0^2."""
    for ratio in (0.2, 1.2, 5.0):
        problem = BALL.build(velocity=[20.0, 0.0, -1.0], mu=0.1, tangential_stiffness_ratio=ratio)
        outcome = LAW.resolve(problem)
        assert outcome.diagnostics["sequence"] == ["slip", "end of compression", "end of impact"]
        np.testing.assert_allclose(outcome.Pt, [-0.1 * 1.5, 0.0], atol=1e-10)


def test_infinitely_stiff_tangential_springs_give_rigid_rolling():
    """eta0^2 -> 0: the tangential springs become rigid and the model tends to rigid Coulomb
    friction with the energetic coefficient. The ball (default state) then stops slipping and
    leaves rolling, vx+ = r wy+, with the invariant L_y = 1.8: vx+ = 1.8 / 1.4. The error
    falls with eta0^2."""
    rolling = 1.8 / 1.4
    errors = [
        abs(LAW.resolve(BALL.build(tangential_stiffness_ratio=ratio)).v_plus[0] - rolling)
        for ratio in (1e-2, 1e-3, 1e-4)
    ]
    assert errors[2] < errors[1] < errors[0] and errors[2] < 1e-3


# --- numerics -----------------------------------------------------------------------------------


def test_tolerance_converges():
    """The accuracy knob: the answer approaches a tight reference as the tolerance shrinks."""
    problem = BALL.build(angular_velocity=[0.0, -2.0, 0.0])
    reference = LAW.resolve(problem, tol=1e-13).v_plus
    errors = [
        np.abs(LAW.resolve(problem, tol=tol).v_plus - reference).max() for tol in (1e-5, 1e-7, 1e-9)
    ]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-7


def test_deterministic():
    first = lawbench.solve("jia", "bouncing_pencil", {"path": True})
    second = lawbench.solve("jia", "bouncing_pencil", {"path": True})
    assert np.array_equal(first.v_plus, second.v_plus)
    assert np.array_equal(first.path["Pt"], second.path["Pt"])
    assert first.diagnostics["sequence"] == second.diagnostics["sequence"]


def test_path_fields():
    outcome = lawbench.solve("jia", "bouncing_ball", {"path": True})
    path = outcome.path
    k = path["tau"].size
    assert path["Pn"].shape == (k, 1) and path["Pt"].shape == (k, 2)
    assert path["En"].shape == (k, 1) and path["Et"].shape == (k, 1)
    assert path["un"].shape == (k, 1) and path["ut"].shape == (k, 2)
    np.testing.assert_allclose(path["Pn"][-1], outcome.Pn, rtol=1e-12)
    assert path["En"][-1, 0] == pytest.approx(0.0, abs=1e-12)
    assert outcome.diagnostics["steps"] > 0


def test_a_rigid_contact_among_several_frictional_ones_is_refused_with_the_reason():
    """With friction at several contacts, a contact that turns rigid (e = 0: the rocking
    block's plastic landing) would need a lock of its tangential springs too: refused."""
    with pytest.raises(lawbench.NotApplicable, match=r"turns rigid .* friction at several"):
        LAW.resolve(lawbench.CASES.get("rocking_block").build())


BILLIARD_SHOTS = {
    "straight": {},
    "side spin": {"offset_side": 0.01},
    "masse": {"elevation": 70.0, "offset_side": 0.012, "offset_height": 0.005},
    "draw, soft table": {"elevation": 30.0, "offset_height": -0.01, "stiffness_ratio": 0.2},
}


@pytest.mark.parametrize("shot", list(BILLIARD_SHOTS.values()), ids=list(BILLIARD_SHOTS))
def test_the_billiard_shot_is_the_compliant_springs_in_impulse_space(shot):
    """Jia's talk (2012), part III: at the cue-ball and ball-table contacts the normal springs
    and each contact's tangential springs, integrated along the normal impulses. At e = 1 with
    linear springs they are exactly the springs that compliant contact integrates in time (a
    separate implementation), so the two answers agree; the velocity to 1e-6 of the cue's
    speed.
    """
    case = lawbench.CASES.get("billiard")
    problem = case.build(**shot, e=1.0, exponent=1.0)
    springs = LAW.resolve(problem)
    in_time = lawbench.LAWS.get("compliant").resolve(problem, model="kelvin_voigt", tol=1e-10)
    np.testing.assert_allclose(springs.v_plus, in_time.v_plus, rtol=0, atol=3e-6)
    np.testing.assert_allclose(springs.Pt, in_time.Pt, rtol=0, atol=1e-6)
    assert springs.dT == pytest.approx(in_time.dT, abs=1e-6 * springs.T_minus)


@pytest.mark.parametrize("shot", list(BILLIARD_SHOTS.values()), ids=list(BILLIARD_SHOTS))
def test_the_billiard_shot_keeps_each_contact_in_its_cone_and_creates_no_energy(shot):
    """Coulomb's bound holds at each contact along the whole impact (Jia 2013: the spring force
    never exceeds mu F_n), and the springs only give back what they stored."""
    outcome = LAW.resolve(lawbench.CASES.get("billiard").build(**shot), path=True)
    mu = np.array([0.6, 0.2])
    Pt = outcome.Pt.reshape(2, 2)
    assert np.all(np.linalg.norm(Pt, axis=1) <= mu * outcome.Pn * (1 + 1e-9) + 1e-12)
    dPn = np.diff(outcome.path["Pn"], axis=0)
    dPt = np.linalg.norm(np.diff(outcome.path["Pt"], axis=0).reshape(-1, 2, 2), axis=2)
    assert np.all(dPt <= mu * dPn * (1 + 1e-6) + 1e-9)
    assert outcome.dT <= 1e-12 * outcome.T_minus


@pytest.mark.parametrize("ratio", [1e-12, 1e-8, 1e-4, 1e4, 1e8, 1e12])
def test_elastic_chain_keeps_energy_at_extreme_stiffness_ratios(ratio):
    """Three equal balls, e = 1, k2/k1 from 1e-12 to 1e12: energy kept and the spring limits.

    Brogliato 2010 (linear-spring limits of the three-ball chain): a soft second contact lets
    the stiff first one act alone, so the impacts are sequential and the last ball leaves with
    the first's velocity, (0, 0, 1); a stiff second contact holds balls 2 and 3 together while
    ball 1 rebounds off their sum, (-1/3, 2/3, 2/3).
    """
    outcome = lawbench.solve("jia", "three_ball_chain", stiffness_ratio=ratio, e=1.0)
    assert abs(outcome.dT) <= 1e-9 * outcome.T_minus
    limit = [0.0, 0.0, 1.0] if ratio < 1 else [-1 / 3, 2 / 3, 2 / 3]
    np.testing.assert_allclose(outcome.v_plus, limit, atol=1e-4)


def test_stiff_contact_in_an_inelastic_chain_tends_to_one_limit():
    """k2/k1 from 1e-6 to 1e-12 at e = 0.5: one answer, the lzb law's at 1e-6.

    Jia, Mason and Erdmann 2013, Theorem 4: a stiff contact kept loaded by its neighbours
    rebounds again and again and tends to a rigid, plastic contact; a spring that empties at
    the instant a locked contact releases must still separate.
    """
    answers = [
        lawbench.solve("jia", "three_ball_chain", stiffness_ratio=r, e=0.5).v_plus
        for r in (1e-6, 1e-8, 1e-10, 1e-12)
    ]
    for answer in answers[1:]:
        np.testing.assert_allclose(answer, answers[0], atol=1e-5)
    lzb = lawbench.solve("lzb", "three_ball_chain", stiffness_ratio=1e-6, e=0.5, exponent=1.0)
    np.testing.assert_allclose(answers[0], lzb.v_plus, atol=1e-4)


@pytest.mark.parametrize("mass", [0.2, 1.0, 5.0])
def test_two_springs_on_one_degree_of_freedom_end_compression_together(mass):
    # Both gap rates are multiples of the one velocity: both springs end compression at one
    # instant, whatever the unit of mass.
    p = lawbench.ImpactProblem.from_arrays(
        mass * np.eye(1), [[-0.819647, -2.492872]], v=[1.0], e=[0.46, 0.691]
    )
    outcome = lawbench.solve("jia", p)
    assert outcome.v_plus == pytest.approx([-0.67196848], rel=1e-6)
    assert (outcome.Pn >= 0).all()


def test_double_pendulum_is_continuous_as_mu_vanishes():
    # The stretch of the tangential springs is resolved at the scale of its stick bound, so a
    # tiny mu neither chatters between stick and slip nor leaves the frictionless answer.
    frictionless = lawbench.solve("jia", "double_pendulum", mu=0.0).v_plus
    for mu in (1e-8, 1e-6):
        v_plus = lawbench.solve("jia", "double_pendulum", mu=mu).v_plus
        assert v_plus == pytest.approx(frictionless, rel=1e-5)


def test_contacts_of_different_exponents_are_refused():
    """The springs read only the ratios of the contacts' stiffnesses: a stiffness in N/m over
    one in N/m^1.5 depends on the unit of length, and so did the outcome (this problem's in
    millimetres was 15 % of the largest velocity away from its answer in metres)."""
    problem = ImpactProblem(
        M=np.diag([1.0, 1.5]),
        Wn=[[1.0, 0.0], [-1.0, 1.0]],
        v=[-1.0, 0.0],
        contacts=[Contact(e=0.9, exponent=1.0), Contact(e=0.7, stiffness=2.0, exponent=1.5)],
    )
    with pytest.raises(lawbench.NotApplicable, match=r"force exponents differ \(1, 1\.5\)"):
        LAW.resolve(problem)


def test_a_spring_whose_period_leaves_double_precision_is_refused_by_name():
    """A stiffness ratio of 5e-324 gave a frequency of 0: a ZeroDivisionError inside the law."""
    with pytest.raises(lawbench.NotApplicable, match="period beyond double precision"):
        lawbench.solve("jia", "two_balls_wall", stiffness_ratio=5e-324)
