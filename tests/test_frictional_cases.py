"""The frictional scenes: geometry and Jacobians by hand, the lectures' formulas, bad input."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import lawbench
from lawbench import InvalidProblem
from lawbench.cases.falling_rod import impulse_response
from lawbench.cases.rocking_block import housner_ratio, sticking_ratio

CASES = ("rocking_block", "falling_rod", "double_pendulum", "sphere_wall")


def build(case, **params):
    return lawbench.CASES.get(case).build(**params)


def local_velocities(problem, v):
    """Normal and tangential velocities of the contact points (contact-point kinematics)."""
    return problem.Wn.T @ v, problem.Wt.T @ v


# 1. Geometry and Jacobians against hand computations


def test_rocking_block_corners_move_as_a_rotation_about_the_pivot():
    """Before the impact the pivot (right corner) is at rest, the left corner comes down."""
    w, h, m, omega = 0.6, 1.4, 3.0, 2.0
    problem = build("rocking_block", width=w, height=h, mass=m, omega=omega)
    vx, vy, wz = problem.v
    # Corner velocity v + omega x r, r = (-w/2, -h/2) and (w/2, -h/2).
    landing = np.array([vx + wz * h / 2, vy - wz * w / 2])
    pivot = np.array([vx + wz * h / 2, vy + wz * w / 2])
    np.testing.assert_allclose(pivot, 0.0, atol=1e-15)
    np.testing.assert_allclose(landing, [0.0, -omega * w], atol=1e-15)
    un, ut = local_velocities(problem, problem.v)
    np.testing.assert_allclose(un, [landing[1], pivot[1]], atol=1e-15)
    np.testing.assert_allclose(ut, [landing[0], pivot[0]], atol=1e-15)
    np.testing.assert_allclose(np.diag(problem.M), [m, m, m * (w * w + h * h) / 12])
    np.testing.assert_allclose(problem.Wn.T, [[0, 1, -w / 2], [0, 1, w / 2]])
    np.testing.assert_allclose(problem.Wt.T, [[1, 0, h / 2], [1, 0, h / 2]])


@pytest.mark.parametrize(("width", "height"), [(1.0, math.sqrt(2.0)), (1.0, 1.0), (0.3, 2.0)])
def test_rocking_block_corners_are_kinetically_orthogonal_iff_l_is_sqrt2_L(width, height):
    """Brogliato 2010, rocking block: the constraints are orthogonal iff l = sqrt(2) L."""
    G = build("rocking_block", width=width, height=height, mass=2.0).delassus
    expected = (height**2 - 2 * width**2) / (2.0 * (width**2 + height**2))
    assert G[0, 1] == pytest.approx(expected, abs=1e-15)
    assert (abs(G[0, 1]) < 1e-14) == math.isclose(height, math.sqrt(2) * width)


def test_falling_rod_jacobians_are_equation_7():
    """Brogliato 2010, eq. (7): (0, 1, l sin theta), (1, 0, l cos theta), theta from vertical."""
    length, angle = 1.6, 35.0
    problem = build("falling_rod", length=length, angle=angle, mass=2.0)
    half, theta = length / 2, math.radians(90.0 - angle)
    np.testing.assert_allclose(problem.Wn[:, 0], [0, 1, half * math.sin(theta)], atol=1e-15)
    np.testing.assert_allclose(problem.Wt[:, 0], [1, 0, half * math.cos(theta)], atol=1e-15)
    np.testing.assert_allclose(np.diag(problem.M), [2.0, 2.0, 2.0 * half**2 / 3])
    # The lower end: (x + l sin theta, y - l cos theta); its velocity by hand.
    vx, vy, omega = 0.3, -1.2, 0.7
    problem = build("falling_rod", length=length, angle=angle, velocities=[vx, vy, omega])
    un, ut = local_velocities(problem, problem.v)
    assert un[0] == pytest.approx(vy + half * math.sin(theta) * omega)
    assert ut[0] == pytest.approx(vx + half * math.cos(theta) * omega)


def test_double_pendulum_free_end_and_mass_matrix_by_hand():
    """Free end velocity l1 w1 (cos t1, sin t1) + l2 w2 (cos t2, sin t2); uniform links."""
    (l1, l2), (m1, m2), (t1, t2), (w1, w2) = (0.8, 1.3), (2.0, 0.5), (50.0, -20.0), (1.5, -2.5)
    problem = build(
        "double_pendulum", lengths=[l1, l2], masses=[m1, m2], angles=[t1, t2], omegas=[w1, w2]
    )
    a, b = math.radians(t1), math.radians(t2)
    end = l1 * w1 * np.array([math.cos(a), math.sin(a)]) + l2 * w2 * np.array(
        [math.cos(b), math.sin(b)]
    )
    un, ut = local_velocities(problem, problem.v)
    np.testing.assert_allclose([ut[0], un[0]], end, atol=1e-15)
    M = np.array(
        [
            [m1 * l1**2 / 3 + m2 * l1**2, m2 * l1 * l2 / 2 * math.cos(a - b)],
            [m2 * l1 * l2 / 2 * math.cos(a - b), m2 * l2**2 / 3],
        ]
    )
    np.testing.assert_allclose(problem.M, M, atol=1e-15)


def test_sphere_contact_point_velocity_by_hand():
    """Contact point velocity v + w x r, r = -radius n, n = (0, 1, 0); tangents x and z."""
    radius, speed, angle, spin = 0.2, 3.0, 30.0, [1.0, -2.0, 4.0]
    problem = build("sphere_wall", radius=radius, speed=speed, angle=angle, spin=spin)
    v = speed * np.array([math.sin(math.radians(angle)), -math.cos(math.radians(angle)), 0.0])
    point = v + np.cross(spin, [0.0, -radius, 0.0])
    un, ut = local_velocities(problem, problem.v)
    assert un[0] == pytest.approx(point[1])
    np.testing.assert_allclose(ut, [point[0], point[2]], atol=1e-15)
    np.testing.assert_allclose(ut, [v[0] + radius * spin[2], -radius * spin[0]], atol=1e-15)


# 2. The rocking block: the lectures' one-contact formulas and Housner's ratio


def one_contact_printed(width, height, e):
    """Brogliato 2010, after eq. (24), as printed (L = width, l = height): vy+/vy-, w+/w-."""
    L2, l2 = width**2, height**2
    vy = (2 * L2 - l2 - 2 * e * (L2 + l2)) / (l2 + 4 * L2)
    omega = (-(2 * e + 1) * (L2 + l2) + 4 * (l2 + L2)) / (4 * l2 + 16 * L2)
    return vy, omega


@pytest.mark.parametrize("e", [0.0, 0.4, 1.0])
@pytest.mark.parametrize(("width", "height"), [(0.5, 1.0), (0.2, 1.0), (1.0, 1.5)])
def test_moreau_without_friction_gives_the_lectures_one_contact_formulas(e, width, height):
    """Brogliato 2010, after eq. (24): vy+ as printed; omega+ derived again (see below).

    The frictionless rule at the landing corner alone is Moreau's law at both corners when the
    pivot separates (height >= sqrt(2) width); the tangential velocity vx is kept.
    """
    params = {"width": width, "height": height, "e": e, "mu": 0.0, "omega": 1.3}
    trial = lawbench.evaluate("moreau", "rocking_block", **params)
    v, v_plus = trial.problem.v, trial.outcome.v_plus
    vy_ratio, _ = one_contact_printed(width, height, e)
    L2, l2 = width**2, height**2
    omega_ratio = (l2 - 2 * L2 - 6 * e * L2) / (l2 + 4 * L2)
    np.testing.assert_allclose(
        v_plus, [v[0], vy_ratio * v[1], omega_ratio * v[2]], rtol=1e-12, atol=1e-14
    )
    assert trial.outcome.Pn[1] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("model", ["hunt_crossley", "kelvin_voigt"])
def test_plastic_compliant_corners_reach_housner_as_their_tangential_springs_stiffen(model):
    """Housner 1963 is the rigid limit of the ground truth: plastic compliant corners (e = 0)
    whose tangential springs are 1e4 times stiffer than the normal ones keep the angular
    momentum about the landing corner, omega+ = ratio omega- (0.7 here) to 1e-4. At Mindlin's
    ratio (eta0^2 = 17/14) the tangential spring still holds energy when the landing corner
    lets go and releases it: omega+ is 0.44."""
    problem = lawbench.CASES["rocking_block"].build()
    errors = []
    for ratio in (17 / 14, 1e-2, 1e-4):
        contacts = [
            dataclasses.replace(c, tangential_stiffness_ratio=ratio) for c in problem.contacts
        ]
        stiff = dataclasses.replace(problem, contacts=tuple(contacts))
        outcome = lawbench.LAWS["compliant"].resolve(stiff, model=model)
        errors.append(abs(outcome.v_plus[2] - housner_ratio(0.5, 1.0)))
    assert errors[2] < 1e-4
    assert errors[2] < errors[1] < errors[0]
    assert errors[0] > 0.2


def test_the_printed_omega_formula_does_not_conserve_energy_at_e_1():
    """Why omega+ is derived again: with e = 1 the printed ratio loses energy (L = l = 1).

    vy+ = -3/5 vy- (printed) with the printed omega+ = omega-/10 keeps 1.1/5 of the energy;
    the derived omega+ = -7/5 omega- keeps all of it: 3 (9/25) + 2 (49/25) = 5.
    """
    vy, omega_printed = one_contact_printed(1.0, 1.0, 1.0)
    # T / (m omega^2 / 24) with vy- = omega L / 2, I = m (L^2 + l^2) / 12.
    energy = lambda a, b: 3 * a * a + 2 * b * b  # noqa: E731
    assert energy(1.0, 1.0) == pytest.approx(5.0)
    assert energy(vy, omega_printed) == pytest.approx(1.1)
    assert energy(vy, -7 / 5) == pytest.approx(5.0)


@pytest.mark.parametrize(("width", "height"), [(1.0, 1.0), (0.5, 1.0), (0.2, 2.0), (1.3, 1.0)])
def test_housner_ratio_keeps_the_angular_momentum_about_the_landing_corner(width, height):
    """Housner 1963: L about the landing corner before = (I + m d^2) omega+ after.

    Also the textbook crate (width = height): omega+ = omega- / 4.
    """
    m, omega = 2.0, 1.0
    inertia = m * (width**2 + height**2) / 12
    vx, vy = -omega * height / 2, -omega * width / 2
    # Centre relative to the landing corner: (width/2, height/2).
    before = inertia * omega + m * (width / 2 * vy - height / 2 * vx)
    about_corner = inertia + m * (width**2 + height**2) / 4
    assert housner_ratio(width, height) == pytest.approx(before / about_corner / omega)
    if width == height:
        assert housner_ratio(width, height) == pytest.approx(0.25)


@pytest.mark.parametrize(("width", "height"), [(0.5, 1.0), (1.0, 1.0), (0.25, 2.0)])
def test_housner_friction_need_is_the_impulse_ratio_of_the_sticking_impact(width, height):
    """|Pt| / Pn of rotating about the landing corner at Housner's ratio, by momentum change."""
    omega, ratio = 1.0, housner_ratio(width, height)
    before = np.array([-omega * height / 2, -omega * width / 2])
    after = ratio * omega * np.array([-height / 2, width / 2])
    impulse = after - before  # per unit mass
    assert abs(impulse[0]) / impulse[1] == pytest.approx(sticking_ratio(width, height))


@pytest.mark.parametrize(("width", "height"), [(0.5, 1.0), (1.0, 1.0), (0.2, 1.0)])
def test_moreau_with_sticking_friction_gives_housner(width, height):
    """Housner 1963 with e = 0 and mu above the sticking ratio: omega+ = ratio omega-."""
    mu = 1.01 * sticking_ratio(width, height)
    params = {"width": width, "height": height, "e": 0.0, "mu": mu}
    outcome = lawbench.solve("moreau", "rocking_block", **params)
    assert outcome.v_plus[2] == pytest.approx(housner_ratio(width, height), rel=1e-9)


# 3. The falling rod: equation (9) and its conditions


def energy_change(params, ratio):
    """Eq. (9) rederived: dT = pn ((1 - e) un- + r (2 ut- + (Gnt + r Gtt) pn)) / 2, r = pt/pn."""
    m, half = params["mass"], params["length"] / 2
    theta = math.radians(90.0 - params["angle"])
    s, c = math.sin(theta), math.cos(theta)
    vx, vy, omega = params["velocities"]
    un, ut = vy + half * s * omega, vx + half * c * omega
    g_nn, g_nt, g_tt = (1 + 3 * s * s) / m, 3 * s * c / m, (1 + 3 * c * c) / m
    assert g_nn + ratio * g_nt > 0, "eq. (9) needs a positive normal impulse"
    pn = -(1 + params["e"]) * un / (g_nn + ratio * g_nt)
    return pn * ((1 - params["e"]) * un + ratio * (2 * ut + (g_nt + ratio * g_tt) * pn)) / 2


def rod_grid():
    yield lawbench.CASES.get("falling_rod").examples["energy gain"]
    rng = np.random.default_rng(11)
    for _ in range(60):
        yield {
            "length": float(rng.uniform(0.5, 2)),
            "mass": float(rng.uniform(0.5, 3)),
            "angle": float(rng.uniform(10, 80)),
            "velocities": [
                float(rng.normal()),
                -float(rng.uniform(0.2, 2)),
                float(rng.normal(0, 3)),
            ],
            "e": float(rng.uniform(0.5, 1)),
            "mu": float(rng.uniform(0.1, 0.8)),
        }


@pytest.mark.parametrize("law", ["brach", "whittaker"])
def test_falling_rod_energy_change_is_equation_9_and_gains_only_by_reversal(law):
    """Brogliato 2010, eq. (9) and the remark after it: dT is a function of the ratio pt/pn;
    a slipping impact (|pt| = mu pn) can gain energy only when the slip reverses."""
    if law not in lawbench.LAWS:
        pytest.skip(f"{law} is not registered")
    gains = 0
    for params in rod_grid():
        case = lawbench.CASES.get("falling_rod")
        full = case.parameters(**params)
        try:
            trial = lawbench.evaluate(law, case, **full)
        except lawbench.NotApplicable:
            continue
        outcome, problem = trial.outcome, trial.problem
        if problem.un[0] >= 0:
            continue
        ratio = outcome.Pt[0] / outcome.Pn[0]
        assert outcome.dT == pytest.approx(energy_change(full, ratio), rel=1e-9, abs=1e-12)
        slipping = math.isclose(abs(ratio), full["mu"], rel_tol=1e-9)
        if outcome.dT > 1e-12 * outcome.T_minus and slipping:
            gains += 1
            assert (problem.Wt[:, 0] @ outcome.v_plus) * problem.ut[0] < 0
    assert gains > 0


def test_falling_rod_closed_form_matches_the_energy_gain_example():
    """The 'energy gain' example: Brach's slip reverses and the energy grows (eq. 8 and 9)."""
    case = lawbench.CASES.get("falling_rod")
    params = case.parameters(**case.examples["energy gain"])
    outcome = lawbench.solve("brach", case, **params)
    ratio = -params["mu"] * math.copysign(1.0, -0.5)  # pre-impact slip ut- = -0.5 m/s
    _, v_plus, ut_plus = impulse_response(params, ratio)
    np.testing.assert_allclose(outcome.v_plus, v_plus, rtol=1e-12)
    assert ut_plus > 0 and outcome.dT > 0
    assert outcome.dT == pytest.approx(energy_change(params, ratio), rel=1e-12)


# 4. The double pendulum: Whittaker's law gains energy at the defaults


def whittaker_by_hand(problem):
    """Every consistent mode of Newton + Coulomb on the post-impact slip at one planar contact."""
    G, un, ut = problem.contact_delassus, problem.un[0], problem.ut[0]
    e, mu = problem.contacts[0].e, problem.contacts[0].mu
    answers = []
    for ratio in (mu, -mu):
        pn = -(1 + e) * un / (G[0, 0] + ratio * G[0, 1])
        if pn > 0 and ratio * (ut + (G[0, 1] + ratio * G[1, 1]) * pn) < 0:
            answers.append((pn, ratio * pn))
    pn, pt = np.linalg.solve(G, [-(1 + e) * un, -ut])
    if pn > 0 and abs(pt) <= mu * pn:
        answers.append((pn, pt))
    return [
        problem.v + problem.solve_mass(problem.Wn[:, 0] * pn + problem.Wt[:, 0] * pt)
        for pn, pt in answers
    ]


def test_double_pendulum_defaults_make_whittakers_law_gain_energy():
    """Kane and Levinson 1985 (Brogliato 2010, after eq. 9): Newton + Coulomb gains energy.

    Solved by hand: one consistent mode; the slip reverses; T+ > T-.
    """
    problem = build("double_pendulum")
    assert problem.un[0] < 0
    (v_plus,) = whittaker_by_hand(problem)
    gain = (v_plus @ problem.M @ v_plus) / (problem.v @ problem.M @ problem.v) - 1
    assert gain > 0.05
    assert (problem.Wt[:, 0] @ v_plus) * problem.ut[0] < 0
    if "whittaker" in lawbench.LAWS:
        outcome = lawbench.LAWS.get("whittaker").resolve(problem)
        np.testing.assert_allclose(outcome.v_plus, v_plus, rtol=1e-10)


# 5. Bad input is refused by name


@pytest.mark.parametrize(
    ("case", "params", "field"),
    [
        ("falling_rod", {"mu": -0.1}, "mu"),
        ("rocking_block", {"mu": -1.0}, "mu"),
        ("double_pendulum", {"mu": -0.5}, "mu"),
        ("sphere_wall", {"mu": -0.2}, "mu"),
        ("sphere_wall", {"e_t": 1.5}, "e_t"),
        ("sphere_wall", {"e_t": -1.2}, "e_t"),
        ("falling_rod", {"velocities": [1.0, -1.0]}, "velocities"),
        ("falling_rod", {"velocities": [1.0, -1.0, 0.0, 2.0]}, "velocities"),
        ("sphere_wall", {"spin": [1.0, 2.0]}, "spin"),
        ("double_pendulum", {"omegas": [1.0, 2.0, 3.0]}, "omegas"),
        ("double_pendulum", {"lengths": [1.0]}, "lengths"),
        ("rocking_block", {"width": 0.0}, "width"),
        ("rocking_block", {"omega": -1.0}, "omega"),
        ("falling_rod", {"e": 1.5}, "e"),
        ("sphere_wall", {"angle": 95.0}, "angle"),
    ],
)
def test_bad_input_is_refused_naming_the_field(case, params, field):
    with pytest.raises(InvalidProblem, match=rf"^{field}\b"):
        lawbench.CASES.get(case).build(**params)


@pytest.mark.parametrize("case", CASES)
def test_every_example_builds_and_approaches(case):
    entry = lawbench.CASES.get(case)
    assert next(iter(entry.examples)) == "default"
    for example, params in entry.examples.items():
        problem = entry.build(**params)
        assert problem.un.min() < 0, example
        assert len(entry.coordinates(entry.parameters(**params))) == problem.n
