"""Moreau's law with Coulomb friction: second-order cones solved with clarabel.

Sources: Moreau (1988) and De Saxce and Feng (1991) for the law in the modified velocity
``uhat_j = (un+_j + e_j r_j + mu_j |ut+_j|, ut+_j)``, ``K_j ∋ P_j _|_ uhat_j ∈ K*_j``; Acary,
Cadoux, Lemarechal and Malick (ZAMM 91, 2011) for the fixed point over convex cone problems;
Anitescu (Math. Program. 105, 2006) for the relaxation without ``mu_j |ut+_j|``. The cone
problems are checked against the same problems written in cvxpy in the velocities (the dual
of the impulse problem: the projection of ``v-`` in the kinetic metric on
``{w : W.T w + (E r + s, 0) in K*}``, whose multipliers are the impulses), solved with SCS.
"""

import dataclasses
import itertools

import cvxpy as cp
import numpy as np
import pytest

import lawbench
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.numerics import cones
from lawbench.numerics.solvers import solve_lcp

SEEDS = range(12)
MOREAU = lawbench.LAWS.get("moreau")


def random_problem(seed, d, approaching=True):
    """A random problem with 2 to 4 contacts, all approaching unless told otherwise.

    Random SPD mass matrix, Jacobians of full column rank (n >= m (1 + d)), mu in [0.1, 1]
    (contact 0 frictionless for every third seed), e in [0, 1].
    """
    rng = np.random.default_rng(seed)
    m = int(rng.integers(2, 5))
    n = m * (1 + d) + int(rng.integers(0, 3))
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    Wn, Wt = rng.normal(size=(n, m)), rng.normal(size=(n, m * d))
    v = rng.normal(size=n)
    if approaching:
        # Shift v along M^-1 Wn so that every normal rate is a chosen negative number.
        G = Wn.T @ np.linalg.solve(M, Wn)
        target = -rng.uniform(0.2, 1.5, m)
        v = v + np.linalg.solve(M, Wn @ np.linalg.solve(G, target - Wn.T @ v))
    mu = rng.uniform(0.1, 1.0, m)
    if seed % 3 == 0:
        mu[0] = 0.0
    contacts = [Contact(e=float(rng.uniform()), mu=float(x)) for x in mu]
    return ImpactProblem(M=M, Wn=Wn, Wt=Wt, v=v, contacts=contacts)


def restituted(problem, separating="unilateral"):
    """``E r``: the restitution term of the normal law."""
    un = problem.un
    r = np.minimum(un, 0.0) if separating == "unilateral" else un
    return problem.restitution("kinematic") * r


def cone_qp_cvxpy(problem, shift):
    """Post-impact velocity of the cone QP, in velocities: ``min |w - v|_M^2 / 2`` subject to
    ``mu_j |Wt_j.T w| <= Wn_j.T w + shift_j`` (``Wn_j.T w + shift_j >= 0`` for ``mu_j = 0``).
    """
    d, w = problem.d, cp.Variable(problem.n)
    constraints = []
    for j, mu in enumerate(problem.mu):
        normal = problem.Wn[:, j] @ w + shift[j]
        if mu > 0:
            tangential = problem.Wt[:, j * d : (j + 1) * d].T @ w
            constraints.append(cp.SOC(normal, mu * tangential))
        else:
            constraints.append(normal >= 0)
    objective = cp.Minimize(0.5 * cp.quad_form(w - problem.v, cp.psd_wrap(problem.M)))
    cp.Problem(objective, constraints).solve(
        solver=cp.SCS, eps_abs=1e-8, eps_rel=1e-8, max_iters=100_000
    )
    return w.value


def local_data(problem):
    """Contact Delassus matrix, ``q = u- + (E r, 0)``, mu and d of a frictional problem."""
    q = problem.W.T @ problem.v
    q[: problem.m] += restituted(problem)
    return problem.contact_delassus, q, problem.mu, problem.d


def coulomb_states(problem, outcome, separating="unilateral"):
    """Check Coulomb's law with the normal law on every contact and return the states.

    free: ``P = 0`` and ``un+ + e r >= 0``; stick: ``un+ + e r = 0``, ``ut+ = 0``,
    ``|Pt| <= mu Pn``; slip: ``un+ + e r = 0``, ``Pt = -mu Pn ut+ / |ut+|``.
    """
    m, d = problem.m, problem.d
    u_plus = problem.W.T @ outcome.v_plus
    gap = u_plus[:m] + restituted(problem, separating)
    slip = u_plus[m:].reshape(m, d)
    Pt = outcome.Pt.reshape(m, d)
    v_scale = np.abs(problem.W.T @ problem.v).max()
    p_scale = np.abs(np.concatenate([outcome.Pn, outcome.Pt])).max()
    states = []
    for j in range(m):
        Pn, mu = outcome.Pn[j], problem.mu[j]
        assert Pn >= -1e-12 * p_scale, j
        assert np.linalg.norm(Pt[j]) <= mu * Pn + 1e-10 * p_scale, j
        assert gap[j] >= -1e-10 * v_scale, j
        if Pn <= 1e-9 * p_scale:
            states.append("free")
            continue
        assert abs(gap[j]) <= 1e-9 * v_scale, j
        speed = np.linalg.norm(slip[j])
        if speed <= 1e-9 * v_scale:
            states.append("stick")
            continue
        np.testing.assert_allclose(Pt[j], -mu * Pn * slip[j] / speed, atol=1e-9 * p_scale)
        states.append("slip")
    return states


@pytest.mark.parametrize("d", [1, 2])
def test_relaxed_problem_agrees_with_cvxpy(d):
    """Anitescu's relaxed cone QP (s = 0): clarabel and cvxpy agree to 1e-6 on v+."""
    for seed in SEEDS:
        problem = random_problem(seed, d)
        outcome = MOREAU.resolve(problem, friction="relaxed")
        expected = cone_qp_cvxpy(problem, restituted(problem))
        scale = np.abs(problem.v).max()
        np.testing.assert_allclose(outcome.v_plus, expected, atol=1e-6 * scale, err_msg=seed)
        assert outcome.diagnostics["formulation"] == "SOCP relaxed (clarabel)"
        assert outcome.diagnostics["fixed_point_steps"] == 1


@pytest.mark.parametrize("d", [1, 2])
def test_one_fixed_point_step_agrees_with_cvxpy(d):
    """The cone QP with a given shift s >= 0 on the normal rows: clarabel and cvxpy agree."""
    for seed in SEEDS:
        problem = random_problem(seed, d)
        G, q, mu, _ = local_data(problem)
        s = mu * np.random.default_rng(seed).uniform(0, 2, problem.m)
        P = cones.solve_cone_qp(G, q + np.pad(s, (0, problem.m * d)), mu, d, 1e-10).P
        v_plus = problem.v + problem.solve_mass(problem.W @ P)
        expected = cone_qp_cvxpy(problem, restituted(problem) + s)
        scale = np.abs(problem.v).max()
        np.testing.assert_allclose(v_plus, expected, atol=1e-6 * scale, err_msg=seed)


@pytest.mark.parametrize("d", [1, 2])
def test_exact_mode_satisfies_coulombs_law(d):
    """Every contact of every result is free, sticking or slipping as Coulomb's law says;
    the three states all occur, and the friction_cone and admissible checks hold.
    """
    seen = set()
    for seed in SEEDS:
        problem = random_problem(seed, d)
        outcome = MOREAU.resolve(problem)
        assert outcome.diagnostics["formulation"] == "SOCP fixed point (clarabel)"
        seen.update(coulomb_states(problem, outcome))
        un_plus = problem.Wn.T @ outcome.v_plus
        assert (un_plus >= -1e-10 * np.abs(problem.un).max()).all(), seed
    assert seen == {"free", "stick", "slip"}


@pytest.mark.parametrize("separating", ["unilateral", "restitution"])
@pytest.mark.parametrize("d", [1, 2])
def test_coulombs_law_with_separating_contacts(d, separating):
    """Arbitrary velocities (some contacts separate before the impact): the law with the
    restitution term of the option ``separating`` holds on every contact.
    """
    for seed in range(6):
        problem = random_problem(seed, d, approaching=False)
        outcome = MOREAU.resolve(problem, separating=separating)
        coulomb_states(problem, outcome, separating)


def test_polished_answers_satisfy_the_cone_conditions_to_rounding():
    """The refined answers satisfy De Saxce's cone complementarity to rounding, and lie within
    clarabel's accuracy of the raw interior-point answers (or the raw path fails and says how).
    """
    for d in (1, 2):
        for seed in range(4):
            problem = random_problem(seed, d)
            G, q, mu, _ = local_data(problem)
            outcome = MOREAU.resolve(problem)
            assert outcome.diagnostics["polished"]
            P = np.concatenate([outcome.Pn, outcome.Pt])
            scale = np.abs(P).max()
            assert cones.residual(G, q, mu, d, P, True) <= 1e-13 * scale
            try:
                raw = MOREAU.resolve(problem, polish=False)
            except lawbench.BudgetExceeded as failure:
                # Unpolished answers carry clarabel's accuracy (~1e-8): the fixed point on mu
                # |ut+| can stall above its 1e-10 tolerance, and says so.
                assert failure.budget == "max_steps"
                continue
            except lawbench.SolverFailure as failure:
                assert "AlmostSolved" in str(failure)
                continue
            np.testing.assert_allclose(raw.v_plus, outcome.v_plus, atol=1e-4 * scale)


@pytest.mark.parametrize("friction", ["coulomb", "relaxed"])
def test_plastic_impacts_never_gain_energy(friction):
    """e = 0: dT = -sum mu Pn |ut+| - P.G P / 2 <= 0 for the exact law (De Saxce's
    orthogonality), dT = -P.G P / 2 for the relaxed one.
    """
    for d in (1, 2):
        for seed in range(6):
            problem = random_problem(seed, d)
            contacts = [Contact(e=0.0, mu=c.mu) for c in problem.contacts]
            problem = ImpactProblem(
                M=problem.M, Wn=problem.Wn, Wt=problem.Wt, v=problem.v, contacts=contacts
            )
            outcome = MOREAU.resolve(problem, friction=friction)
            assert outcome.dT <= 1e-12 * outcome.T_minus, (d, seed)


def test_zero_friction_is_the_frictionless_law():
    """mu = 0 everywhere: the frictionless QP/LCP path, bit for bit, and Pt = 0; the cone QP
    itself with mu = 0 is the LCP of the normal Delassus matrix.
    """
    for d in (1, 2):
        for seed in range(6):
            rough = random_problem(seed, d)
            contacts = [Contact(e=c.e) for c in rough.contacts]
            smooth = ImpactProblem(M=rough.M, Wn=rough.Wn, v=rough.v, contacts=contacts)
            tangential = ImpactProblem(
                M=rough.M, Wn=rough.Wn, Wt=rough.Wt, v=rough.v, contacts=contacts
            )
            expected, outcome = MOREAU.resolve(smooth), MOREAU.resolve(tangential)
            assert np.array_equal(outcome.v_plus, expected.v_plus)
            assert np.array_equal(outcome.Pn, expected.Pn)
            assert np.array_equal(outcome.Pt, np.zeros(rough.m * d))
            assert outcome.diagnostics["formulation"] == expected.diagnostics["formulation"]

            G, q, _, _ = local_data(rough)
            m = rough.m
            P = cones.solve_cone_qp(G, q, np.zeros(m), d, 1e-10).P
            lcp = solve_lcp(rough.delassus, q[:m])
            np.testing.assert_allclose(P[:m], lcp.z, atol=1e-12 * np.abs(lcp.z).max())
            assert np.array_equal(P[m:], np.zeros(m * d))


def particle(d, mass, normal_rate, slip, e, mu):
    """A particle of ``mass`` on a rough fixed plane: coordinates (tangential..., normal)."""
    n = d + 1
    Wn, Wt = np.eye(n)[:, [d]], np.eye(n)[:, :d]
    v = np.append(slip, normal_rate)
    contact = Contact(e=e, mu=mu)
    return ImpactProblem(M=mass * np.eye(n), Wn=Wn, Wt=Wt, v=v, contacts=[contact])


PARTICLES = [
    # d, tangential velocity, mu: stick when |vt| <= mu (1 + e) |vn|.
    (1, [0.3], 0.5),
    (1, [-2.0], 0.4),
    (2, [0.2, -0.1], 0.6),
    (2, [1.5, 2.0], 0.3),
]


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
@pytest.mark.parametrize(("d", "slip", "mu"), PARTICLES)
def test_particle_on_a_rough_plane(d, slip, mu, e):
    """Closed form: Pn = m (1 + e) |vn|, un+ = e |vn|; stick (vt+ = 0, Pt = -m vt) when
    |vt| <= mu Pn / m, else slip with Pt = -mu Pn vt / |vt| and vt+ = vt + Pt / m.
    """
    mass, vn = 2.0, -1.2
    slip = np.array(slip)
    outcome = MOREAU.resolve(particle(d, mass, vn, slip, e, mu))
    Pn = mass * (1 + e) * abs(vn)
    speed = np.linalg.norm(slip)
    if speed <= mu * Pn / mass:
        Pt = -mass * slip
    else:
        Pt = -mu * Pn * slip / speed
    expected = np.append(slip + Pt / mass, -e * vn)
    np.testing.assert_allclose(outcome.v_plus, expected, rtol=0, atol=1e-13)
    np.testing.assert_allclose(outcome.Pn, [Pn], rtol=1e-13)
    np.testing.assert_allclose(outcome.Pt, Pt, rtol=0, atol=1e-13)


@pytest.mark.parametrize("e", [0.0, 0.5])
@pytest.mark.parametrize(("d", "slip", "mu"), [p for p in PARTICLES if p[1][0] > 1])
def test_relaxation_lets_a_slipping_particle_leave(d, slip, mu, e):
    """Anitescu's relaxation, slipping particle, by hand: un+ + e r = mu |ut+| gives
    Pn = m (mu |vt| + (1 + e) |vn|) / (1 + mu^2): it leaves at e |vn| + mu |ut+| > e |vn|.
    """
    mass, vn = 2.0, -1.2
    slip = np.array(slip)
    outcome = MOREAU.resolve(particle(d, mass, vn, slip, e, mu), friction="relaxed")
    speed = np.linalg.norm(slip)
    Pn = mass * (mu * speed + (1 + e) * abs(vn)) / (1 + mu**2)
    vt_plus = slip - mu * Pn / mass * slip / speed
    expected = np.append(vt_plus, vn + Pn / mass)
    np.testing.assert_allclose(outcome.v_plus, expected, rtol=0, atol=1e-13)
    assert outcome.v_plus[-1] > -e * vn + 0.1


def _consistent(state, Pn, Pt, gap, slip, mu, slack):
    """The inequalities of a planar contact state (``gap`` is ``un+ + e r``)."""
    if state == "free":
        return gap >= -slack
    if state == "stick":
        return Pn >= -slack and abs(Pt) <= mu * Pn + slack
    return Pn >= -slack and state * slip > 0


def planar_solutions(problem):
    """Every solution of the planar Coulomb law, by enumeration of the contact states.

    Each contact is free (``P = 0``), sticking (``un+ + e r = 0``, ``ut+ = 0``) or slipping
    either way (``un+ + e r = 0``, ``Pt = -/+ mu Pn``); each choice is a linear system, kept
    when its solution has the inequalities of its states.
    """
    G, q, mu, _ = local_data(problem)
    m, solutions = problem.m, []
    for states in itertools.product(("free", "stick", 1.0, -1.0), repeat=m):
        A, b = np.zeros((2 * m, 2 * m)), np.zeros(2 * m)
        for j, state in enumerate(states):
            rows = [j, m + j]
            if state == "free":
                A[rows, rows] = 1.0
                continue
            A[j], b[j] = G[j], -q[j]
            if state == "stick":
                A[m + j], b[m + j] = G[m + j], -q[m + j]
            else:  # slip with sign(ut+) = state
                A[m + j, m + j], A[m + j, j] = 1.0, mu[j] * state
        P = np.linalg.solve(A, b)
        u, slack = G @ P + q, 1e-12 * np.abs(P).max()
        if all(
            _consistent(state, P[j], P[m + j], u[j], u[m + j], mu[j], slack)
            for j, state in enumerate(states)
        ):
            solutions.append(P)
    return solutions


def test_planar_law_matches_the_enumerated_solution():
    """Planar problems with one Coulomb solution: the fixed point finds it, to 1e-9."""
    compared = 0
    for seed in SEEDS:
        problem = random_problem(seed, 1)
        solutions = planar_solutions(problem)
        if len(solutions) != 1:
            continue
        outcome = MOREAU.resolve(problem)
        P = np.concatenate([outcome.Pn, outcome.Pt])
        np.testing.assert_allclose(P, solutions[0], atol=1e-9 * np.abs(P).max(), err_msg=seed)
        compared += 1
    assert compared >= len(SEEDS) // 2


def test_averaged_fixed_point_breaks_a_cycle():
    """Random planar problem, two contacts: one Coulomb solution (stick, slip) exists, but the
    plain substitution over s alternates between two iterates forever (20 steps are not
    enough); past its 20 plain steps the law averages the update and reaches the solution.
    """
    problem = random_problem(1183, 1)
    solutions = planar_solutions(problem)
    assert len(solutions) == 1
    ran_out = r"step budget ran out \(20 Coulomb fixed-point steps; last change"
    with pytest.raises(lawbench.SolverFailure, match=ran_out):
        MOREAU.resolve(problem, max_steps=20)
    outcome = MOREAU.resolve(problem)
    assert outcome.diagnostics["fixed_point_steps"] > 20
    np.testing.assert_allclose(
        np.concatenate([outcome.Pn, outcome.Pt]), solutions[0], rtol=1e-8, atol=1e-10
    )


def test_fixed_point_steps_are_bounded_and_reported():
    """The count of cone QPs is reported; one step fewer raises SolverFailure naming it."""
    problem = random_problem(1, 2)
    steps = MOREAU.resolve(problem).diagnostics["fixed_point_steps"]
    assert 2 < steps <= 1000
    assert MOREAU.resolve(problem, max_steps=steps).diagnostics["iterations"] > steps
    ran_out = rf"step budget ran out \({steps - 1} Coulomb fixed-point steps"
    with pytest.raises(lawbench.SolverFailure, match=ran_out):
        MOREAU.resolve(problem, max_steps=steps - 1)


def test_options_and_tags():
    """Friction, several contacts and spatial problems; friction mode checked on input."""
    tags = MOREAU.tags
    assert tags.friction and tags.several_contacts and tags.spatial
    assert tags.accuracy_knob == "tol"
    with pytest.raises(lawbench.InvalidProblem, match="friction"):
        MOREAU.resolve(random_problem(0, 1), friction="exact")


@pytest.mark.parametrize("friction", ["coulomb", "relaxed"])
def test_deterministic(friction):
    """The same spatial problem twice gives bit-identical outcomes."""
    problem = random_problem(4, 2)
    first = MOREAU.resolve(problem, friction=friction)
    second = MOREAU.resolve(problem, friction=friction)
    for field in ("v_plus", "Pn", "Pt"):
        assert np.array_equal(getattr(first, field), getattr(second, field)), field


@pytest.mark.parametrize("scale", [1e-12, 1e-6, 1e6])
def test_a_cone_program_answers_alike_at_every_scale_of_its_velocities(scale):
    """Moreau's law is homogeneous: velocities times s give impulses times s (Moreau 1988).
    clarabel's tolerances are partly absolute, so the program is solved at unit magnitudes;
    at 1e-7 m/s it had ended 'Solved' with an active contact still separating at half its
    approach speed (an LMGC90 problem, tests/data/fclib)."""
    problem = lawbench.CASES["bouncing_ball"].build()
    scaled = dataclasses.replace(problem, v=problem.v * scale)
    law = lawbench.LAWS["moreau"]
    unit, small = law.resolve(problem), law.resolve(scaled)
    np.testing.assert_allclose(small.v_plus / scale, unit.v_plus, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(small.Pn / scale, unit.Pn, rtol=1e-9)


@pytest.mark.parametrize("method", ["fixed_point", "nsgs"])
def test_a_lamina_without_a_coulomb_solution_is_refused_with_the_reason(method):
    """Lamina on an anvil with h0 mu = 1.5 > f0 = 1 (Lubarda 2010; Brogliato 2010, lamina).

    One coordinate omega: un+ = f0 omega+, ut+ = h0 omega+, omega+ = -1 + Pn + 1.5 Pt (I = 1).
    Moreau's law at e = 0.5 needs un+ >= 0.5 with Pn > 0: free fails (omega+ = -1), stick needs
    un+ = 0 < 0.5, and slip (un+ = 0.5, Pt = -Pn) gives Pn = -3 < 0. No impulse satisfies the
    law, so the law says so instead of returning where its iteration stopped.
    """
    with pytest.raises(lawbench.NotApplicable, match="no solution"):
        lawbench.solve("moreau", "lamina", h0=1.5, mu=1.0, options={"method": method})


def test_a_huge_friction_coefficient_gives_the_sticking_answer():
    """mu = 1e300 on the falling rod: the modified velocity un + mu |ut| loses un to rounding.

    The cone iteration then stops at a zero impulse that leaves the end approaching the floor;
    the contact's exact state is the stick of any mu above the sticking ratio (Brogliato 2010,
    eq. 8, sticking mode), the answer at mu = 1e3.
    """
    sticking = lawbench.solve("moreau", "falling_rod", mu=1e3)
    for method in ("auto", "fixed_point"):
        huge = lawbench.solve("moreau", "falling_rod", {"method": method}, mu=1e300)
        np.testing.assert_allclose(huge.v_plus, sticking.v_plus, rtol=1e-12)
    assert huge.diagnostics["formulation"].endswith("then the contact's exact state")


def test_impulses_that_change_the_velocities_only_through_their_rounding_are_refused():
    """One coordinate and a spatial contact: both tangential directions are the normal's, so
    Coulomb's states hold impulses of any size along the dependence. The contact's exact
    state was impulses of 3e16 whose velocity, their rounding, left the contact at
    un+ = 1 = -un- with e = 0.5, FC3D error zero, status ok."""
    problem = lawbench.ImpactProblem.from_arrays(
        [[1.0]], [[1.0]], [-1.0], [[0.5, 1.0]], e=0.5, mu=1000.0
    )
    with pytest.raises(lawbench.SolverFailure, match="only through their cancellation"):
        lawbench.solve("moreau", problem)


def test_a_cone_narrower_than_the_solvers_tolerances_is_never_left_ok():
    """At mu = 1e-9 (not yet negligible) the cone QP's cone (mu Pn, Pt) lies below clarabel's
    tolerances, and the polish, kept for lowering the natural residual, made contact 0 stick
    with |Pt| = 0.5 where mu Pn is 5e-10: status ok. The answer keeps its cones or fails."""
    problem = lawbench.ImpactProblem.from_arrays(
        np.diag([1.33, 1.95, 1.72]),
        [[0.68, -0.38, 0.23], [1.14, -0.06, -2.54], [0.68, 1.08, -0.95]],
        [-0.34, -1.06, 1.45],
        [[-0.35, -0.02, 0.29], [0.14, -1.38, -1.75], [0.08, 1.28, 2.51]],
        e=0.5,
        mu=1e-9,
    )
    try:
        outcome = lawbench.solve("moreau", problem)
    except lawbench.SolverFailure as failure:
        assert "leaves its Coulomb cone" in str(failure)
        return
    assert (np.abs(outcome.Pt) <= 1e-9 * outcome.Pn + 1e-12).all(), (outcome.Pn, outcome.Pt)
