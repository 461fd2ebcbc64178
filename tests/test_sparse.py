"""Problems given with scipy.sparse matrices: the same answers as dense ones, checked fields."""

import numpy as np
import pytest
import scipy.sparse

import lawbench
from lawbench import Contact, ImpactProblem, InvalidProblem
from lawbench.cases._chains import SPARSE_CONTACTS
from lawbench.core.metric import SMALL
from lawbench.files.problem_files import load_problem, save_problem
from lawbench.numerics.active_sets import _solve_block


def random_chain(seed, sparse, banded=False):
    """A free or walled chain of 100 to 400 balls, random masses, speeds, e and gaps.

    ``banded`` couples neighbouring coordinates in M (a tridiagonal, diagonally dominant M).
    """
    rng = np.random.default_rng(seed)
    n = int(rng.integers(100, 400))
    masses = 10.0 ** rng.uniform(-1.0, 1.0, n)
    rows, columns = np.arange(n - 1), np.arange(n - 1)
    Wn = scipy.sparse.csc_array(
        (np.r_[-np.ones(n - 1), np.ones(n - 1)], (np.r_[rows, rows + 1], np.r_[columns, columns])),
        shape=(n, n - 1),
    )
    M = scipy.sparse.diags_array(masses)
    if banded:
        coupling = 0.2 * np.minimum(masses[:-1], masses[1:])
        M = scipy.sparse.diags_array([coupling, masses, coupling], offsets=[-1, 0, 1])
    e = rng.uniform(0.0, 1.0, n - 1) if seed % 2 else 0.7
    gaps = np.where(rng.uniform(size=n - 1) < 0.1, 1e-3, 0.0)
    v = rng.normal(size=n)
    if not sparse:
        M, Wn = M.toarray(), Wn.toarray()
    return ImpactProblem.from_arrays(M, Wn, v, gaps=gaps, e=e)


def assert_same(a, b):
    for field in ("v_plus", "Pn", "T_plus"):
        x, y = getattr(a, field), getattr(b, field)
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * max(1.0, np.abs(x).max()))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("banded", [False, True], ids=["diagonal M", "banded M"])
def test_sparse_and_dense_chains_give_the_same_outcome(seed, banded):
    sparse, dense = random_chain(seed, True, banded), random_chain(seed, False, banded)
    assert sparse.sparse and not dense.sparse
    np.testing.assert_allclose(
        sparse.delassus.toarray(), dense.delassus, rtol=0, atol=1e-12 * abs(dense.delassus).max()
    )
    moreau = lawbench.LAWS.get("moreau")
    for separating in ("unilateral", "restitution"):
        assert_same(
            moreau.resolve(sparse, separating=separating),
            moreau.resolve(dense, separating=separating),
        )


@pytest.mark.parametrize("law", ["newton", "poisson"])
def test_other_laws_receive_the_dense_view_of_a_sparse_problem(law):
    sparse, dense = random_chain(1, True), random_chain(1, False)
    resolve = lawbench.LAWS.get(law).resolve
    assert_same(resolve(sparse), resolve(dense))


def test_a_small_sparse_problem_is_kept_dense():
    M = scipy.sparse.diags_array([1.0, 2.0, 3.0])
    Wn = scipy.sparse.csc_array(np.array([[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]]))
    problem = ImpactProblem(M, Wn, np.array([1.0, 0.0, 0.0]), [Contact(), Contact()])
    assert problem.n <= SMALL and not problem.sparse
    assert isinstance(problem.M, np.ndarray) and isinstance(problem.Wn, np.ndarray)


def test_given_sparse_arrays_are_left_writeable():
    chain = random_chain(0, True)
    M, Wn = scipy.sparse.csc_array(chain.M.toarray()), scipy.sparse.csc_array(chain.Wn.toarray())
    ImpactProblem(M, Wn, chain.v, chain.contacts)
    assert M.data.flags.writeable and Wn.data.flags.writeable


def sparse_fields():
    """The fields of the sparse chain of seed 0, its matrices as scipy.sparse arrays."""
    chain = random_chain(0, True)
    return {"M": chain.M, "Wn": chain.Wn, "v": chain.v, "contacts": chain.contacts}


def with_entry(matrix, row, column, value):
    matrix = scipy.sparse.lil_array(matrix)
    matrix[row, column] = value
    return matrix.tocsc()


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (
            lambda c: {"M": with_entry(c["M"], 3, 4, np.nan)},
            r"M\[3, 4\] is not a number: must be finite",
        ),
        (lambda c: {"Wn": with_entry(c["Wn"], 7, 2, np.inf)}, r"Wn\[7, 2\] is infinite"),
        (lambda c: {"M": with_entry(c["M"], 3, 4, 0.5)}, "M is not symmetric"),
        (lambda c: {"M": with_entry(c["M"], 5, 5, -1.0)}, "M is not positive definite"),
        (
            lambda c: {"M": c["M"] + with_entry(with_entry(c["M"] * 0, 0, 1, 9.0), 1, 0, 9.0)},
            "M is not positive definite",
        ),
        (lambda c: {"Wn": c["Wn"][:, :-1]}, r"Wn has shape \(\d+, \d+\), expected"),
        (lambda c: {"M": c["M"][:-1, :-1]}, r"M has shape"),
        (lambda c: {"Wn": with_entry(with_entry(c["Wn"], 4, 4, 0.0), 5, 4, 0.0)}, r"contacts\[4\]"),
    ],
    ids=["nan", "inf", "asymmetric", "negative mass", "indefinite", "Wn shape", "M shape", "null"],
)
def test_bad_sparse_fields_are_refused_by_name(make, message):
    fields = sparse_fields()
    fields |= make(fields)
    with pytest.raises(InvalidProblem, match=message):
        ImpactProblem(**fields)


@pytest.mark.parametrize("suffix", [".npz", ".h5"])
def test_a_sparse_problem_is_read_back_sparse(suffix, tmp_path):
    if suffix == ".h5":
        pytest.importorskip("h5py")
    problem = random_chain(2, True)
    loaded = load_problem(save_problem(problem, tmp_path / f"chain{suffix}"))
    assert loaded.sparse
    for name in ("M", "Wn"):
        assert abs(getattr(loaded, name) - getattr(problem, name)).max() == 0.0
    moreau = lawbench.LAWS.get("moreau")
    assert_same(moreau.resolve(loaded), moreau.resolve(problem))


def test_a_ten_thousand_ball_chain_solves_sparse():
    """Moreau at e = 0 on a long chain: every ball leaves with the centre of mass velocity."""
    rng = np.random.default_rng(4)
    n = 10_000
    masses = 10.0 ** rng.uniform(-1.0, 1.0, n)
    velocities = np.sort(rng.uniform(0.0, 1.0, n))[::-1]
    scene = lawbench.CASES.get("ball_chain")
    problem = scene.build(n=n, masses=masses.tolist(), velocities=velocities.tolist(), e=[0.0])
    assert problem.sparse and problem.m > SPARSE_CONTACTS
    outcome = lawbench.LAWS.get("moreau").resolve(problem)
    assert outcome.diagnostics["polished"]
    np.testing.assert_allclose(outcome.v_plus, masses @ velocities / masses.sum(), atol=1e-10)


def block_of(pattern, n=200):
    """A symmetric, diagonally dominant block (COO) of ``pattern``, and its dense copy.

    ``split entries`` lists each diagonal entry of a tridiagonal block in two halves.
    """
    rng = np.random.default_rng(len(pattern))
    width = {"tridiagonal": 1, "pentadiagonal": 2, "arrow": 1, "split entries": 1}[pattern]
    dense = np.zeros((n, n))
    for offset in range(1, width + 1):
        coupling = rng.uniform(-1.0, 1.0, n - offset)
        dense += np.diag(coupling, offset) + np.diag(coupling, -offset)
    if pattern == "arrow":
        dense[0, 1:] = dense[1:, 0] = rng.uniform(-1.0, 1.0, n - 1) / n
    dense += np.diag(4.0 * width + 10.0 ** rng.uniform(-1.0, 1.0, n))
    if pattern != "split entries":
        return scipy.sparse.coo_array(dense), dense
    half, diagonal = np.diag(dense) / 2, np.arange(n)
    block = scipy.sparse.coo_array(dense - np.diag(half))
    block = scipy.sparse.coo_array(
        (np.r_[block.data, half], (np.r_[block.row, diagonal], np.r_[block.col, diagonal])),
        shape=(n, n),
    )
    return block, dense


@pytest.mark.parametrize("pattern", ["tridiagonal", "pentadiagonal", "arrow", "split entries"])
def test_a_sparse_block_of_the_polish_is_solved_as_a_dense_one(pattern):
    """Banded blocks by banded Cholesky, the others by sparse LU: a dense solve's answer."""
    block, dense = block_of(pattern)
    rhs = np.random.default_rng(1).normal(size=len(dense))
    expected = np.linalg.solve(dense, rhs)
    for given in (block, dense):
        solution = _solve_block(given, rhs)
        np.testing.assert_allclose(solution, expected, rtol=0, atol=1e-13 * np.abs(expected).max())


def test_a_dense_law_refuses_a_problem_too_large_to_hold_dense():
    """The 100000-ball chain is built sparse (its range allows it); a law that works on dense
    matrices refuses it naming the size, rather than allocating 75 GiB."""
    problem = lawbench.CASES.get("ball_chain").build(n=100_000)
    with pytest.raises(lawbench.NotApplicable, match=r"74\.5 GiB dense"):
        lawbench.solve("newton", problem)
