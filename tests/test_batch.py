"""Many small impacts at once: the batch path equals the one-by-one path.

The vectorized laws solve every problem of a batch with closed forms and active-set
enumeration on the Delassus matrices; the answers must be those of `Law.resolve` on each
problem, to 1e-12, on random chains with masses over three decades, coefficients per contact
and velocities of any sign (separating contacts included).
"""

import numpy as np
import pytest

import lawbench
from lawbench.numerics.solvers import enumerate_lcp, solve_lcp


def random_chains(rng, count, balls):
    """Random free chains of ``balls`` balls (stacked arrays), every contact closed."""
    masses = 10.0 ** rng.uniform(-1.5, 1.5, (count, balls))
    M = np.einsum("kn,nl->knl", masses, np.eye(balls))
    Wn = np.zeros((balls, balls - 1))
    for j in range(balls - 1):
        Wn[j, j], Wn[j + 1, j] = -1.0, 1.0
    v = rng.normal(size=(count, balls))
    e = rng.uniform(0.0, 1.0, (count, balls - 1))
    return lawbench.ProblemBatch(M, Wn, v, {"e": e})


@pytest.mark.parametrize("balls", [2, 3, 5, 7])
@pytest.mark.parametrize(
    ("law", "options"),
    [
        ("newton", {}),
        ("poisson", {}),
        ("moreau", {}),
        ("moreau", {"separating": "restitution"}),
    ],
)
def test_the_batch_equals_one_by_one(law, options, balls):
    batch = random_chains(np.random.default_rng(balls), 300, balls)
    together = lawbench.solve_batch(law, batch, options)
    entry = lawbench.LAWS.get(law)
    for k in range(len(batch)):
        alone = entry.resolve(batch.problem(k), **options)
        scale = np.abs(batch.v[k]).max()
        assert np.abs(together.v_plus[k] - alone.v_plus).max() <= 1e-12 * scale, k
        assert np.abs(together.Pn[k] - alone.Pn).max() <= 1e-12 * np.abs(alone.Pn).max() + 1e-300
        assert together.T_plus[k] == pytest.approx(alone.T_plus, rel=1e-12)


def test_a_law_without_a_vectorized_path_goes_one_by_one():
    batch = random_chains(np.random.default_rng(0), 20, 3)
    together = lawbench.solve_batch("sequential", batch)
    assert together.diagnostics["formulation"] == "one by one"
    for k in range(len(batch)):
        alone = lawbench.solve("sequential", batch.problem(k))
        assert np.array_equal(together.v_plus[k], alone.v_plus)


def test_a_list_of_problems_is_stacked_and_shapes_must_agree():
    problems = [lawbench.CASES.get("three_ball_chain").build(e=e) for e in (0.0, 0.5, 1.0)]
    together = lawbench.solve_batch("moreau", problems)
    for k, problem in enumerate(problems):
        expected = lawbench.solve("moreau", problem).v_plus
        assert np.abs(together.v_plus[k] - expected).max() <= 1e-12
    with pytest.raises(lawbench.InvalidProblem, match="problem 1 has"):
        lawbench.solve_batch("moreau", [problems[0], lawbench.CASES.get("ball_chain").build(n=5)])


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("e", 1.5, r"contacts\[0\]\.e = 1\.5"),
        ("v", np.nan, r"v\[0, 0\] = nan"),
        ("M", -1.0, "problem 0: M is not positive definite"),
    ],
)
def test_bad_batches_name_the_field_and_the_problem(field, value, message):
    M, Wn, v = np.eye(2), [[-1.0], [1.0]], np.array([[1.0, 0.0], [2.0, 0.0]])
    arrays = {"M": M, "v": v}
    coefficients = {}
    if field == "e":
        coefficients["e"] = value
    else:
        arrays[field] = np.where(np.ones_like(arrays[field], dtype=bool), value, 0.0) * (
            np.eye(2) if field == "M" else 1.0
        )
    with pytest.raises(lawbench.InvalidProblem, match=message):
        lawbench.ProblemBatch(arrays["M"], Wn, arrays["v"], coefficients)


@pytest.mark.parametrize(
    ("mass", "normal", "message"),
    [(1e-200, 1e200, "problem 1: .* Wn overflows"), (1.0, 1e-200, "problem 1: .* Wn underflows")],
)
def test_a_batch_names_a_delassus_entry_beyond_double_precision(mass, normal, message):
    """As `ImpactProblem`: an entry of 2e600 or 2e-500 is beyond range, not singular."""
    M = np.stack([np.eye(2), np.eye(2) * mass])
    Wn = np.stack([[[-1.0], [1.0]], [[-normal], [normal]]])
    with pytest.raises(lawbench.InvalidProblem, match=message):
        lawbench.ProblemBatch(M, Wn, np.array([[1.0, 0.0], [1.0, 0.0]]))


def test_a_batch_of_an_extreme_jacobian_is_judged_by_its_geometry():
    """Wn of 1e160 on masses of 1e300: W = 2e20, though the squares of Wn overflow."""
    batch = lawbench.ProblemBatch(np.eye(2)[None] * 1e300, [[[-1e160], [1e160]]], [[1.0, 0.0]])
    assert batch.delassus[0, 0, 0] == pytest.approx(2e20)


@pytest.mark.parametrize("m", [2, 3, 4, 6])
def test_enumeration_solves_the_lcp_exactly(m):
    """Against Lawson-Hanson NNLS (finite and exact): same z, and w = Gz + q complementary."""
    rng = np.random.default_rng(m)
    for _ in range(50):
        A = rng.normal(size=(m, m))
        G = A @ A.T + 1e-3 * np.eye(m)
        q = rng.normal(size=m)
        z, found = enumerate_lcp(G, q)
        assert found
        w = G @ z + q
        assert z.min() >= 0 and w.min() >= -1e-10 * np.abs(q).max()
        assert abs(z @ w) <= 1e-10 * np.abs(q).max() * max(np.abs(z).max(), 1e-300)
        assert np.allclose(z, solve_lcp(G, q, method="nnls").z, atol=1e-10)


def test_enumeration_of_a_batch_equals_one_at_a_time_bit_for_bit():
    rng = np.random.default_rng(7)
    A = rng.normal(size=(200, 3, 3))
    G = A @ np.swapaxes(A, 1, 2) + 1e-2 * np.eye(3)
    q = rng.normal(size=(200, 3))
    together, _ = enumerate_lcp(G, q)
    for k in range(200):
        alone, _ = enumerate_lcp(G[k], q[k])
        assert np.array_equal(together[k], alone)
