"""The exact solution of an LCP on an active set: the polish of an approximate answer.

``0 <= G z + q _|_ z >= 0`` with ``G`` symmetric positive semidefinite (a Delassus matrix). An
interior point's answer carries its tolerance; the active set it shows is solved exactly
(`polish`) and kept when the equations' solution satisfies every condition to rounding. Where
that set is wrong, block principal pivoting moves contacts across until one holds; where it is
singular (redundant contacts), its independent contacts are solved. Every condition is judged in
units of velocity, contact by contact, so that impulses of 1e9 on heavy bodies hide no wrong
sign of an impulse of 1 on a light one.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from lawbench.core.metric import SPARSE_SHARE, is_sparse

ROUNDING = 1e-12
# Blocks larger than this with at most SPARSE_SHARE non-zero entries are solved as sparse.
SPARSE_SIZE = 64
# Largest rounding of the slacks w = G z + q, eps max_i sum_j |G_ij z_j|, over the velocities
# max |q|, of an active set's solution: beyond it the slacks are rounding, not velocities. An
# LCP without a solution (opposite normals, one contact restituted) has on a near-singular set
# impulses of 1e16 whose slacks cancel to anything, and the set passed for its solution.
CANCELLING = 1e-5
EPS = float(np.finfo(float).eps)
# Relative pivot of a pivoted QR below which a contact's column depends on the others.
DEPENDENT = 1e3 * EPS
# Principal pivoting (`_pivoted`): contacts up to which a polish that finds no set tries it,
# its steps per contact, and the steps without progress before it moves one contact at a time.
PIVOTED_MAX, PIVOTS_PER_CONTACT, STALLS = 200, 3, 3


def polish(G: np.ndarray, q: np.ndarray, z: np.ndarray) -> np.ndarray | None:
    """Solve the active set of an approximate LCP solution exactly.

    Candidate active sets: where ``z`` exceeds the slack ``w``, then where ``z`` is not
    negligible against its largest entry (badly scaled problems, masses over many decades,
    leave both ``z`` and ``w`` small). Returns the exact solution on the first set that is
    complementary to rounding, else principal pivoting from where the impulse gives its
    contact more velocity than its slack (`_pivoted`); None when that fails too.
    """
    w = G @ z + q
    for active in (z > w, z > 1e-6 * z.max()):
        exact = _on_active_set(G, q, active)
        if exact is not None:
            return exact
    if is_sparse(G) or len(q) > PIVOTED_MAX:
        return None
    return _pivoted(G, q, np.asarray(G.diagonal()) * z > w)


def _pivoted(G: np.ndarray, q: np.ndarray, active: np.ndarray) -> np.ndarray | None:
    """The LCP's solution by block principal pivoting from the set ``active``, or None.

    Júdice and Pires (1994): solve the set's equations (its independent contacts where it is
    singular), then move every contact that breaks a sign, an active impulse that pulls or an
    inactive slack that approaches, to the other side; after `STALLS` steps without fewer
    such contacts, only the last one (Murty's rule, which ends on a P-matrix). An interior
    point's answer leaves the active set of light bodies beside bodies 1e9 times heavier
    unresolved: its objective, their energy, is all the heavy ones'.
    """
    fewest, stalls = len(q) + 1, 0
    for _ in range(PIVOTS_PER_CONTACT * len(q)):
        try:
            z = _on_independent(G, q, np.flatnonzero(active))
        except (np.linalg.LinAlgError, ValueError):
            return None
        w = G @ z + q
        allowed = 1e-10 * max(float(np.abs(q).max()), ROUNDING) + ROUNDING * (abs(G) @ np.abs(z))
        wrong = (active & (np.asarray(G.diagonal()) * z < -allowed)) | (~active & (w < -allowed))
        if not wrong.any():
            return _on_active_set(G, q, active)
        count = int(wrong.sum())
        fewest, stalls = (count, 0) if count < fewest else (fewest, stalls + 1)
        if stalls > STALLS:
            last = int(np.flatnonzero(wrong)[-1])
            wrong = np.zeros_like(wrong)
            wrong[last] = True
        active = active ^ wrong
    return None


def _on_independent(G: np.ndarray, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Impulses zeroing the slacks of the independent contacts of ``rows``, the others at 0."""
    z = np.zeros_like(q)
    if rows.size:
        keep = rows[_independent(G[np.ix_(rows, rows)])]
        z[keep] = _solve_block(G[np.ix_(keep, keep)], -q[keep])
    return z


def _on_active_set(G: np.ndarray, q: np.ndarray, active: np.ndarray) -> np.ndarray | None:
    """The solution of the ``active`` contacts' equations, or None where it breaks the LCP.

    A singular block (redundant contacts: a contact given twice, more normals than the bodies
    have coordinates) has a solution only where its right-hand side lies in its range, and
    then many. When its factorization fails or gives impulses that break the LCP, the
    equations of its independent contacts (`_independent`) are solved, the others' impulses
    left at zero: the slacks of every contact then say whether the set holds. Least squares
    would do it, but only to ``eps |G| |z|`` in the norm of all the slacks, which impulses of
    1e9 make 1e-6: beyond the slack of a light contact beside them.
    """
    rows = np.flatnonzero(active)
    if not rows.size:
        return _checked(G, q, np.zeros_like(q))
    block = G if rows.size == len(q) else G[np.ix_(rows, rows)]
    found = _solved(G, q, block, rows)
    if found is None and not is_sparse(block):
        keep = _independent(block)
        if keep.size < rows.size:
            found = _solved(G, q, block[np.ix_(keep, keep)], rows[keep])
    return found


def _solved(G: np.ndarray, q: np.ndarray, block: np.ndarray, rows: np.ndarray) -> np.ndarray | None:
    """The impulses of ``rows`` that zero their slacks (``block`` their equations), checked."""
    exact = np.zeros_like(q)
    try:
        exact[rows] = _solve_block(block, -q[rows])
    except (np.linalg.LinAlgError, ValueError):
        return None
    return _checked(G, q, exact)


def _independent(block: np.ndarray) -> np.ndarray:
    """The positions of a largest set of independent columns of ``block``, in order.

    By QR with column pivoting: a column whose pivot is below `DEPENDENT` of the first is a
    combination of those before it (a contact given twice leaves a pivot of 1e-17; masses of
    1 and 1e9 a genuine one of 1e-11).
    """
    _, R, order = scipy.linalg.qr(block, mode="economic", pivoting=True)
    pivots = np.abs(np.diagonal(R))
    rank = int(np.count_nonzero(pivots > DEPENDENT * pivots[0]))
    return np.sort(order[:rank])


def _checked(G: np.ndarray, q: np.ndarray, exact: np.ndarray) -> np.ndarray | None:
    """``exact`` when it solves the LCP to rounding, else None.

    A negative impulse counts by the velocity it gives its own contact, ``G_jj z_j``, like a
    negative slack: impulses of 1e9 elsewhere make no pull of 1e-2 on a light ball rounding.
    """
    slack = G @ exact + q
    velocity_scale = max(np.abs(q).max(), ROUNDING)
    # A slack is a sum of terms G_ij z_j that cancel down to the size of q: their rounding too,
    # unless it is all the slack holds (`CANCELLING`).
    reach = abs(G) @ np.abs(exact)
    allowed = 1e-10 * velocity_scale + ROUNDING * reach
    pulls = np.asarray(G.diagonal()) * exact
    if (pulls < -allowed).any() or (slack < -allowed).any():
        return None
    if EPS * float(reach.max()) > CANCELLING * velocity_scale:
        return None
    return np.maximum(exact, 0.0)


def _solve_block(block: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve a symmetric positive (semi)definite block of a Delassus matrix.

    When it is sparse, or large with few non-zero entries: by banded Cholesky when its band
    holds no more entries than its non-zero ones (chains: each contact shares a body with its
    neighbours only, so the block is tridiagonal), else, or when it is only semidefinite, by
    sparse LU. A dense solve otherwise.

    An ill-conditioned block (redundant contacts) is fine: the caller checks the answer.
    """
    if is_sparse(block) or (
        block.shape[0] > SPARSE_SIZE and np.count_nonzero(block) <= SPARSE_SHARE * block.size
    ):
        band = _lower_band(block)
        if band is not None:
            try:
                return scipy.linalg.solveh_banded(band, rhs, lower=True)
            except np.linalg.LinAlgError:  # not positive definite: sparse LU decides
                pass
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", scipy.sparse.linalg.MatrixRankWarning)
            solution = scipy.sparse.linalg.spsolve(scipy.sparse.csc_matrix(block), rhs)
        if not np.isfinite(solution).all():
            raise np.linalg.LinAlgError("singular block")
        return solution
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
        return scipy.linalg.solve(block, rhs, assume_a="pos")


def _lower_band(block: np.ndarray) -> np.ndarray | None:
    """The lower band of a symmetric block in LAPACK's storage (``band[i - j, j] = block[i, j]``).

    None when the band would hold more entries than the block's non-zero ones: the block is not
    banded, and its band is no cheaper than a sparse factor.
    """
    entries = scipy.sparse.coo_array(block)
    offset = entries.row - entries.col
    width = int(offset.max(initial=0))
    if (width + 1) * block.shape[0] > entries.nnz:
        return None
    lower = offset >= 0
    band = np.zeros((width + 1, block.shape[0]))
    # Added, not assigned: a sparse block may list an entry in several parts.
    np.add.at(band, (offset[lower], entries.col[lower]), entries.data[lower])
    return band
