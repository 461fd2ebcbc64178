"""The Darboux-Keller law: frictionless reductions, stick/slip phases, planar vs spatial, energy.

Sources of the expected values: Brogliato, *An introduction to impact dynamics* (lectures,
2010): frictionless single impacts (eqs. 2-4: the three coefficients agree and equal Newton's),
Coulomb friction along the impulse (the normal impulse as clock) and the 3D dynamics (eq. 15);
W.J. Stronge (J. Appl. Mech. 58, 1991, "Unraveling paradoxical theories for rigid body
collisions"): the energetic coefficient never creates energy, Newton's can when slip halts or
reverses.
"""

import dataclasses

import numpy as np
import pytest

import lawbench
from lawbench import Contact, ImpactProblem
from lawbench.numerics.rigid import planar_column

LAW = lawbench.LAWS.get("darboux_keller")
NEWTON = lawbench.LAWS.get("newton")
TERMINATIONS = ("newton", "poisson", "energetic")


def random_problem(rng, n, d, mu=None, e=None):
    """One approaching contact on n coordinates with d tangential directions (0: none)."""
    A = rng.normal(size=(n, n))
    M = A @ A.T + 0.3 * n * np.eye(n)
    Wn, v = rng.normal(size=(n, 1)), rng.normal(size=n)
    if Wn[:, 0] @ v > 0:
        v = -v
    contact = Contact(
        e=rng.uniform() if e is None else e, mu=rng.uniform(0, 2) if mu is None else mu
    )
    Wt = rng.normal(size=(n, d)) if d else None
    return ImpactProblem(M=M, Wn=Wn, Wt=Wt, v=v, contacts=[contact])


def embedded(problem):
    """The planar ``problem`` as a spatial one: a second tangent on an extra, uncoupled mass."""
    n = problem.n
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[n, n] = problem.M, 2.0
    Wt = np.zeros((n + 1, 2))
    Wt[:n, 0], Wt[n, 1] = problem.Wt[:, 0], 1.0
    return ImpactProblem(
        M=M,
        Wn=np.vstack([problem.Wn, [[0.0]]]),
        Wt=Wt,
        v=np.append(problem.v, 0.0),
        contacts=problem.contacts,
    )


def rod(angle, v, e, mu, length=1.0, mass=1.0):
    """A uniform rod (x, y, theta) whose lower end at ``angle`` to the floor strikes it."""
    inertia = mass * length**2 / 12
    r = -length / 2 * np.array([np.cos(angle), np.sin(angle)])
    Wn = planar_column(r, np.array([0.0, 1.0]))[:, None]
    Wt = planar_column(r, np.array([1.0, 0.0]))[:, None]
    M = np.diag([mass, mass, inertia])
    return ImpactProblem(M=M, Wn=Wn, Wt=Wt, v=v, contacts=[Contact(e=e, mu=mu)]), r


# --- frictionless ------------------------------------------------------------------------------


@pytest.mark.parametrize("termination", TERMINATIONS)
@pytest.mark.parametrize("d", [0, 1, 2])
def test_frictionless_equals_newton_on_one_contact(termination, d):
    """Lectures, eqs. (3)-(4): without friction every coefficient gives un+ = -e un-."""
    rng = np.random.default_rng(3 + d)
    for _ in range(20):
        problem = random_problem(rng, 4, d, mu=0.0)
        outcome = LAW.resolve(problem, termination=termination)
        expected = NEWTON.resolve(problem)
        np.testing.assert_allclose(outcome.v_plus, expected.v_plus, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(outcome.Pn, expected.Pn, rtol=1e-12)
        assert outcome.diagnostics["formulation"] == "exact (frictionless)"
        assert outcome.diagnostics["phases"] == [
            "frictionless",
            "end of compression",
            "end of impact",
        ]


@pytest.mark.parametrize("kind", ["newton", "poisson", "energy"])
def test_each_termination_reads_its_own_coefficient(kind):
    termination = {"energy": "energetic"}.get(kind, kind)
    contact = Contact(e=0.1, **{f"e_{kind}": 0.9})
    problem = ImpactProblem(M=[[2.0]], Wn=[[1.0]], v=[-1.0], contacts=[contact])
    assert LAW.resolve(problem, termination=termination).v_plus[0] == pytest.approx(0.9)


# --- planar phases against hand computations ---------------------------------------------------


def particle(ut, mu, e=0.5, un=-1.0, mass=2.0):
    """A point mass on a plane: Gnn = Gtt = 1/m, Gnt = 0."""
    return ImpactProblem(
        M=np.eye(2) * mass,
        Wn=[[0.0], [1.0]],
        Wt=[[1.0], [0.0]],
        v=[ut, un],
        contacts=[Contact(e=e, mu=mu)],
    )


@pytest.mark.parametrize("termination", TERMINATIONS)
def test_particle_slipping_throughout(termination):
    """Slip never stops: Pt = -mu Pn sign(ut-), Pn = (1 + e) m |un-| (no coupling)."""
    outcome = LAW.resolve(particle(ut=3.0, mu=0.4), termination=termination)
    Pn = 1.5 * 2.0 * 1.0
    np.testing.assert_allclose(outcome.Pn, [Pn], rtol=1e-14)
    np.testing.assert_allclose(outcome.Pt, [-0.4 * Pn], rtol=1e-14)
    np.testing.assert_allclose(outcome.v_plus, [3.0 - 0.4 * Pn / 2.0, 0.5], rtol=1e-14)
    assert outcome.diagnostics["phases"] == ["slip", "end of compression", "end of impact"]


@pytest.mark.parametrize("termination", TERMINATIONS)
def test_particle_slip_then_stick(termination):
    """Slip stops at Pn = m |ut-| / mu before compression ends; stick lasts (Gtn = 0)."""
    outcome = LAW.resolve(particle(ut=-0.2, mu=0.5), termination=termination)
    d = outcome.diagnostics
    assert d["phases"] == ["slip", "stick", "end of compression", "end of impact"]
    np.testing.assert_allclose(d["phase_impulses"], [0.0, 0.8, 2.0, 3.0], rtol=1e-14)
    np.testing.assert_allclose(outcome.v_plus, [0.0, 0.5], atol=1e-15)
    np.testing.assert_allclose(outcome.Pt, [0.4], rtol=1e-14)


def test_particle_at_rest_tangentially_sticks():
    outcome = LAW.resolve(particle(ut=0.0, mu=0.1))
    assert outcome.diagnostics["phases"] == ["stick", "end of compression", "end of impact"]
    np.testing.assert_allclose(outcome.Pt, [0.0])


def rod_by_hand(angle, v, e, mu):
    """Newton's termination on the rod of `rod` with slip in direction +1 that stops in
    compression, then sticks or reverses (affine phases, slopes from the Delassus entries)."""
    length, mass = 1.0, 1.0
    inertia = mass * length**2 / 12
    rx, ry = -length / 2 * np.cos(angle), -length / 2 * np.sin(angle)
    Gnn, Gtt, Gnt = 1 / mass + rx**2 / inertia, 1 / mass + ry**2 / inertia, -rx * ry / inertia
    un, ut = v[1] + rx * v[2], v[0] - ry * v[2]
    assert ut > 0 and Gnt - mu * Gtt < 0
    stop = -ut / (Gnt - mu * Gtt)
    un_stop = un + (Gnn - mu * Gnt) * stop
    assert un_stop < 0
    if mu * Gtt >= abs(Gnt):
        name, ratio = "stick", -Gnt / Gtt
    else:
        name, ratio = "slip reversal", mu
    slope = Gnn + Gnt * ratio
    compression = stop - un_stop / slope
    end = compression + e * -un / slope
    Pt = -mu * stop + ratio * (end - stop)
    phases = ["slip", name, "end of compression", "end of impact"]
    return phases, [0.0, stop, compression, end], Pt


@pytest.mark.parametrize(("mu", "expected"), [(0.3, "slip reversal"), (0.9, "stick")])
def test_rod_stick_or_reversal_by_the_criterion(mu, expected):
    """Stick lasts iff mu Gtt >= |Gtn|; otherwise slip reverses. Angular momentum about the
    contact point is conserved by any impulse there."""
    angle, v = 0.9, np.array([0.5, -1.0, 0.0])
    problem, r = rod(angle, v, 0.8, mu)
    outcome = LAW.resolve(problem, termination="newton")
    phases, impulses, Pt = rod_by_hand(angle, v, 0.8, mu)
    assert phases[1] == expected
    assert outcome.diagnostics["phases"] == phases
    np.testing.assert_allclose(outcome.diagnostics["phase_impulses"], impulses, rtol=1e-13)
    np.testing.assert_allclose(outcome.Pt, [Pt], rtol=1e-13)

    def momentum_about_contact(w):
        return problem.M[2, 2] * w[2] + (-r[0] * w[1] + r[1] * w[0]) * problem.M[0, 0]

    assert momentum_about_contact(outcome.v_plus) == pytest.approx(
        momentum_about_contact(v), abs=1e-14
    )


@pytest.mark.parametrize("mu", [0.5, 0.9])
def test_newton_termination_gains_energy_where_stronge_does_not(mu):
    """Stronge 1991: on a rod whose slip halts (mu = 0.9) or reverses (mu = 0.5), Newton's
    termination with e = 1 ends with more kinetic energy; the energetic one never does."""
    problem, _ = rod(0.9, np.array([0.5, -1.0, 0.0]), 1.0, mu)
    assert LAW.resolve(problem, termination="newton").dT > 1e-3
    assert LAW.resolve(problem, termination="energetic").dT <= 0


# --- spatial -----------------------------------------------------------------------------------


def turning_slip_problems():
    rng = np.random.default_rng(1)
    return [random_problem(rng, 4, 2) for _ in range(2)]


@pytest.mark.parametrize("termination", TERMINATIONS)
def test_spatial_slip_in_a_plane_matches_planar_exact(termination):
    """Slip whose rate lies along it keeps its direction: solved exactly, as in the plane."""
    rng = np.random.default_rng(21)
    for _ in range(8):
        planar = random_problem(rng, 3, 1)
        exact = LAW.resolve(planar, termination=termination)
        spatial = LAW.resolve(embedded(planar), termination=termination)
        assert exact.diagnostics["formulation"] == "exact piecewise (planar)"
        assert spatial.diagnostics["formulation"] == "exact piecewise (spatial)"
        # Spatial slip restarting from rest is named by its fixed direction.
        phases = [
            p.replace("slip (fixed direction)", "slip reversal")
            for p in spatial.diagnostics["phases"]
        ]
        assert phases == exact.diagnostics["phases"]
        np.testing.assert_allclose(spatial.v_plus[:3], exact.v_plus, rtol=1e-12, atol=1e-12)
        assert spatial.v_plus[3] == 0


@pytest.mark.parametrize("termination", TERMINATIONS)
def test_spatial_ode_tends_to_planar_exact_as_slip_leaves_the_plane(termination):
    """An out-of-plane slip of 1e-9 |v| makes the slip turn (ODE); the outcome stays within the
    ODE tolerance of the planar exact one."""
    rng = np.random.default_rng(22)
    rtol = 1e-8
    for _ in range(8):
        planar = random_problem(rng, 3, 1)
        exact = LAW.resolve(planar, termination=termination)
        scale = np.abs(planar.v).max()
        tilted = embedded(planar)
        tilted = dataclasses.replace(tilted, v=np.append(planar.v, 1e-9 * scale))
        ode = LAW.resolve(tilted, termination=termination, tol=rtol)
        assert ode.diagnostics["formulation"] == "ODE (spatial)"
        assert np.abs(ode.v_plus[:3] - exact.v_plus).max() <= 10 * rtol * scale


def test_planar_answer_does_not_depend_on_rtol():
    problem = random_problem(np.random.default_rng(5), 3, 1)
    loose, tight = LAW.resolve(problem, tol=1e-2), LAW.resolve(problem, tol=1e-13)
    np.testing.assert_array_equal(loose.v_plus, tight.v_plus)


def test_spatial_error_decreases_with_rtol():
    for problem in turning_slip_problems():
        reference = LAW.resolve(problem, tol=1e-12)
        errors, steps = [], []
        for rtol in [1e-4, 1e-6, 1e-8]:
            outcome = LAW.resolve(problem, tol=rtol)
            errors.append(np.abs(outcome.v_plus - reference.v_plus).max())
            steps.append(outcome.diagnostics["ode_steps"])
        assert errors[0] > errors[1] > errors[2]
        assert errors[2] <= 1e-6 * np.abs(problem.v).max()
        assert steps[0] < steps[2]


# --- properties on random problems ------------------------------------------------------------


@pytest.mark.parametrize(("d", "count", "rtol"), [(1, 300, 1e-9), (2, 100, 1e-6)])
def test_stronge_never_gains_energy_and_stays_admissible(d, count, rtol):
    """Stronge's termination dissipates; |Pt| <= mu Pn; no approach after; Pn >= 0."""
    rng = np.random.default_rng(100 + d)
    for _ in range(count):
        problem = random_problem(rng, int(rng.integers(2, 6)), d)
        outcome = LAW.resolve(problem, tol=rtol)
        assert outcome.dT <= 1e-12 * outcome.T_minus, (outcome.dT, outcome.diagnostics)
        assert outcome.Pn[0] > 0
        assert np.linalg.norm(outcome.Pt) <= problem.mu[0] * outcome.Pn[0] * (1 + 1e-12)
        # Exact in the plane; in space to the ODE's tolerance on the contact velocity.
        speed = np.linalg.norm(np.concatenate([problem.un, problem.ut]))
        tolerance = 1e-12 if d == 1 else 10 * rtol
        assert problem.Wn[:, 0] @ outcome.v_plus >= -tolerance * speed


def test_poisson_termination_dissipates_on_planar_problems():
    """Measured here on random planar problems, consistently with Djerassi (2009): in 2D
    Poisson's hypothesis within the impulse-time dynamics is energy-consistent."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        problem = random_problem(rng, int(rng.integers(2, 6)), 1)
        outcome = LAW.resolve(problem, termination="poisson")
        assert outcome.dT <= 1e-12 * outcome.T_minus


# --- outcome fields, path, refusals ------------------------------------------------------------


@pytest.mark.parametrize("d", [1, 2])
def test_path_contents(d):
    problem = turning_slip_problems()[0] if d == 2 else rod(0.9, [0.5, -1.0, 0.0], 0.8, 0.3)[0]
    outcome = LAW.resolve(problem, path=True, tol=1e-6)
    path, diagnostics = outcome.path, outcome.diagnostics
    k = path["Pn"].size
    assert set(path) == {"Pn", "Pt", "un", "ut", "Wn", "v"}
    assert path["Pt"].shape == path["ut"].shape == (k, d)
    assert path["v"].shape == (k, problem.n)
    assert path["Pn"][0] == 0 and np.all(np.diff(path["Pn"]) >= 0)
    assert path["Pn"][-1] == outcome.Pn[0]
    np.testing.assert_allclose(path["Pt"][-1], outcome.Pt, rtol=1e-12)
    np.testing.assert_allclose(path["v"][-1], outcome.v_plus, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(path["un"], path["v"] @ problem.Wn[:, 0], atol=1e-8)
    np.testing.assert_allclose(path["ut"], path["v"] @ problem.Wt, atol=1e-8)
    at_compression = np.argmin(np.abs(path["Pn"] - diagnostics["compression_impulse"]))
    assert path["un"][at_compression] == pytest.approx(0, abs=1e-9)
    assert path["Wn"][at_compression] == pytest.approx(diagnostics["work_compression"])
    assert path["Wn"][-1] == pytest.approx(
        diagnostics["work_compression"] + diagnostics["work_restitution"]
    )
    assert LAW.resolve(problem).path is None


@pytest.mark.parametrize("d", [1, 2])
def test_deterministic(d):
    problem = (
        turning_slip_problems()[0] if d == 2 else random_problem(np.random.default_rng(0), 3, 1)
    )
    first, second = LAW.resolve(problem, tol=1e-6), LAW.resolve(problem, tol=1e-6)
    np.testing.assert_array_equal(first.v_plus, second.v_plus)
    np.testing.assert_array_equal(first.Pt, second.Pt)
    assert first.diagnostics["phase_impulses"] == second.diagnostics["phase_impulses"]


def test_contact_not_approaching_gets_nothing():
    problem = ImpactProblem(
        M=np.eye(2),
        Wn=[[0.0], [1.0]],
        Wt=[[1.0], [0.0]],
        v=[1.0, 0.5],
        contacts=[Contact(e=0.5, mu=0.5)],
    )
    outcome = LAW.resolve(problem)
    np.testing.assert_array_equal(outcome.v_plus, problem.v)
    np.testing.assert_array_equal(outcome.Pn, [0.0])
    np.testing.assert_array_equal(outcome.Pt, [0.0])
    path = LAW.resolve(problem, path=True).path
    np.testing.assert_array_equal(path["v"], [problem.v])
    np.testing.assert_array_equal(path["Pn"], [0.0])


def test_zero_restitution_is_plastic_for_every_termination():
    problem = dataclasses.replace(
        random_problem(np.random.default_rng(2), 3, 1), contacts=[Contact(e=0.0, mu=0.5)]
    )
    for termination in TERMINATIONS:
        outcome = LAW.resolve(problem, termination=termination)
        assert problem.Wn[:, 0] @ outcome.v_plus == pytest.approx(0, abs=1e-14)


def test_refuses_several_contacts_and_bad_options():
    chain = lawbench.CASES.get("three_ball_chain").build()
    with pytest.raises(lawbench.NotApplicable, match="treats one"):
        LAW.resolve(chain)
    problem = particle(ut=1.0, mu=0.3)
    with pytest.raises(lawbench.InvalidProblem, match="termination"):
        LAW.resolve(problem, termination="ivanov")
    with pytest.raises(lawbench.InvalidProblem, match="tol"):
        LAW.resolve(problem, tol=0.5)
    assert LAW.tags.accuracy_knob == "tol"
