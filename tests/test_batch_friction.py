"""One-contact frictional impacts in a batch: the batch path equals the one-by-one path.

Whittaker's, Brach's and Moreau's one-contact laws are closed forms per mode, and
Darboux-Keller's planar impulse-time phases are too, vectorized over the batch; every other law
takes a frictional batch one by one. On random bodies (full mass
matrices, planar and spatial contacts, e from 0 to 1, mu from 0 to large, sticking and
sliding) each answer must be `Law.resolve`'s to 1e-10 of the problem's speed and impulse.
"""

import numpy as np
import pytest

import lawbench
from lawbench.core.batch import ProblemBatch


def random_contacts(seed, count, d):
    """``count`` random one-contact problems with ``d`` tangential directions, stacked."""
    rng = np.random.default_rng(seed)
    n = 3 + d
    A = rng.normal(size=(count, n, n))
    M = A @ np.swapaxes(A, 1, 2) + 0.5 * np.eye(n)
    Wn, Wt = rng.normal(size=(count, n, 1)), rng.normal(size=(count, n, d))
    v = rng.normal(size=(count, n))
    e = rng.choice([0.0, 1.0, 0.5], (count, 1)) * (rng.uniform(size=(count, 1)) < 0.2)
    e = np.where(rng.uniform(size=(count, 1)) < 0.2, e, rng.uniform(0, 1, (count, 1)))
    mu = 10.0 ** rng.uniform(-2, 1.5, (count, 1)) * (rng.uniform(size=(count, 1)) > 0.1)
    coefficients = {"e": e, "mu": mu, "e_t": rng.uniform(-1, 1, (count, 1))}
    return ProblemBatch(M, Wn, v, coefficients, Wt)


def assert_equal_one_by_one(law, batch, options=None):
    """Each problem of ``batch`` solved alone gives the batch's answer (skip those it refuses)."""
    options = options or {}
    together = lawbench.solve_batch(law, batch, options)
    entry, compared = lawbench.LAWS.get(law), 0
    for k in range(len(batch)):
        try:
            alone = entry.resolve(batch.problem(k), **options)
        except (lawbench.NotApplicable, lawbench.SolverFailure):
            continue
        compared += 1
        speed, impulse = np.abs(batch.v[k]).max(), max(np.abs(alone.Pn).max(), 1e-300)
        assert np.abs(together.v_plus[k] - alone.v_plus).max() <= 1e-10 * speed, k
        assert np.abs(together.Pn[k] - alone.Pn).max() <= 1e-10 * impulse, k
        assert np.abs(together.Pt[k] - alone.Pt).max() <= 1e-10 * impulse, k
        assert together.T_plus[k] == pytest.approx(alone.T_plus, rel=1e-9, abs=1e-12)
    assert compared >= len(batch) // 2
    return together


def assert_both_regimes(batch, together):
    """Impulses inside the Coulomb cone (stick) and on its boundary (slip) both occur."""
    Pt = np.linalg.norm(together.Pt, axis=1)
    bound = batch.mu[:, 0] * together.Pn[:, 0]
    on_cone = np.isclose(Pt, bound, rtol=1e-9) & (bound > 0)
    assert on_cone.any() and (Pt < bound * (1 - 1e-6)).any()


@pytest.mark.parametrize("d", [1, 2])
@pytest.mark.parametrize(("law", "count"), [("whittaker", 80), ("brach", 80), ("moreau", 20)])
def test_a_frictional_batch_equals_one_by_one(law, count, d):
    batch = random_contacts(40 + d, count, d)
    together = assert_equal_one_by_one(law, batch)
    assert together.diagnostics["formulation"].startswith("closed form (batch)")
    assert together.diagnostics["one_by_one"] < count // 4
    assert_both_regimes(batch, together)


@pytest.mark.parametrize("termination", ["energetic", "newton", "poisson"])
def test_darboux_keller_phases_in_a_planar_batch_equal_one_by_one(termination):
    batch = random_contacts(7, 80, 1)
    together = assert_equal_one_by_one("darboux_keller", batch, {"termination": termination})
    assert together.diagnostics["formulation"] == "exact piecewise (batch)"
    assert together.diagnostics["one_by_one"] == 0
    assert_both_regimes(batch, together)


def test_moreau_leaves_problems_without_a_unique_solution_to_its_solver():
    """Strong coupling at a separating contact: no impulse, or a slip that closes it."""
    M, Wn, Wt = np.eye(2), [[0.0], [1.0]], [[1.0], [3.0]]
    v = np.array([[1.0, 0.1], [1.0, -1.0]])
    batch = ProblemBatch(M, Wn, v, {"e": 0.5, "mu": 1.0}, Wt)
    together = assert_equal_one_by_one("moreau", batch)
    assert together.diagnostics["one_by_one"] >= 1


@pytest.mark.parametrize("d", [1, 2])
def test_a_law_without_a_batch_path_takes_a_frictional_batch_one_by_one(d):
    batch = random_contacts(11, 6, d)
    together = assert_equal_one_by_one("jia", batch)
    assert together.diagnostics["formulation"] == "one by one"


def test_spatial_slip_that_may_turn_is_left_to_the_integrator():
    batch = random_contacts(13, 5, 2)
    together = assert_equal_one_by_one("darboux_keller", batch)
    frictional = int(np.count_nonzero((batch.mu[:, 0] > 0) & (batch.un[:, 0] < 0)))
    assert together.diagnostics["one_by_one"] == frictional > 0


def test_a_frictionless_law_refuses_a_frictional_batch_as_it_refuses_a_problem():
    batch = random_contacts(0, 5, 1)
    with pytest.raises(lawbench.NotApplicable, match="newton: the problem has friction"):
        lawbench.solve_batch("newton", batch)


def test_problems_stack_into_a_batch_and_come_back_unchanged():
    scene = lawbench.CASES.get("lamina")
    problems = [scene.build(mu=mu) for mu in (0.0, 0.1, 0.3)]
    batch = ProblemBatch.from_problems(problems)
    assert batch.d == problems[0].d == 1
    for k, problem in enumerate(problems):
        again = batch.problem(k)
        np.testing.assert_array_equal(again.Wt, problem.Wt)
        np.testing.assert_array_equal(again.mu, problem.mu)
        assert again.contacts[0].e_t == problem.contacts[0].e_t
    together = lawbench.solve_batch("whittaker", problems)
    for k, problem in enumerate(problems):
        np.testing.assert_allclose(
            together.v_plus[k], lawbench.solve("whittaker", problem).v_plus, atol=1e-12
        )
    with pytest.raises(lawbench.InvalidProblem, match=r"problem 1 has \(n, m, d\)"):
        ProblemBatch.from_problems([problems[0], lawbench.CASES.get("three_ball_chain").build()])


@pytest.mark.parametrize(
    ("coefficients", "Wt", "message"),
    [
        ({"mu": -0.5}, [[1.0], [0.0]], r"problem 0: contacts\[0\]\.mu = -0\.5: must be >= 0"),
        ({"mu": np.inf}, [[1.0], [0.0]], r"contacts\[0\]\.mu = inf: must be a finite number"),
        ({"e_t": 1.5}, [[1.0], [0.0]], r"contacts\[0\]\.e_t = 1\.5: must be in \[-1, 1\]"),
        ({"mu": 0.5}, None, "coefficient 'mu' without a tangential Jacobian"),
        ({}, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], r"Wt has shape \(2, 3\)"),
        ({}, [[np.nan], [0.0]], r"Wt\[0, 0, 0\] = nan"),
    ],
)
def test_bad_frictional_batches_name_the_field_and_the_problem(coefficients, Wt, message):
    with pytest.raises(lawbench.InvalidProblem, match=message):
        ProblemBatch(np.eye(2), [[0.0], [1.0]], [[1.0, -1.0]], coefficients, Wt)
