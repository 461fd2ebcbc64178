"""Brach's bilinear law: equation (11) for a particle, invariants, regimes, cone, limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lawbench
from lawbench import Contact, ImpactProblem, InvalidProblem, NotApplicable
from lawbench.core.outcome import generalized_impulse

BRACH = lawbench.LAWS.get("brach")


def equation_11(m, vn, vt, e, e_t, mu):
    """Brogliato 2010, eq. (11), for a particle; vt a vector of 1 or 2 components."""
    vt = np.atleast_1d(np.asarray(vt, dtype=float))
    pn = -(1 + e) * m * vn
    speed = np.linalg.norm(vt)
    size = min(mu * pn, (1 + e_t) * m * speed)
    return pn, -size * vt / speed if speed > 0 else np.zeros_like(vt)


def particle(m, v, e, e_t, mu):
    """A point mass on a wall of normal y: (x, y) planar or (x, y, z) spatial, tangents x (, z)."""
    n = len(v)
    tangents = [0] if n == 2 else [0, 2]
    return ImpactProblem(
        M=m * np.eye(n),
        Wn=np.eye(n)[:, [1]],
        Wt=np.eye(n)[:, tangents],
        v=np.asarray(v, dtype=float),
        contacts=[Contact(e=e, e_t=e_t, mu=mu)],
    )


PARTICLES = [
    # m, v, e, e_t, mu: sticking, slipping, reversed tangential rebound, 3D, no slip.
    (2.0, [0.3, -1.0], 0.5, 0.0, 0.5),
    (2.0, [3.0, -1.0], 0.5, 0.0, 0.5),
    (0.5, [-0.4, -2.0], 0.9, 0.6, 0.8),
    (1.5, [1.0, -1.0, -2.0], 0.7, 0.3, 0.4),
    (1.5, [0.1, -1.0, 0.05], 0.7, 0.3, 0.4),
    (1.0, [0.0, -1.0], 0.8, 0.5, 0.3),
    (1.0, [0.5, -1.0], 0.8, -0.5, 0.3),
]


@pytest.mark.parametrize(("m", "v", "e", "e_t", "mu"), PARTICLES)
def test_particle_is_equation_11(m, v, e, e_t, mu):
    """Brach's law for a particle is exactly Brogliato 2010, eq. (11) (Brach 1991)."""
    problem = particle(m, v, e, e_t, mu)
    outcome = BRACH.resolve(problem)
    pn, pt = equation_11(m, v[1], np.delete(v, 1), e, e_t, mu)
    assert outcome.Pn[0] == pytest.approx(pn, rel=1e-13)
    np.testing.assert_allclose(outcome.Pt, pt, rtol=1e-13, atol=1e-15)
    expected = np.asarray(v, dtype=float)
    expected[1] += pn / m
    expected[np.delete(np.arange(len(v)), 1)] += pt / m
    np.testing.assert_allclose(outcome.v_plus, expected, rtol=1e-13, atol=1e-15)
    assert outcome.diagnostics["formulation"] == "closed form"


def angular_momentum_about_contact(case, params, v):
    """I w + m radius n x v of the sphere, about its contact point with the wall."""
    radius, m = params["radius"], params["mass"]
    normal = np.array([0.0, 1.0, 0.0])
    return 2 * m * radius**2 / 5 * v[3:] + m * radius * np.cross(normal, v[:3])


def test_any_impulse_at_the_sphere_contact_keeps_angular_momentum_about_it():
    """PHYSICS_NOTES (Jia's examples): an impulse at the contact point keeps L about it."""
    case = lawbench.CASES.get("sphere_wall")
    params = case.parameters()
    problem = case.build(**params)
    before = angular_momentum_about_contact(case, params, problem.v)
    for impulse in np.random.default_rng(3).normal(size=(5, 3)):
        moved = problem.v + problem.solve_mass(
            generalized_impulse(problem, impulse[:1], impulse[1:])
        )
        after = angular_momentum_about_contact(case, params, moved)
        np.testing.assert_allclose(after, before, rtol=0, atol=1e-13)


@pytest.mark.parametrize("example", list(lawbench.CASES.get("sphere_wall").examples))
def test_brach_keeps_the_angular_momentum_about_the_sphere_contact(example):
    """The invariant above, for Brach's outcome on every example of the sphere."""
    case = lawbench.CASES.get("sphere_wall")
    params = case.parameters(**case.examples[example])
    problem = case.build(**params)
    outcome = BRACH.resolve(problem)
    np.testing.assert_allclose(
        angular_momentum_about_contact(case, params, outcome.v_plus),
        angular_momentum_about_contact(case, params, problem.v),
        rtol=0,
        atol=1e-13,
    )


def critical_incidence(e, e_t, mu):
    """Eq. (11) on a spinless sphere (m_t = 2 m / 7): slip beyond tan(a) = 7 mu (1+e) / 2(1+e_t)."""
    return math.degrees(math.atan(3.5 * mu * (1 + e) / (1 + e_t)))


@pytest.mark.parametrize(("e", "e_t", "mu"), [(0.8, 0.2, 0.3), (0.5, 0.0, 0.1), (1.0, 0.9, 0.6)])
def test_stick_and_slip_regimes_of_a_sphere_change_at_the_analytic_incidence(e, e_t, mu):
    """Below the critical incidence ut+ = -e_t ut- (|Pt| < mu Pn); above, |Pt| = mu Pn."""
    critical = critical_incidence(e, e_t, mu)
    for angle, regime in ((0.9 * critical, "stick"), (min(1.1 * critical, 89.0), "slip")):
        params = {"angle": angle, "spin": [0.0, 0.0, 0.0], "e": e, "e_t": e_t, "mu": mu}
        trial = lawbench.evaluate("brach", "sphere_wall", **params)
        problem, outcome = trial.problem, trial.outcome
        assert outcome.diagnostics["regime"] == regime, angle
        ut_plus = problem.Wt.T @ outcome.v_plus
        if regime == "stick":
            np.testing.assert_allclose(ut_plus, -e_t * problem.ut, atol=1e-13)
            assert np.linalg.norm(outcome.Pt) < mu * outcome.Pn[0]
        else:
            assert np.linalg.norm(outcome.Pt) == pytest.approx(mu * outcome.Pn[0], rel=1e-13)
            # Along the slip, less than the tangential rebound: ut+ = ut- - 7 mu Pn / (2 m) s.
            speed = np.linalg.norm(problem.ut)
            expected = (speed - 3.5 * mu * outcome.Pn[0]) * problem.ut / speed
            np.testing.assert_allclose(ut_plus, expected, atol=1e-13)
            assert ut_plus @ problem.ut > -e_t * speed**2


def frictional_trials():
    rng = np.random.default_rng(7)
    for _ in range(30):
        yield (
            "falling_rod",
            {
                "angle": float(rng.uniform(5, 85)),
                "velocities": [
                    float(rng.normal()),
                    -float(rng.uniform(0.1, 2)),
                    float(rng.normal()),
                ],
                "e": float(rng.uniform()),
                "mu": float(rng.uniform(0, 1)),
            },
        )
        yield (
            "sphere_wall",
            {
                "angle": float(rng.uniform(0, 85)),
                "spin": rng.normal(scale=10, size=3).tolist(),
                "e": float(rng.uniform()),
                "e_t": float(rng.uniform(-1, 1)),
                "mu": float(rng.uniform(0, 1)),
            },
        )
        yield (
            "double_pendulum",
            {
                "angles": rng.uniform(-80, 80, size=2).tolist(),
                "omegas": rng.normal(scale=3, size=2).tolist(),
                "e": float(rng.uniform()),
                "mu": float(rng.uniform(0, 0.5)),
            },
        )


def test_impulses_stay_in_the_friction_cone_and_the_normal_law_holds():
    """|Pt| <= mu Pn and un+ = -e un- on random rods, spheres and double pendulums."""
    solved = 0
    for case, params in frictional_trials():
        try:
            trial = lawbench.evaluate("brach", case, **params)
        except NotApplicable as exc:
            assert "strong normal-tangential coupling" in str(exc)
            continue
        problem, outcome = trial.problem, trial.outcome
        if problem.un[0] >= 0:
            assert not outcome.Pn.any() and not outcome.Pt.any()
            continue
        solved += 1
        assert outcome.Pn[0] > 0
        assert np.linalg.norm(outcome.Pt) <= problem.mu[0] * outcome.Pn[0] * (1 + 1e-12)
        un_plus = problem.Wn[:, 0] @ outcome.v_plus
        assert un_plus == pytest.approx(-problem.contacts[0].e * problem.un[0], abs=1e-12)
    assert solved > 40


@pytest.mark.parametrize(
    ("case", "params"),
    [
        ("falling_rod", {"mu": 0.0}),
        ("falling_rod", {"mu": 0.0, "angle": 20.0, "velocities": [2.0, -1.0, -3.0]}),
        ("double_pendulum", {"mu": 0.0}),
        ("sphere_wall", {"mu": 0.0, "e_t": 0.7}),
    ],
)
def test_without_friction_brach_is_newton(case, params):
    """mu = 0: no tangential impulse and Newton's post-impact velocity (one contact)."""
    brach = lawbench.solve("brach", case, **params)
    newton = lawbench.solve("newton", case, **params)
    assert not brach.Pt.any()
    np.testing.assert_allclose(brach.v_plus, newton.v_plus, rtol=1e-13, atol=1e-14)


def test_a_problem_without_tangential_jacobian_gets_newton():
    problem = ImpactProblem(
        M=np.diag([2.0]), Wn=np.ones((1, 1)), v=[-1.0], contacts=[Contact(e=0.5)]
    )
    outcome = BRACH.resolve(problem)
    assert outcome.v_plus[0] == pytest.approx(0.5)
    assert outcome.Pt.size == 0


def test_a_contact_that_does_not_approach_receives_nothing():
    outcome = BRACH.resolve(particle(1.0, [2.0, 0.5], 0.5, 0.0, 0.5))
    assert not outcome.Pn.any() and not outcome.Pt.any()
    np.testing.assert_array_equal(outcome.v_plus, [2.0, 0.5])


def test_strong_coupling_without_a_slip_solution_is_refused():
    """Gnn - mu Gnt.s <= 0 and no stick solution: the law has no answer (found in space)."""
    A = np.array([[-0.8, -0.6, 0.9], [0.0, -1.7, 0.8], [0.4, 0.9, -0.3]])
    local = np.array([-1.0, 0.8, -1.1])  # un-, ut-
    problem = ImpactProblem(
        M=np.eye(3),
        Wn=A.T[:, :1],
        Wt=A.T[:, 1:],
        v=np.linalg.solve(A, local),
        contacts=[Contact(e=0.5, mu=1.0)],
    )
    G = A @ A.T
    slip = local[1:] / np.linalg.norm(local[1:])
    assert G[0, 0] - G[0, 1:] @ slip < 0
    with pytest.raises(NotApplicable, match="strong normal-tangential coupling"):
        BRACH.resolve(problem)


def test_no_pre_impact_slip_on_a_coupled_body_slips_against_the_impact():
    """ut- = 0 on the rod: the friction opposes the slip the normal impulse starts."""
    # Lower end at rest tangentially: vx = -l cos(theta) omega with theta = 45 deg.
    params = {"angle": 45.0, "velocities": [0.0, -1.0, 0.0], "e": 0.5, "mu": 0.1}
    trial = lawbench.evaluate("brach", "falling_rod", **params)
    problem, outcome = trial.problem, trial.outcome
    assert problem.ut[0] == pytest.approx(0.0, abs=1e-15)
    frictionless = lawbench.solve("brach", "falling_rod", **{**params, "mu": 0.0})
    started = problem.Wt[:, 0] @ frictionless.v_plus
    assert outcome.diagnostics["regime"] == "slip"
    assert outcome.Pt[0] * started < 0
    assert abs(outcome.Pt[0]) == pytest.approx(0.1 * outcome.Pn[0], rel=1e-13)


def test_several_contacts_are_refused_by_the_base_class():
    with pytest.raises(NotApplicable, match="2 closed contacts and this law treats one"):
        lawbench.solve("brach", "rocking_block")


def test_tangential_restitution_out_of_range_is_refused():
    with pytest.raises(InvalidProblem, match="e_t"):
        particle(1.0, [1.0, -1.0], 0.5, 1.5, 0.3)


def test_sphere_effective_masses_are_m_and_two_sevenths_m():
    """A solid sphere: 1/m_t = 1/m + radius^2 / I = 7 / (2 m), no coupling (eq. 11 applies)."""
    outcome = lawbench.solve("brach", "sphere_wall", mass=3.0)
    assert outcome.diagnostics["formulation"] == "closed form"
    np.testing.assert_allclose(outcome.diagnostics["effective_masses"], [3.0, 6.0 / 7.0])
