"""Lemke's complementary pivoting against brute-force enumeration of complementary bases.

An LCP ``w = M z + q``, ``0 <= w _|_ z >= 0`` of size n has 2^n complementary bases (for each
i, either z_i or w_i may be non-zero); enumerating them all finds every solution. A P-matrix
(every principal minor positive) gives exactly one solution for every q (Cottle, Pang and
Stone, *The Linear Complementarity Problem*, 1992, theorem 3.3.7); Lemke's method processes
P-matrices and positive semidefinite matrices (ibid., section 4.4).
"""

import itertools

import numpy as np
import pytest

from lawbench.core.errors import InvalidProblem, SolverFailure
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.laws.whittaker import planar_friction_lcp
from lawbench.numerics.lemke import RayTermination, lemke


def enumerate_solutions(M, q, tol=1e-9):
    """Every solution z found over the 2^n complementary bases (duplicates removed)."""
    n, scale = len(q), max(np.abs(q).max(), 1.0)
    found = []
    for support in itertools.product([False, True], repeat=n):
        support = np.array(support)
        z = np.zeros(n)
        if support.any():
            block = M[np.ix_(support, support)]
            if abs(np.linalg.det(block)) < 1e-12:
                continue
            z[support] = np.linalg.solve(block, -q[support])
        w = M @ z + q
        if z.min() >= -tol * scale and w.min() >= -tol * scale:
            if not any(np.allclose(z, other, atol=1e-9 * scale) for other in found):
                found.append(z)
    return found


def assert_solves(M, q, result, tol=1e-9):
    scale = max(np.abs(q).max(), 1.0)
    assert result.z.min() >= 0 and result.w.min() >= 0
    np.testing.assert_allclose(result.w, M @ result.z + q, atol=tol * scale)
    assert np.abs(result.z * result.w).max() <= tol * scale * max(result.z.max(), 1.0)


def nonsymmetric_p_matrix(rng, n):
    """Symmetric positive definite plus a skew part: every principal minor is positive."""
    A, S = rng.normal(size=(n, n)), rng.normal(size=(n, n))
    return A @ A.T + 0.1 * np.eye(n) + 2.0 * (S - S.T)


def spd_matrix(rng, n):
    A = rng.normal(size=(n, n))
    return A @ A.T + 1e-2 * np.eye(n)


@pytest.mark.parametrize("seed", range(30))
@pytest.mark.parametrize("kind", [nonsymmetric_p_matrix, spd_matrix])
def test_unique_solution_matches_enumeration(seed, kind):
    """P-matrices (here positive definite, symmetric or not) have one solution: Lemke finds it."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 9))
    M, q = kind(rng, n), rng.normal(size=n)
    result = lemke(M, q)
    (expected,) = enumerate_solutions(M, q)
    np.testing.assert_allclose(result.z, expected, atol=1e-9 * np.abs(expected).max() + 1e-12)
    assert_solves(M, q, result)
    assert (result.pivots == 0) == (q.min() >= 0)


def random_friction_problem(rng, m):
    """m planar frictional contacts on a random body: random SPD M, Wn, Wt, v."""
    n = int(rng.integers(2 * m, 2 * m + 3))
    A = rng.normal(size=(n, n))
    contacts = [Contact(e=rng.uniform(), mu=rng.uniform(0.0, 1.0)) for _ in range(m)]
    return ImpactProblem(
        M=A @ A.T + 0.1 * np.eye(n),
        Wn=rng.normal(size=(n, m)),
        Wt=rng.normal(size=(n, m)),
        v=rng.normal(size=n),
        contacts=contacts,
    )


def impulses(z, m):
    return np.concatenate([z[:m], z[m : 2 * m] - z[2 * m : 3 * m]])


@pytest.mark.parametrize("seed", range(24))
def test_friction_lcp_matches_enumeration(seed):
    """The planar friction LCP (4m unknowns, m = 1..3): Lemke's answer is one of the solutions.

    The LCP's solutions are not unique in z (Pt+ and Pt- can both be positive when sticking)
    but their impulses (Pn, Pt+ - Pt-) are what matter: Lemke's are among the enumerated ones.
    """
    rng = np.random.default_rng(100 + seed)
    m = 1 + seed % 3
    A, b = planar_friction_lcp(random_friction_problem(rng, m))
    solutions = enumerate_solutions(A, b)
    try:
        result = lemke(A, b)
    except RayTermination:
        # Lemke's method is not guaranteed on this matrix class; enumeration decides.
        pytest.skip("ray termination on a strongly coupled friction LCP")
    assert_solves(A, b, result)
    found = impulses(result.z, m)
    scale = max(np.abs(found).max(), 1.0)
    assert any(np.allclose(found, impulses(z, m), atol=1e-8 * scale) for z in solutions)


def test_friction_lcp_without_coupling_always_solved():
    """Without normal-tangential coupling (Wt orthogonal to Wn in M^-1) Lemke always succeeds.

    The friction LCP matrix is then copositive-plus, which Lemke's method processes (Cottle,
    Pang and Stone 1992, theorem 4.4.13); the solution must also be one the enumeration finds.
    """
    rng = np.random.default_rng(7)
    for m in (1, 2, 3):
        for _ in range(5):
            n = 2 * m
            contacts = [Contact(e=rng.uniform(), mu=rng.uniform(0, 1)) for _ in range(m)]
            problem = ImpactProblem(
                M=np.diag(rng.uniform(0.5, 2.0, n)),
                Wn=np.vstack([rng.normal(size=(m, m)), np.zeros((m, m))]),
                Wt=np.vstack([np.zeros((m, m)), rng.normal(size=(m, m))]),
                v=rng.normal(size=n),
                contacts=contacts,
            )
            A, b = planar_friction_lcp(problem)
            result = lemke(A, b)
            assert_solves(A, b, result)
            found = impulses(result.z, m)
            assert any(
                np.allclose(found, impulses(z, m), atol=1e-8) for z in enumerate_solutions(A, b)
            )


def test_nonnegative_q_is_solved_by_zero():
    M, q = np.array([[1.0, 2.0], [-3.0, 1.0]]), np.array([0.0, 2.0])
    result = lemke(M, q)
    assert result.pivots == 0
    np.testing.assert_array_equal(result.z, [0.0, 0.0])
    np.testing.assert_array_equal(result.w, q)


def test_ray_termination_is_reported_with_the_pivot_count():
    """``w1 = z1 - z2 - 1``, ``w2 = -z1 + z2 - 1``: ``w1 + w2 = -2`` is never >= 0.

    M is positive semidefinite, so ray termination is the proof that no solution exists.
    """
    M, q = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])
    with pytest.raises(RayTermination, match=r"ray termination after \d+ pivots"):
        lemke(M, q)
    assert issubclass(RayTermination, SolverFailure)
    assert enumerate_solutions(M, q) == []


def test_pivot_bound_is_reported():
    rng = np.random.default_rng(3)
    M, q = spd_matrix(rng, 6), -np.ones(6)
    with pytest.raises(SolverFailure, match="bound of 2 pivots"):
        lemke(M, q, max_pivots=2)


@pytest.mark.parametrize(
    ("M", "q"),
    [
        (np.eye(3), -np.ones(3)),
        (np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]]), -np.ones(3)),
        (np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]]), [-1.0, 0.0, -1.0]),
        (np.array([[2.0, 1.0, 1.0], [1.0, 2.0, 1.0], [1.0, 1.0, 2.0]]), [-1.0, -1.0, 0.0]),
    ],
)
def test_degenerate_ties_do_not_cycle(M, q):
    """Ties in every ratio test (equal q, zero q): the lexicographic rule ends on a solution."""
    q = np.asarray(q, dtype=float)
    result = lemke(M, q)
    assert_solves(M, q, result)
    assert any(np.allclose(result.z, z) for z in enumerate_solutions(M, q))


@pytest.mark.parametrize("seed", range(10))
def test_integer_degenerate_problems(seed):
    """Small integer P-matrices and q with many equal entries and zeros: heavy degeneracy."""
    rng = np.random.default_rng(50 + seed)
    n = int(rng.integers(2, 7))
    A = rng.integers(-2, 3, size=(n, n)).astype(float)
    M = A @ A.T + np.eye(n)
    q = rng.integers(-1, 1, size=n).astype(float)
    result = lemke(M, q)
    (expected,) = enumerate_solutions(M, q)
    np.testing.assert_allclose(result.z, expected, atol=1e-9)


def test_covering_vector_and_scale_do_not_change_the_solution():
    """Another covering vector, or M and q scaled by 1e-6 and 1e6, give the same solution."""
    rng = np.random.default_rng(11)
    M, q = nonsymmetric_p_matrix(rng, 6), rng.normal(size=6)
    reference = lemke(M, q).z
    np.testing.assert_allclose(lemke(M, q, covering=rng.uniform(0.5, 2, 6)).z, reference)
    np.testing.assert_allclose(lemke(1e-6 * M, 1e6 * q).z, 1e12 * reference, rtol=1e-9)


def test_deterministic():
    rng = np.random.default_rng(5)
    M, q = nonsymmetric_p_matrix(rng, 7), rng.normal(size=7)
    first, second = lemke(M, q), lemke(M, q)
    np.testing.assert_array_equal(first.z, second.z)
    assert first.pivots == second.pivots


@pytest.mark.parametrize(
    ("M", "q", "covering", "message"),
    [
        (np.eye(2), [1.0, 2.0, 3.0], None, "shape"),
        (np.eye(2), [1.0, np.nan], None, "non-finite"),
        (np.eye(2), [-1.0, 1.0], [1.0, 0.0], "must be > 0"),
    ],
)
def test_bad_input(M, q, covering, message):
    with pytest.raises(InvalidProblem, match=message):
        lemke(M, q, covering)
