"""Whittaker's law: Newton's restitution with Coulomb friction at the impulse level.

Source of the analytic results: Brogliato, *An introduction to impact dynamics* (lectures,
2010), "Single impact with Coulomb's friction, friction at the impulse level": the particle
striking a wall (eq. 6 and its three cases), the rod striking the ground (eqs. 7-8), the
energy gain when the slip reverses (remark after eq. 9, Kane and Levinson 1985). The
multi-contact and spatial results are checked against independent enumerations written here:
every planar mode combination as a full square linear system, and a dense scan of the slip
angle of one spatial contact.
"""

import itertools
import math

import numpy as np
import pytest
import scipy.optimize

import lawbench
from lawbench.core.errors import NotApplicable, SolverFailure
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.laws.whittaker import MAX_ENUMERATED
from lawbench.numerics.rigid import spatial_column

LAW = lawbench.LAWS.get("whittaker")


def particle(vt, vn, mu=0.5, e=0.5, mass=2.0):
    """A particle of mass ``mass`` striking the wall y = 0: q = (x, y), tangent x, normal y."""
    return ImpactProblem(
        M=mass * np.eye(2),
        Wn=[[0.0], [1.0]],
        Wt=[[1.0], [0.0]],
        v=[vt, vn],
        contacts=[Contact(e=e, mu=mu)],
    )


def rod(theta, v, mu, e, mass=1.0, half=0.5):
    """The rod of eq. (7): q = (x, y, theta), contact end at ``half`` from the centre of mass
    (the lectures' l), I = m l^2 / 3."""
    s, c = math.sin(theta), math.cos(theta)
    return ImpactProblem(
        M=np.diag([mass, mass, mass * half * half / 3]),
        Wn=[[0.0], [1.0], [half * s]],
        Wt=[[1.0], [0.0], [half * c]],
        v=v,
        contacts=[Contact(e=e, mu=mu)],
    )


def from_delassus(G, un, ut, mu, e):
    """A problem whose contact Delassus matrix is G: M = G^-1 and W the identity."""
    eye, m = np.eye(len(G)), len(un)
    return ImpactProblem(
        M=np.linalg.inv(G),
        Wn=eye[:, :m],
        Wt=eye[:, m:],
        v=np.concatenate([un, ut]),
        contacts=[Contact(e=a, mu=b) for a, b in zip(e, mu, strict=True)],
    )


def random_planar(seed, m, mu_high=1.0, dependent=True):
    """Random SPD M, Wn, Wt, v; ``dependent`` allows n = 2m - 1 (dependent contact directions)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2 * m - 1 if dependent else 2 * m, 2 * m + 3))
    A = rng.normal(size=(n, n))
    return ImpactProblem(
        M=A @ A.T + 0.1 * np.eye(n),
        Wn=rng.normal(size=(n, m)),
        Wt=rng.normal(size=(n, m)),
        v=rng.normal(size=n),
        contacts=[Contact(e=rng.uniform(), mu=rng.uniform(0, mu_high)) for _ in range(m)],
    )


def post_rates(problem, Pn, Pt):
    v_plus = problem.v + problem.solve_mass(problem.Wn @ Pn + problem.Wt @ Pt)
    return v_plus, problem.Wn.T @ v_plus, (problem.Wt.T @ v_plus).reshape(problem.m, -1)


def law_violation(problem, Pn, Pt):
    """Largest relative violation of the law's conditions by the impulses (Pn, Pt)."""
    Pt = np.reshape(Pt, (problem.m, -1))
    _, un_plus, ut_plus = post_rates(problem, Pn, Pt.ravel())
    e, mu = problem.restitution("kinematic"), problem.mu
    V = max(np.abs(problem.un).max(), np.abs(problem.ut).max())
    P = max(np.abs(Pn).max(), np.abs(Pt).max(), V / problem.contact_delassus.diagonal().max())
    gap = un_plus + e * np.minimum(problem.un, 0.0)
    slip = np.linalg.norm(ut_plus, axis=1)
    sliding = slip > 1e-9 * V
    coulomb = np.where(
        sliding[:, None], Pt + (mu * Pn)[:, None] * ut_plus / np.maximum(slip, 1e-300)[:, None], 0
    )
    return max(
        -Pn.min() / P,
        -gap.min() / V,
        np.abs(gap * Pn).max() / (V * P),
        (np.linalg.norm(Pt, axis=1) - mu * Pn).max() / P,
        np.abs(coulomb).max() / P,
    )


def distinct(velocities, M, tol=1e-7):
    kept = []
    for v in velocities:
        if all(np.sqrt((v - w) @ M @ (v - w)) > tol * max(1.0, np.sqrt(v @ M @ v)) for w in kept):
            kept.append(v)
    return kept


def mode_system(problem, modes):
    """Equalities ``A P = b`` and inequalities ``C P <= d`` of one planar mode combination.

    Per contact: 0 no impulse (Pn = Pt = 0, gap >= 0), 1 stick (gap = 0, ut+ = 0,
    |Pt| <= mu Pn), 2 slip with ut+ >= 0 (gap = 0, Pt = -mu Pn), 3 slip with ut+ <= 0
    (gap = 0, Pt = mu Pn); the gap is ``un+ + e min(un-, 0)``.
    """
    m, G = problem.m, problem.contact_delassus
    e, mu, un, ut = problem.restitution("kinematic"), problem.mu, problem.un, problem.ut
    bias = np.concatenate([un + e * np.minimum(un, 0.0), ut])
    eye = np.eye(2 * m)
    A, b, C, d = [], [], [], []
    for j, mode in enumerate(modes):
        normal, tangent = eye[j], eye[m + j]
        if mode == 0:
            A += [normal, tangent]
            b += [0.0, 0.0]
            C.append(-G[j])
            d.append(bias[j])
            continue
        A.append(G[j])
        b.append(-bias[j])
        C.append(-normal)
        d.append(0.0)
        if mode == 1:
            A.append(G[m + j])
            b.append(-bias[m + j])
            C += [tangent - mu[j] * normal, -tangent - mu[j] * normal]
            d += [0.0, 0.0]
        else:
            sign = 1.0 if mode == 2 else -1.0
            A.append(tangent + sign * mu[j] * normal)
            b.append(0.0)
            C.append(-sign * G[m + j])
            d.append(sign * bias[m + j])
    return np.array(A), np.array(b), np.array(C), np.array(d)


def deepest_point(A, b, C, d):
    """The solution of ``A P = b`` deepest inside ``C P <= d`` (linear programming), or None."""
    size = A.shape[1]
    result = scipy.optimize.linprog(
        np.append(np.zeros(size), -1.0),
        A_ub=np.column_stack([C, np.linalg.norm(C, axis=1)]),
        b_ub=d,
        A_eq=np.column_stack([A, np.zeros(len(b))]),
        b_eq=b,
        bounds=[(None, None)] * size + [(None, 1.0)],
        method="highs",
    )
    return result.x[:-1] if result.status == 0 and result.x[-1] >= -1e-9 else None


def enumerate_planar(problem):
    """Post-impact velocities of every admissible planar mode combination (full 2m systems).

    A singular system (dependent contacts) is searched by linear programming for the point
    deepest inside its inequalities.
    """
    m, found = problem.m, []
    systems = [mode_system(problem, modes) for modes in itertools.product(range(4), repeat=m)]
    A, b = np.array([s[0] for s in systems]), np.array([s[1] for s in systems])
    singular = np.linalg.svd(A, compute_uv=False)[:, -1] <= 1e-12 * np.abs(A).max()
    solved = np.zeros_like(b)
    solved[~singular] = np.linalg.solve(A[~singular], b[~singular][..., None])[..., 0]
    for system, P, dependent in zip(systems, solved, singular, strict=True):
        tol = 1e-6 if dependent else 1e-8
        if dependent and (P := deepest_point(*system)) is None:
            continue
        if P[:m].min() < -tol * np.abs(P).max():
            continue  # a tensile impulse: rejected before the full check, for speed
        if law_violation(problem, P[:m], P[m:]) <= tol:
            found.append(post_rates(problem, P[:m], P[m:])[0])
    return distinct(found, problem.M)


def scan_spatial(problem, samples=20_000):
    """Post-impact velocities of one spatial contact: no impulse, stick, slip by angle scan.

    The slip direction s (of ut+) gives Pn = c / D(s), Pt = -mu Pn s; ut+ must be parallel to
    s. Sign changes of the cross product between grid angles (poles of Pn excluded) are
    refined with brentq.
    """
    G, mu = problem.contact_delassus, problem.mu[0]
    e, un, ut = problem.restitution("kinematic")[0], problem.un[0], problem.ut
    c = -(un + e * min(un, 0.0))

    def state(theta):
        s = np.array([np.cos(theta), np.sin(theta)])
        D = G[0, 0] - mu * G[0, 1:] @ s
        Pn = c / D
        slip = ut[:, None] * np.ones_like(D) + Pn * (G[1:, :1] - mu * G[1:, 1:] @ s)
        return s, D, Pn, slip, s[0] * slip[1] - s[1] * slip[0]

    candidates = [np.zeros(3), np.linalg.solve(G, np.array([c, -ut[0], -ut[1]]))]
    grid = np.linspace(0, 2 * math.pi, samples + 1)
    _, D, _, _, cross = state(grid)
    brackets = np.flatnonzero((cross[:-1] * cross[1:] <= 0) & (D[:-1] * D[1:] > 0))
    for k in brackets:
        theta = scipy.optimize.brentq(
            lambda t: state(np.array([t]))[4][0], grid[k], grid[k + 1], xtol=1e-15
        )
        s, _, Pn, slip, _ = state(np.array([theta]))
        if Pn[0] > 0 and slip[:, 0] @ s[:, 0] > 0:
            candidates.append(np.concatenate([Pn, -mu * Pn[0] * s[:, 0]]))
    velocities = [
        post_rates(problem, P[:1], P[1:])[0]
        for P in candidates
        if law_violation(problem, P[:1], P[1:]) <= 1e-8
    ]
    return distinct(velocities, problem.M)


def listed_velocities(problem, outcome):
    return [
        post_rates(problem, np.array(s["Pn"]), np.array(s["Pt"]))[0]
        for s in outcome.diagnostics["solutions"]
    ]


def assert_same_set(found, expected, M):
    assert len(found) == len(expected)
    for v in expected:
        assert any(
            np.sqrt((v - w) @ M @ (v - w)) <= 1e-7 * max(1, np.sqrt(v @ M @ v)) for w in found
        )


@pytest.mark.parametrize(
    ("vt", "case"), [(-3.0, "slip -"), (-1.0, "stick"), (0.4, "stick"), (2.5, "slip +")]
)
def test_particle_three_cases(vt, case):
    """The three cases after eq. (6) (Brogliato 2010), particle of mass 2, f = 0.5, e = 0.5.

    pn = -m (1 + e) vn-; vt- < f (1 + e) vn-: vt+ = vt- - f (1 + e) vn-, pt = f pn;
    vt- > -f (1 + e) vn-: vt+ = vt- + f (1 + e) vn-, pt = -f pn; otherwise vt+ = 0.
    """
    m, f, e, vn = 2.0, 0.5, 0.5, -2.0
    outcome = LAW.resolve(particle(vt, vn, f, e, m))
    pn, bound = -m * (1 + e) * vn, f * (1 + e) * vn
    if vt < bound:
        vt_plus, pt = vt - bound, f * pn
    elif vt > -bound:
        vt_plus, pt = vt + bound, -f * pn
    else:
        vt_plus, pt = 0.0, m * (0.0 - vt)
        assert abs(pt) <= f * pn
    np.testing.assert_allclose(outcome.v_plus, [vt_plus, -e * vn], atol=1e-12)
    np.testing.assert_allclose([outcome.Pn[0], outcome.Pt[0]], [pn, pt], atol=1e-12)
    assert outcome.diagnostics["solutions"][0]["modes"] == [case]
    assert outcome.diagnostics["formulation"] == f"closed form, {case.rstrip(' +-')}"
    assert outcome.status == "ok"


def test_particle_dissipates_and_never_speeds_up_the_slip():
    """Lecture: without inertial coupling T_L <= 0 for e in [0, 1], and |vt+| <= |vt-|."""
    for vt, vn, mu, e in itertools.product(
        np.linspace(-3, 3, 13), [-2.0, -0.3], [0.1, 0.5, 2.0], [0.0, 0.5, 1.0]
    ):
        outcome = LAW.resolve(particle(vt, vn, mu, e))
        assert outcome.dT <= 1e-12 * outcome.T_minus
        assert abs(outcome.v_plus[0]) <= abs(vt) + 1e-12


def rod_equation_8(theta, v, mu, e, mode, mass=1.0, half=0.5):
    """Eq. (8) as a linear system in (x+, y+, theta+, pn, pt) for one mode of the end."""
    s, c, inertia = math.sin(theta), math.cos(theta), mass * half * half / 3
    xd, yd, td = v
    A = np.zeros((5, 5))
    A[0, [0, 4]] = mass, -1.0
    A[1, [1, 3]] = mass, -1.0
    A[2, [2, 3, 4]] = inertia, -half * s, -half * c
    A[3, [1, 2]] = 1.0, half * s
    if mode == "stick":  # x+ + l cos(theta) theta+ = 0
        A[4, [0, 2]] = 1.0, half * c
    else:  # pt = -f pn sgn(ut+)
        A[4, [3, 4]] = (1.0 if mode == "slip +" else -1.0) * mu, 1.0
    b = [mass * xd, mass * yd, inertia * td, -e * (yd + half * td * s), 0.0]
    x = np.linalg.solve(A, b)
    return x[:3], x[3], x[4], x[0] + half * c * x[2]


@pytest.mark.parametrize(
    ("v", "mode"),
    [([2.0, -1.0, 0.0], "slip +"), ([-2.0, -1.0, 0.0], "slip -"), ([-0.6, -1.0, 0.0], "stick")],
)
def test_rod_stick_and_slip(v, mode):
    """The rod of eqs. (7)-(8) at theta = 30 deg, f = 0.3, e = 0.5: each mode by hand.

    The mode is checked to be consistent (pn > 0, pt opposing the slip, or |pt| <= f pn when
    sticking) before the law's answer is compared with it.
    """
    theta, mu, e = math.radians(30), 0.3, 0.5
    v_plus, pn, pt, slip = rod_equation_8(theta, v, mu, e, mode)
    assert pn > 0
    if mode == "stick":
        assert abs(pt) <= mu * pn
    else:
        assert slip * (1 if mode == "slip +" else -1) > 0
    outcome = LAW.resolve(rod(theta, v, mu, e))
    np.testing.assert_allclose(outcome.v_plus, v_plus, atol=1e-12)
    np.testing.assert_allclose([outcome.Pn[0], outcome.Pt[0]], [pn, pt], atol=1e-12)
    assert outcome.diagnostics["solutions"][0]["modes"] == [mode]
    assert outcome.diagnostics["uniqueness"] == "unique"


def test_rod_gains_energy_when_the_slip_reverses():
    """Remark after eq. (9): with coupling and sgn(vt+) = -sgn(vt-), T_L > 0 for e in [0, 1].

    Rod at 45 deg, f = 0.3, e = 0.9, spinning into the floor: the end slides left, ends
    sliding right, and the energy change equals the work of the impulses at the mean contact
    velocity, ``(Pn (un- + un+) + Pt (ut- + ut+)) / 2``.
    """
    problem = rod(math.radians(45), [0.0, -1.0, -6.0], 0.3, 0.9)
    outcome = LAW.resolve(problem)
    _, un_plus, ut_plus = post_rates(problem, outcome.Pn, outcome.Pt)
    assert problem.ut[0] < 0 < ut_plus[0, 0]
    work = (outcome.Pn @ (problem.un + un_plus) + outcome.Pt @ (problem.ut + ut_plus[:, 0])) / 2
    assert outcome.dT == pytest.approx(work, rel=1e-12)
    assert outcome.dT > 0.1 * outcome.T_minus


@pytest.mark.parametrize("seed", range(20))
def test_uncoupled_approaching_contacts_never_gain_energy(seed):
    """G_nt = 0 (tangential directions orthogonal to the normals in M^-1), every contact
    approaching: dT = sum Pn (1 - e) un- / 2 + Pt.ut+ - Pt.Gtt Pt / 2 <= 0 (lecture: T_L <= 0
    because of decoupling)."""
    rng = np.random.default_rng(seed)
    m = 1 + seed % 3
    normals = rng.normal(size=(m, m))
    v = np.concatenate([np.linalg.solve(normals.T, -rng.uniform(0.1, 2, m)), rng.normal(size=m)])
    problem = ImpactProblem(
        M=np.diag(rng.uniform(0.2, 5, 2 * m)),
        Wn=np.vstack([normals, np.zeros((m, m))]),
        Wt=np.vstack([np.zeros((m, m)), rng.normal(size=(m, m))]),
        v=v,
        contacts=[Contact(e=rng.uniform(), mu=rng.uniform(0, 2)) for _ in range(m)],
    )
    assert problem.un.max() < 0
    outcome = LAW.resolve(problem)
    assert outcome.dT <= 1e-10 * outcome.T_minus


@pytest.mark.parametrize("seed", range(30))
def test_random_planar_outcomes_satisfy_the_law(seed):
    """Friction cone, admissibility, complementarity and Coulomb's direction, m = 1..5."""
    problem = random_planar(seed, 1 + seed % 5)
    try:
        outcome = LAW.resolve(problem)
    except NotApplicable:
        assert problem.m <= MAX_ENUMERATED and enumerate_planar(problem) == []
        return
    assert law_violation(problem, outcome.Pn, outcome.Pt) <= 1e-8
    for solution in outcome.diagnostics["solutions"]:
        assert law_violation(problem, np.array(solution["Pn"]), np.array(solution["Pt"])) <= 1e-8


@pytest.mark.parametrize("seed", range(24))
def test_lemke_and_enumeration_agree(seed):
    """Random planar problems, 2 to 6 contacts, mu up to 2.5: the law's solutions are the
    enumerated ones (these seeds include ambiguous problems and one without a solution).

    Up to MAX_ENUMERATED contacts the law lists the same set and picks the one of least
    kinetic energy; beyond, its (Lemke) answer is one of the enumerated solutions.
    """
    m = 2 + seed % 5
    # Beyond MAX_ENUMERATED the enumeration here is long when contacts are dependent (LPs).
    problem = random_planar(1000 + seed, m, mu_high=2.5, dependent=m <= MAX_ENUMERATED)
    expected = enumerate_planar(problem)
    try:
        outcome = LAW.resolve(problem)
    except NotApplicable as exc:
        assert m <= MAX_ENUMERATED and expected == [], exc
        return
    except SolverFailure as exc:
        assert m > MAX_ENUMERATED and "ray termination" in str(exc)
        return
    if m <= MAX_ENUMERATED:
        assert_same_set(listed_velocities(problem, outcome), expected, problem.M)
        energies = [v @ problem.M @ v / 2 for v in expected]
        assert outcome.T_plus == pytest.approx(min(energies), rel=1e-9)
        assert outcome.status == ("ok" if len(expected) == 1 else "ambiguous")
    else:
        assert outcome.diagnostics["uniqueness"] == "unchecked"
        assert outcome.diagnostics["formulation"] == "Lemke LCP"
        assert any(
            np.sqrt((outcome.v_plus - v) @ problem.M @ (outcome.v_plus - v)) < 1e-7
            for v in expected
        )


def test_strongly_coupled_rod_at_rest_has_two_solutions():
    """Rod at tan(theta) = 1/2 with f = 2: mu |G_nt| / G_nn = 1.5 >= 1.

    The end touches the floor without approaching (un- = 0) and slides right (ut- = 1): no
    impulse is a solution, and so is an impulse that sticks it (eq. 8 with un+ = 0, ut+ = 0,
    |pt| <= f pn). The law lists both, says 'ambiguous' and returns the one of least energy.
    With f = 0.5 (coupling 0.375) only the first remains.
    """
    theta, v = math.atan(0.5), [1.0, 0.0, 0.0]
    problem = rod(theta, v, 2.0, 0.9)
    outcome = LAW.resolve(problem)
    assert outcome.diagnostics["coupling"] == [pytest.approx(1.5)]
    assert outcome.status == "ambiguous"
    stick, pn, pt, _ = rod_equation_8(theta, v, 2.0, 0.0, "stick")
    assert pn > 0 and abs(pt) <= 2.0 * pn
    assert_same_set(listed_velocities(problem, outcome), [np.array(v), stick], problem.M)
    np.testing.assert_allclose(outcome.v_plus, stick, atol=1e-12)
    assert outcome.diagnostics["formulation"] == "closed form, stick"
    assert "least post-impact kinetic energy" in outcome.diagnostics["choice"]
    weak = LAW.resolve(rod(theta, v, 0.5, 0.9))
    assert weak.status == "ok" and weak.diagnostics["solutions"][0]["modes"] == ["no impulse"]
    np.testing.assert_array_equal(weak.v_plus, v)


# A spatial contact with strong coupling (mu |G_nt| / G_nn = 5.0), approaching: three solutions.
SPATIAL_AMBIGUOUS = {
    "G": [[0.58, 0.71, 1.41], [0.71, 1.02, 1.92], [1.41, 1.92, 5.14]],
    "un": [-0.21],
    "ut": [0.05, -1.98],
    "mu": [1.83],
    "e": [0.88],
}


def test_spatial_strong_coupling_several_solutions():
    """Every solution the angle scan finds is listed; the answer has the least energy."""
    problem = from_delassus(**SPATIAL_AMBIGUOUS)
    outcome = LAW.resolve(problem)
    expected = scan_spatial(problem)
    assert len(expected) == 3
    assert outcome.status == "ambiguous"
    assert outcome.diagnostics["coupling"][0] >= 1
    assert_same_set(listed_velocities(problem, outcome), expected, problem.M)
    assert outcome.T_plus == pytest.approx(min(v @ problem.M @ v / 2 for v in expected))


def test_no_solution_is_reported_with_the_coupling():
    """Two planar contacts on a body with 3 degrees of freedom (dependent contact directions),
    strong coupling: no mode is consistent (checked here by linear programming), and the law
    says so, naming the coupling and the rank of the contact Delassus matrix."""
    problem = ImpactProblem(
        M=np.diag([1.1, 1.3, 1.7]),
        Wn=[[0.6, -0.5], [1.2, -1.3], [-0.5, 0.0]],
        Wt=[[2.4, -0.9], [0.3, 0.5], [-1.6, 2.5]],
        v=[1.1, 0.4, -0.2],
        contacts=[Contact(e=0.2, mu=1.9), Contact(e=0.6, mu=0.5)],
    )
    assert enumerate_planar(problem) == []
    pattern = r"no solution.*strong.*mu \|G_nt\| / G_nn = 2.71, 1.76.*rank 3 < 4"
    with pytest.raises(NotApplicable, match=pattern):
        LAW.resolve(problem)


def test_dependent_contacts_block_landing_flat():
    """A block (2 m x 1 m, 1 kg) lands flat on both lower corners (3 degrees of freedom, four
    contact directions): sliding slowly it sticks at both corners, fast it slips at both.

    Sticking: vy+ = -e vy-, vx+ = 0, omega+ = 0 by symmetry of the targets; slipping with
    mu = 0.5: both corners slide forward and the total Pt = -mu (Pn1 + Pn2) = -mu m (1 + e)
    |vy-|, so vx+ = vx- - mu (1 + e) |vy-|.
    """
    corners = [(-1.0, -0.5), (1.0, -0.5)]

    def problem_for(vx):
        return ImpactProblem(
            M=np.diag([1.0, 1.0, (4 + 1) / 12]),
            Wn=np.array([[0.0, 1.0, rx] for rx, _ in corners]).T,
            Wt=np.array([[1.0, 0.0, -ry] for _, ry in corners]).T,
            v=[vx, -1.0, 0.0],
            contacts=[Contact(e=0.5, mu=0.5)] * 2,
        )

    slow = LAW.resolve(problem_for(0.1))
    np.testing.assert_allclose(slow.v_plus, [0.0, 0.5, 0.0], atol=1e-12)
    fast = LAW.resolve(problem_for(2.0))
    np.testing.assert_allclose(fast.v_plus, [2.0 - 0.5 * 1.5, 0.5, 0.0], atol=1e-12)
    for outcome, problem in ((slow, problem_for(0.1)), (fast, problem_for(2.0))):
        assert outcome.diagnostics["uniqueness"] == "unique"
        assert_same_set(listed_velocities(problem, outcome), enumerate_planar(problem), problem.M)


def spatial_body(v, mu, e=0.5):
    """A rigid body (mass 1, principal inertia 0.05, 0.08, 0.1) touching the floor z = 0 at
    r = (0.3, 0.2, -0.4) from its centre of mass; tangents x and y."""
    r, axes = np.array([0.3, 0.2, -0.4]), np.eye(3)
    return ImpactProblem(
        M=np.diag([1.0, 1.0, 1.0, 0.05, 0.08, 0.1]),
        Wn=spatial_column(r, axes[2])[:, None],
        Wt=np.column_stack([spatial_column(r, axes[0]), spatial_column(r, axes[1])]),
        v=v,
        contacts=[Contact(e=e, mu=mu)],
    )


@pytest.mark.parametrize(
    ("v", "mu"),
    [
        ([2.0, 0.0, -1.0, 0.0, 0.0, 0.0], 0.2),
        ([2.0, 0.0, -1.0, 0.0, 0.0, 0.0], 0.5),
        ([1.0, 0.5, -2.0, 1.0, 0.0, 0.0], 0.5),
        ([0.5, 0.0, -1.0, 0.0, 0.0, 3.0], 0.2),
    ],
)
def test_spatial_slip_direction_is_not_the_pre_impact_one(v, mu):
    """The post-impact slip turns away from the pre-impact one (inertial coupling), and the
    friction impulse opposes the post-impact slip; the angle scan finds the same answer."""
    problem = spatial_body(v, mu)
    outcome = LAW.resolve(problem)
    assert outcome.diagnostics["formulation"] == "closed form, slip direction from a quartic"
    _, _, ut_plus = post_rates(problem, outcome.Pn, outcome.Pt)
    before, after = problem.ut, ut_plus[0]
    turn = math.degrees(math.acos(before @ after / np.linalg.norm(before) / np.linalg.norm(after)))
    assert turn > 2.0
    np.testing.assert_allclose(
        outcome.Pt, -mu * outcome.Pn[0] * after / np.linalg.norm(after), atol=1e-12
    )
    assert_same_set([outcome.v_plus], scan_spatial(problem), problem.M)


@pytest.mark.parametrize("seed", range(20))
def test_random_spatial_contacts_match_the_angle_scan(seed):
    rng = np.random.default_rng(300 + seed)
    A = rng.normal(size=(3, 3))
    problem = from_delassus(
        A @ A.T + 0.05 * np.eye(3),
        rng.normal(size=1),
        rng.normal(size=2),
        [rng.uniform(0, 3)],
        [rng.uniform()],
    )
    outcome = LAW.resolve(problem)
    assert_same_set(listed_velocities(problem, outcome), scan_spatial(problem), problem.M)
    assert law_violation(problem, outcome.Pn, outcome.Pt) <= 1e-8


def with_mu(problem, mu):
    """The same problem with every friction coefficient set to ``mu``."""
    contacts = [Contact(e=c.e, mu=mu) for c in problem.contacts]
    return ImpactProblem(M=problem.M, Wn=problem.Wn, Wt=problem.Wt, v=problem.v, contacts=contacts)


WITHOUT_FRICTION = [
    *((3000 + seed, 1, "newton", "closed form", 1e-13) for seed in range(10)),
    *((2000 + seed, 2 + seed % 4, "moreau", "Lemke LCP", 1e-12) for seed in range(12)),
]


@pytest.mark.parametrize(("seed", "contacts", "peer", "formulation", "tiny_mu"), WITHOUT_FRICTION)
def test_mu_zero_is_newton_at_one_contact_and_moreau_at_several(
    seed, contacts, peer, formulation, tiny_mu
):
    """mu = 0 (and a tiny mu, through the frictional formulation) gives Newton's law for one
    approaching contact, and Moreau's unilateral LCP for several."""
    problem = random_planar(seed, contacts, mu_high=0.0)
    if contacts == 1 and problem.un[0] >= 0:
        problem = ImpactProblem(
            M=problem.M, Wn=problem.Wn, Wt=problem.Wt, v=-problem.v, contacts=problem.contacts
        )
    expected = lawbench.LAWS.get(peer).resolve(problem).v_plus
    atol = 1e-12 if contacts == 1 else 1e-8
    outcome = LAW.resolve(problem)
    np.testing.assert_allclose(outcome.v_plus, expected, atol=atol)
    assert outcome.diagnostics["formulation"] == formulation
    np.testing.assert_allclose(
        LAW.resolve(with_mu(problem, tiny_mu)).v_plus, expected, atol=max(atol, 1e-10)
    )


@pytest.mark.parametrize("seed", range(6))
def test_frictionless_chains_match_moreau(seed):
    params = {"n": 4 + seed, "velocities": np.random.default_rng(seed).normal(size=4 + seed)}
    case = lawbench.CASES.get("ball_chain")
    problem = case.build(**{**params, "velocities": params["velocities"].tolist()})
    expected = lawbench.LAWS.get("moreau").resolve(problem).v_plus
    np.testing.assert_allclose(LAW.resolve(problem).v_plus, expected, atol=1e-9)


def test_separating_contact_receives_no_restitution():
    """un- > 0 with weak coupling: no impulse at all, as moreau's default."""
    outcome = LAW.resolve(rod(math.radians(30), [1.0, 1.0, 0.0], 0.3, 0.8))
    np.testing.assert_array_equal(outcome.Pn, [0.0])
    assert outcome.diagnostics["formulation"] == "closed form, no impulse"


def test_squeezed_particle_without_friction_has_no_solution():
    """A particle between two walls, moving into one: un+ >= e |un-| at one wall and un+ >= 0
    at the other cannot both hold (their sum is zero); ray termination proves it."""
    problem = ImpactProblem(M=[[1.0]], Wn=[[1.0, -1.0]], v=[-1.0], contacts=[Contact(e=0.5)] * 2)
    with pytest.raises(NotApplicable, match="no solution"):
        LAW.resolve(problem)


def test_several_spatial_contacts_not_applicable():
    problem = ImpactProblem(
        M=np.eye(3),
        Wn=np.eye(3)[:, :2],
        Wt=np.ones((3, 4)),
        v=[-1.0, -1.0, 0.0],
        contacts=[Contact(mu=0.5)] * 2,
    )
    with pytest.raises(NotApplicable, match="2 spatial contacts"):
        LAW.resolve(problem)


@pytest.mark.parametrize(
    "problem",
    [random_planar(7, 3), random_planar(8, 6), from_delassus(**SPATIAL_AMBIGUOUS)],
    ids=["three planar", "six planar", "spatial"],
)
def test_deterministic(problem):
    first, second = LAW.resolve(problem), LAW.resolve(problem)
    np.testing.assert_array_equal(first.v_plus, second.v_plus)
    np.testing.assert_array_equal(first.Pt, second.Pt)
    for key in ("solutions", "formulation", "uniqueness", "coupling"):
        assert first.diagnostics[key] == second.diagnostics[key]


def test_the_wall_clock_stop_inside_lemke_ends_the_solve(monkeypatch):
    """Lemke's failure hands a problem of several contacts to the mode enumeration; the
    solve's time running out (the guard's stop, raised wherever the law's code runs) ends it."""
    from lawbench.core.errors import BudgetExceeded
    from lawbench.core.guards import stopped
    from lawbench.laws import whittaker

    def out_of_time(*args):
        raise stopped(0.1)

    monkeypatch.setattr(whittaker, "lemke", out_of_time)
    with pytest.raises(BudgetExceeded, match="wall-clock guard"):
        lawbench.solve("whittaker", "rocking_block")


def test_lemkes_rounding_never_leaves_a_contact_outside_its_cone():
    """Three contacts along one normal, all separating: no impulse acts, but Lemke's pivots
    left a tangential impulse of 5.5e-17 at a contact whose normal impulse is zero, outside
    its cone (the check's verdict a numerical failure, and ``lawbench solve`` refused it)."""
    tangents = [[0.57, -0.9, 0.51], [-0.97, -0.05, -0.15], [0.9, -0.9, 0.05]]
    problem = ImpactProblem.from_arrays(
        np.diag([0.0073, 0.0098, 0.0116]),
        [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
        [1.0, -2.0, -10.0],
        tangents,
        e=1.0,
        mu=0.3,
    )
    trial = lawbench.evaluate("whittaker", problem)
    assert trial.outcome.diagnostics["formulation"] == "Lemke LCP"
    assert lawbench.run_checks(trial, checks=["friction_cone"])["friction_cone"].passed


@pytest.mark.parametrize("case", ["bouncing_ball", "falling_rod", "lamina"])
def test_a_friction_coefficient_beyond_the_cones_range_is_refused_by_name(case):
    """mu = 1.7e308 overflowed the slip quartic (a LinAlgError in numpy's roots) and the cone
    rows of the planar modes (an invalid linear program)."""
    with pytest.raises(lawbench.NotApplicable, match=r"mu = 1\.7e\+308"):
        lawbench.solve("whittaker", case, mu=1.7e308)
