"""Coulomb's frictional contact problem in contact space (FCLIB's local form), as given.

Source: Acary, Brémond and Huber (2018), "On solving contact problems with Coulomb friction:
formulations and numerical comparisons": u = W r + q, De Saxce's complementarity per contact,
and the FC3D error (the natural map over max(|q|, |r|, |u|)) that measures an answer.
"""

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse

import lawbench
from lawbench import ContactProblem, InvalidProblem
from lawbench.core.mechanics import fc3d_error

# One contact, by hand: W = diag(2, 1, 1), q = (-1, 3, 4), mu = 1/2 slips against (3, 4):
# r = (1/2, -(1/4) (3, 4) / 5), u = (0, 3 - 3/20, 4 - 4/20).
ISOTROPIC = (np.diag([2.0, 1.0, 1.0]), np.array([-1.0, 3.0, 4.0]), [0.5])


def test_one_slipping_contact_by_hand():
    problem = ContactProblem(*ISOTROPIC)
    solution = lawbench.LAWS["moreau"].solve_contact(problem, method="nsgs")
    np.testing.assert_allclose(solution.r, [0.5, -0.15, -0.2], rtol=0, atol=1e-14)
    np.testing.assert_allclose(solution.u, [0.0, 2.85, 3.8], rtol=0, atol=1e-14)
    assert solution.fc3d_error <= 1e-15
    assert problem.error(np.zeros(3)) > 0.1


def test_stored_zeros_are_dropped_and_change_nothing():
    """A writer that stores a dense W as sparse (Siconos' reformulation of its Spheres file
    keeps 1.14 million entries, 7165 of them non-zero) gives the same W without the zeros,
    and Gauss-Seidel the same impulses to the bit."""
    rng = np.random.default_rng(0)
    blocks = [rng.normal(size=(3, 3)) for _ in range(4)]
    W = scipy.linalg.block_diag(*[b @ b.T + np.eye(3) for b in blocks])
    q = rng.normal(size=12)
    q[0::3] = -1.0
    stored = scipy.sparse.csr_array(
        (W.ravel(), (np.repeat(np.arange(12), 12), np.tile(np.arange(12), 12))), shape=(12, 12)
    )
    assert stored.nnz == 144
    problem = ContactProblem(stored, q, [0.3] * 4)
    assert problem.W.nnz == np.count_nonzero(W) == 36
    moreau = lawbench.LAWS["moreau"]
    plain = moreau.solve_contact(ContactProblem(W, q, [0.3] * 4), method="nsgs")
    assert np.array_equal(moreau.solve_contact(problem, method="nsgs").r, plain.r)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"dim": 4}, "dim = 4, must be 2 or 3"),
        ({"q": [1.0, 2.0]}, "W is 3 x 3 and q holds 2 entries"),
        ({"mu": [-0.1]}, r"mu\[0\] = -0.1, must be >= 0"),
        ({"q": [np.nan, 0.0, 0.0]}, "q holds a number that is not finite"),
        ({"W": np.diag([0.0, 1.0, 1.0])}, r"W\[0, 0\] = 0: contact 0's normal impulse"),
        ({"W": [["a"] * 3] * 3}, "W is not a numeric matrix"),
        ({"mu": []}, "mu is empty"),
    ],
)
def test_a_bad_field_is_refused_by_name(change, message):
    fields = dict(zip(("W", "q", "mu"), ISOTROPIC, strict=True)) | change
    with pytest.raises(InvalidProblem, match=message):
        ContactProblem(**fields)


def test_a_contact_problem_is_not_an_impact_problem():
    """The two entry points each name the type they take."""
    moreau = lawbench.LAWS["moreau"]
    with pytest.raises(TypeError, match="must be an ImpactProblem, not ContactProblem"):
        moreau.resolve(ContactProblem(*ISOTROPIC))
    with pytest.raises(TypeError, match="must be a ContactProblem, not ImpactProblem"):
        moreau.solve_contact(lawbench.CASES["sphere_wall"].build())


def test_a_fixed_point_that_settles_above_tol_fails_saying_where():
    """In contact space the FC3D error is the measure: a fixed point whose shift no longer
    changes but whose answer misses tol on W is a failure, never an answer. Frictionless, the
    shift is zero from the start, so one cone QP settles it at rounding, above tol = 1e-300."""
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 6))
    problem = ContactProblem(A @ A.T + np.eye(6), [-1.0, 0.2, 0.1, -0.5, 0.0, 0.3], [0.0, 0.0])
    moreau = lawbench.LAWS["moreau"]
    assert moreau.solve_contact(problem).fc3d_error <= 1e-10
    with pytest.raises(lawbench.SolverFailure, match=r"settled after 1 cone QPs at FC3D error"):
        moreau.solve_contact(problem, tol=1e-300)


def test_the_fc3d_error_is_free_of_units_and_counts_every_approach():
    """Impulses of 1e100 against a W of 1e-100 are measured like impulses of 1 against a W of
    1, and velocities in any unit alike: an answer leaving the contact approaching at half its
    speed is as wrong in every unit. At mu = 1e6 the dual cone is so narrow that the natural
    map sees an approach of 1 as a shift of 1e-6; the approach itself is counted."""
    W, q, mu = np.eye(3), np.array([-1.0, 0.0, 0.0]), np.array([0.3])
    half = np.array([0.5, 0.0, 0.0])
    base = fc3d_error(W, q, mu, half)
    assert base > 0.3
    for s in (1e-100, 1e100):
        assert fc3d_error(W / s, q, mu, half * s) == pytest.approx(base, rel=1e-12)
        assert fc3d_error(W * s, q * s, mu, half) == pytest.approx(base, rel=1e-12)
    sliding = np.array([-1.0, 1.0, 0.0])
    assert fc3d_error(W, sliding, np.array([1e6]), np.zeros(3)) > 0.5


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("method", ["auto", "nsgs", "fixed_point"])
def test_a_rank_one_delassus_matrix_leaving_contacts_approaching_is_refused(seed, method):
    """W = 1e-100 b b.T over three contacts with mu = 1e6: one impulse direction cannot stop
    three approaching contacts, and the answers the sweeps stopped at (impulses of 1e100,
    contacts approaching at their full speed) had an FC3D error of 1e-19 and less, relative to
    impulses in other units than the velocities. They are refused."""
    rng = np.random.default_rng(seed)
    b, q = rng.normal(size=9), rng.normal(size=9)
    q[0::3] = -np.abs(q[0::3]) - 0.5
    problem = ContactProblem(1e-100 * np.outer(b, b), q, np.full(3, 1e6))
    with pytest.raises(lawbench.SolverFailure):
        lawbench.LAWS["moreau"].solve_contact(problem, method=method, max_steps=50)
