"""Small impacts: closed forms, work done once per problem, and batches of problems.

An LCP of one or two contacts is solved in closed form instead of by the generic enumeration;
a problem is validated when built and keeps what it computed, so it can be resolved many times;
a batch carries the enumeration over every problem at once. Each gives the general path's
answer: the same numbers bit for bit where the formulas are the same, else to 1e-12.
"""

import dataclasses
import warnings

import numpy as np
import pytest

import lawbench
from lawbench import Contact, ImpactProblem, InvalidProblem
from lawbench.core.metric import KineticMetric
from lawbench.numerics.solvers import (
    QPResult,
    _enumerate_sets,
    _finish,
    clarabel_qp,
    enumerate_lcp,
    polish,
    solve_lcp,
)


def random_lcps(rng, count, m, decades=2.0):
    """Symmetric positive definite G and q of either sign, scaled over +-``decades``."""
    A = rng.normal(size=(count, m, m)) * 10.0 ** rng.uniform(-decades, decades, (count, 1, 1))
    G = A @ np.swapaxes(A, 1, 2) + 1e-3 * np.eye(m)
    q = rng.normal(size=(count, m)) * 10.0 ** rng.uniform(-decades, decades, (count, 1))
    return G, q


@pytest.mark.parametrize("m", [1, 2])
def test_the_closed_form_equals_the_enumeration_bit_for_bit(m):
    G, q = random_lcps(np.random.default_rng(m), 500, m)
    together, found = enumerate_lcp(G, q)
    assert found.all()
    for k in range(len(q)):
        alone = solve_lcp(G[k], q[k])
        generic, slack = _enumerate_sets(G[k], q[k])
        assert np.array_equal(alone.z, generic), k
        assert np.array_equal(alone.z, together[k]), k
        np.testing.assert_allclose(alone.w, slack, rtol=0, atol=1e-15 * np.abs(q[k]).max())
        assert alone.method == ("closed form" if m == 1 else "LCP (active-set enumeration)")


@pytest.mark.parametrize("m", [1, 2])
def test_the_closed_form_equals_clarabel_polished(m):
    """clarabel's interior point, refined on its active set, is exact to rounding too (on
    moderately scaled problems, where its absolute tolerances find the active set)."""
    G, q = random_lcps(np.random.default_rng(10 + m), 100, m, decades=0.5)
    for k in range(len(q)):
        approximate = clarabel_qp(G[k], q[k], np.eye(m), 1e-10).x
        exact = polish(G[k], q[k], np.maximum(approximate, 0.0))
        assert exact is not None
        z = solve_lcp(G[k], q[k]).z
        assert np.abs(z - exact).max() <= 1e-12 * max(np.abs(exact).max(), 1e-300), k


def test_a_singular_pair_of_contacts_falls_back_to_a_single_contact():
    """Two identical normals: the pair's equations are singular, one contact takes it all."""
    z, found = enumerate_lcp(np.ones((2, 2)), np.array([-1.0, -1.0]))
    assert found and np.array_equal(z, [1.0, 0.0])


def test_a_batch_with_full_mass_matrices_and_own_jacobians_equals_one_by_one():
    rng = np.random.default_rng(3)
    count, n, m = 200, 4, 2
    A = rng.normal(size=(count, n, n))
    M = A @ np.swapaxes(A, 1, 2) + np.eye(n)
    Wn = rng.normal(size=(count, n, m))
    v = rng.normal(size=(count, n))
    e = rng.uniform(0.0, 1.0, (count, m))
    batch = lawbench.ProblemBatch(M, Wn, v, {"e": e})
    together = lawbench.solve_batch("moreau", batch)
    moreau = lawbench.LAWS.get("moreau")
    for k in range(count):
        alone = moreau.resolve(batch.problem(k))
        assert np.abs(together.v_plus[k] - alone.v_plus).max() <= 1e-12 * np.abs(v[k]).max()
        assert together.T_plus[k] == pytest.approx(alone.T_plus, rel=1e-12)


@pytest.mark.parametrize(
    ("arrays", "coefficients", "message"),
    [
        ({"Wn": [[-1.0], [np.nan]]}, {}, r"Wn\[0, 1, 0\] = nan"),
        ({}, {"e": [[0.5], [np.nan]]}, r"problem 1: contacts\[0\]\.e = nan"),
        ({"M": np.diag([1.0, 1e-320])}, {}, "problem 0: M is too close to singular"),
    ],
)
def test_a_batch_names_the_bad_entry_of_a_shared_array(arrays, coefficients, message):
    fields = {"M": np.eye(2), "Wn": [[-1.0], [1.0]], "v": np.ones((2, 2))} | arrays
    with pytest.raises(InvalidProblem, match=message):
        lawbench.ProblemBatch(fields["M"], fields["Wn"], fields["v"], coefficients)


def test_a_prebuilt_problem_is_resolved_many_times_without_validation(monkeypatch):
    problem = lawbench.CASES.get("three_ball_chain").build(e=0.9)
    first = {name: lawbench.solve(name, problem) for name in ("moreau", "newton", "poisson")}

    def validated_again(*args, **kwargs):
        raise AssertionError("validated again")

    monkeypatch.setattr(KineticMetric, "__init__", validated_again)
    monkeypatch.setattr(ImpactProblem, "_check_normals", validated_again)
    monkeypatch.setattr(Contact, "validate", validated_again)
    for _ in range(3):
        for name, outcome in first.items():
            again = lawbench.solve(name, problem)
            assert np.array_equal(again.v_plus, outcome.v_plus)
            assert again.T_plus == outcome.T_plus


@pytest.mark.parametrize(
    ("coefficients", "message"),
    [({"e": 1.5}, r"contacts\[0\]\.e = 1\.5"), ({"e": [0.5, -0.5]}, r"contacts\[1\]\.e = -0\.5")],
)
def test_shared_and_per_contact_coefficients_are_validated_by_name(coefficients, message):
    chain = [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]]
    with pytest.raises(InvalidProblem, match=message):
        ImpactProblem.from_arrays(np.eye(3), chain, [1.0, 0.0, 0.0], **coefficients)


def test_a_small_diagonal_mass_is_inverted_exactly():
    M = np.diag([1e-3, 3.0, 7e3])
    problem = ImpactProblem.from_arrays(M, [[-1.0], [1.0], [0.0]], [1.0, 0.0, 0.0])
    rhs = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(problem.solve_mass(rhs), rhs / np.diag(M), rtol=1e-15)
    np.testing.assert_allclose(problem.delassus, [[1e3 + 1 / 3]], rtol=1e-15)
    with pytest.raises(InvalidProblem, match="M is too close to singular"):
        ImpactProblem.from_arrays(np.diag([1.0, 1e-320]), [[-1.0], [1.0]], [1.0, 0.0])


@pytest.mark.parametrize("seed", range(5))
def test_the_delassus_matrix_of_a_diagonal_mass_is_symmetric_as_computed(seed):
    """G = S.T S with S = M^-1/2 Wn is symmetric bit for bit and equals Wn.T M^-1 Wn."""
    rng = np.random.default_rng(seed)
    n, m = 6, 4
    M = np.diag(10.0 ** rng.uniform(-3.0, 3.0, n))
    Wn = rng.normal(size=(n, m))
    G = ImpactProblem.from_arrays(M, Wn, rng.normal(size=n)).delassus
    assert np.array_equal(G, G.T)
    np.testing.assert_allclose(G, Wn.T @ np.linalg.solve(M, Wn), rtol=1e-13)


def test_the_kinetic_energy_of_a_small_diagonal_mass_is_numpys_and_overflows_silently():
    """T = v.M v / 2 in Python floats equals numpy's to rounding; past the float range it is
    inf without a warning (a law's outcome is then refused by name, not with a warning)."""
    rng = np.random.default_rng(0)
    M = np.diag(10.0 ** rng.uniform(-3.0, 3.0, 5))
    problem = ImpactProblem.from_arrays(M, rng.normal(size=(5, 2)), rng.normal(size=5))
    v = rng.normal(size=5)
    assert problem.kinetic_energy(v) == pytest.approx(v @ M @ v / 2, rel=1e-15)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert problem.kinetic_energy(np.full(5, 1e200)) == np.inf


@pytest.mark.parametrize(
    "M", [[[0.0, 1.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, -1.0]], [[1.0, 0.0], [0.0, 0.0]]]
)
def test_a_mass_matrix_with_at_most_n_non_zero_entries_is_diagonal_or_refused(M):
    """A positive definite M has no zero on its diagonal, so n non-zero entries make it
    diagonal; any other M with n non-zero entries or fewer is refused, never read as one."""
    with pytest.raises(InvalidProblem, match="M is not positive definite"):
        ImpactProblem.from_arrays(np.array(M), [[-1.0], [1.0]], [1.0, 0.0])


def test_an_outcome_is_frozen_and_replaced_field_by_field():
    outcome = lawbench.solve("moreau", "three_ball_chain")
    with pytest.raises(dataclasses.FrozenInstanceError):
        outcome.status = "changed"
    changed = dataclasses.replace(outcome, status="ambiguous")
    assert changed.status == "ambiguous" and changed.T_plus == outcome.T_plus
    assert changed.diagnostics == outcome.diagnostics


def test_an_lcp_without_a_solution_is_never_polished_into_one():
    """Two closed contacts along opposite normals, one approaching (e = 1), the other
    separating: restituting the first asks the second to approach, and the LCP has no
    solution. clarabel certifies it (its QP is unbounded); its last iterate, impulses of
    1e15 whose slacks cancel to within their rounding, passed the polish as an answer with a
    contact left approaching, status ok."""
    problem = ImpactProblem.from_arrays(np.eye(2), [[1.0, -1.0], [1.0, -1.0]], [-1.0, 0.3], e=1.0)
    with pytest.raises(lawbench.SolverFailure, match="the LCP has no solution"):
        lawbench.solve("moreau", problem)
    q = problem.un + problem.un.clip(max=0.0)
    with pytest.raises(lawbench.SolverFailure, match="DualInfeasible"):
        solve_lcp(problem.delassus, q)


# Seven contacts (beyond the enumeration) along three directions of the plane of the first
# two coordinates, every one of them approaching; the third coordinate, which no contact
# moves, is STIFF times heavier.
REDUNDANT = np.array([[1, 0, 1, 0, 1, 1, 0], [0, 1, 0, 2, 1, 0, 1], [0, 0, 0, 0, 0, 0, 0]])


@pytest.mark.parametrize("stiff", [3e9, 1e12])
def test_a_stiff_coordinate_no_contact_moves_leaves_moreaus_answer_exact(stiff):
    """The plane's velocity (-1, -1) approaches every contact, so its projection on their cone
    is 0 and Moreau's law (e = 0.5) gives (0.5, 0.5), the third coordinate untouched. clarabel's
    velocity QP, whose tolerances are relative to the stiff coordinate's kinetic energy, ended
    'Solved' with multipliers that broke the LCP by a third of the approach: status ok, with
    (0.47, 0.04) at 3e9 and an energy gain at 1e12. An unpolished answer is now held to the
    LCP, and the law solves the Delassus LCP, which does not see the stiff coordinate."""
    problem = ImpactProblem.from_arrays(np.diag([1.0, 1.0, stiff]), REDUNDANT, [-1, -1, 1], e=0.5)
    try:
        outcome = lawbench.solve("moreau", problem)
    except lawbench.SolverFailure as failure:
        assert "break the LCP" in str(failure)
        return
    np.testing.assert_allclose(outcome.v_plus, [0.5, 0.5, 1.0], rtol=1e-5)


def test_a_solved_status_with_multipliers_that_break_the_lcp_fails():
    G, q = np.array([[1.0, 1.0], [1.0, 1.0]]), np.array([-1.0, -1.0])
    for z, holds in (([0.5, 0.5], True), ([0.2, 0.2], False), ([2.0, 0.0], False)):
        z = np.array(z)
        solved = QPResult(z, z, "Solved", 5)
        if holds:
            assert _finish(G, q, z, solved, False, 1e-10).z.tolist() == z.tolist()
        else:
            with pytest.raises(lawbench.SolverFailure, match="break the LCP"):
                _finish(G, q, z, solved, False, 1e-10)


def test_a_set_whose_slacks_are_rounding_is_no_solution_of_the_lcp():
    """Contacts 0 and 2 along n separate, contact 1 along -0.83 n approaches and is restituted:
    the three ask n.v+ to be both >= 0 and < 0, and the LCP has no solution. The enumeration
    took a near-singular active set whose impulses of 3e15 leave slacks that are only their
    rounding, and so did the polish of clarabel's answer: status ok, contact 0 approaching at
    0.16 m/s."""
    n, t = np.array([0.4776, -0.6055]), np.array([0.3, 0.7])
    Wn = np.column_stack([n, -0.83 * n, 0.37 * n, t])
    problem = ImpactProblem.from_arrays(np.eye(2), Wn, [0.8311, -0.2518], e=0.5)
    with pytest.raises(lawbench.SolverFailure, match=r"no solution|break the LCP"):
        lawbench.solve("moreau", problem)
    q = problem.un + 0.5 * problem.un.clip(max=0.0)
    assert not enumerate_lcp(problem.delassus, q)[1]
    assert not enumerate_lcp(problem.delassus, q[None])[1].any()
