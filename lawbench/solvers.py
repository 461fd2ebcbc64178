"""Complementarity solvers shared by the laws.

The frictionless laws reduce to linear complementarity problems with a symmetric positive
(semi)definite matrix, ``w = G z + q``, ``0 <= w _|_ z >= 0``: the optimality conditions of the
convex QP ``min z.G z / 2 + q.z`` over ``z >= 0``. Decoupled problems (diagonal G) are solved in
closed form. The others either with clarabel, called directly with sparse matrices, then
polished (the active set clarabel finds is solved exactly and kept when it satisfies the
conditions to rounding, so the answer does not carry the interior-point tolerance); or as the
non-negative least-squares problem ``min |R z + R^-T q|`` with ``G = R.T R``, whose active-set
method (Lawson and Hanson) is finite and exact.

A problem of a few contacts (at most `ENUMERATION_MAX`) is solved exactly by enumerating its
active sets (`enumerate_lcp`): each set's equations are one small linear solve, and numpy does
them for a whole batch of problems at once, which is what makes many small impacts cheap.
"""

from __future__ import annotations

import functools
import itertools
import math
import warnings
from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse
import scipy.sparse.linalg

from lawbench.errors import SolverFailure
from lawbench.mechanics import is_diagonal
from lawbench.problem import SPARSE_SHARE, as_array, is_sparse

ROUNDING = 1e-12
# Contacts up to which active-set enumeration (2**m sets) is the exact, cheap method.
ENUMERATION_MAX = 6
# Blocks larger than this with at most SPARSE_SHARE non-zero entries are solved as sparse.
SPARSE_SIZE = 64
# Relative violation of z >= 0 and w >= 0 accepted as rounding.
COMPLEMENTARITY = 1e-10


@dataclass(frozen=True)
class QPResult:
    """Primal ``x`` and the multipliers ``y >= 0`` of the inequality rows, with solver facts."""

    x: np.ndarray
    y: np.ndarray
    status: str
    iterations: int


def clarabel_settings(tol: float, max_iter: int) -> clarabel.DefaultSettings:
    """Settings of clarabel: quiet, with gap and feasibility tolerances ``tol``."""
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = max_iter
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tol
    settings.tol_ktratio = max(tol, 1e-12)
    return settings


def clarabel_qp(
    P: np.ndarray, c: np.ndarray, A: np.ndarray, tol: float, max_iter: int = 200
) -> QPResult:
    """Solve ``min x.P x / 2 + c.x`` subject to ``A x >= 0`` with clarabel.

    ``P`` and ``A`` are numpy or scipy.sparse arrays; sparse ones reach clarabel as they are.
    Returns whatever clarabel ended with; the caller decides whether its status will do.
    """
    if is_sparse(P):
        upper, constraints = scipy.sparse.triu(P, format="csc"), (-A).tocsc()
    else:
        upper, constraints = scipy.sparse.csc_matrix(np.triu(P)), scipy.sparse.csc_matrix(-A)
    solver = clarabel.DefaultSolver(
        upper,
        np.asarray(c, dtype=float),
        constraints,
        np.zeros(A.shape[0]),
        [clarabel.NonnegativeConeT(A.shape[0])],
        clarabel_settings(tol, max_iter),
    )
    solution = solver.solve()
    return QPResult(
        np.array(solution.x), np.array(solution.z), str(solution.status), solution.iterations
    )


@dataclass(frozen=True)
class LCPResult:
    """Solution ``z`` of an LCP, ``w = G z + q``, and how it was found."""

    z: np.ndarray
    w: np.ndarray
    method: str
    solver_status: str | None = None
    iterations: int = 0
    polished: bool = False


def polish(G: np.ndarray, q: np.ndarray, z: np.ndarray) -> np.ndarray | None:
    """Solve the active set of an approximate LCP solution exactly.

    Candidate active sets: where ``z`` exceeds the slack ``w``, then where ``z`` is not
    negligible against its largest entry (badly scaled problems, masses over many decades,
    leave both ``z`` and ``w`` small). Returns the exact solution on the first set that is
    complementary to rounding, else None.
    """
    w = G @ z + q
    for active in (z > w, z > 1e-6 * z.max()):
        exact = _on_active_set(G, q, active)
        if exact is not None:
            return exact
    return None


def _on_active_set(G: np.ndarray, q: np.ndarray, active: np.ndarray) -> np.ndarray | None:
    exact = np.zeros_like(q)
    if active.any():
        rows = np.flatnonzero(active)
        try:
            exact[active] = _solve_block(G[np.ix_(rows, rows)], -q[active])
        except (np.linalg.LinAlgError, ValueError):
            return None
    slack = G @ exact + q
    velocity_scale = max(np.abs(q).max(), ROUNDING)
    impulse_scale = max(np.abs(exact).max(), ROUNDING)
    # A slack is a sum of terms G_ij z_j that cancel down to the size of q: their rounding too.
    rounding = ROUNDING * (abs(G) @ np.abs(exact))
    if exact.min() < -1e-10 * impulse_scale or (slack < -1e-10 * velocity_scale - rounding).any():
        return None
    return np.maximum(exact, 0.0)


def _solve_block(block: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve a symmetric positive (semi)definite block of a Delassus matrix.

    Sparse LU when it is sparse, or large with few non-zero entries (the banded blocks of
    chains), a dense solve otherwise.

    An ill-conditioned block (redundant contacts) is fine: the caller checks the answer.
    """
    if is_sparse(block) or (
        block.shape[0] > SPARSE_SIZE and np.count_nonzero(block) <= SPARSE_SHARE * block.size
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", scipy.sparse.linalg.MatrixRankWarning)
            solution = scipy.sparse.linalg.spsolve(scipy.sparse.csc_matrix(block), rhs)
        if not np.isfinite(solution).all():
            raise np.linalg.LinAlgError("singular block")
        return solution
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
        return scipy.linalg.solve(block, rhs, assume_a="pos")


@functools.cache
def _active_sets(m: int) -> tuple[np.ndarray, ...]:
    """Every subset of m contacts as index arrays, smallest first, then in lexicographic order."""
    return tuple(
        np.array(subset, dtype=int)
        for size in range(m + 1)
        for subset in itertools.combinations(range(m), size)
    )


def _solve_blocks(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve the stacked systems ``A[k] x[k] = b[k]``.

    Blocks of one and two rows by their closed forms (a singular one gives non-finite numbers,
    which the caller rejects); larger ones by LU, or their least-norm solution when singular.
    """
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        if A.shape[-1] == 1:
            return b / A[..., 0]
        if A.shape[-1] == 2:
            a, c, d = A[..., 0, 0], A[..., 0, 1], A[..., 1, 1]
            det = a * d - c * A[..., 1, 0]
            return (
                np.stack([(d * b[..., 0] - c * b[..., 1]), (a * b[..., 1] - c * b[..., 0])], -1)
                / det[..., None]
            )
        try:
            return np.linalg.solve(A, b[..., None])[..., 0]
        except np.linalg.LinAlgError:
            return (np.linalg.pinv(A) @ b[..., None])[..., 0]


def enumerate_lcp(G: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``0 <= G z + q _|_ z >= 0`` by enumerating active sets, for a batch of problems.

    Parameters
    ----------
    G : array (..., m, m)
        Symmetric positive (semi)definite matrices; one matrix serves every problem.
    q : array (..., m)
        Constant terms, one row per problem.

    Returns
    -------
    z : array (..., m)
        The solution on the first active set (smallest, then lexicographic) whose equations
        give ``z >= 0`` and ``w >= 0`` to rounding; zeros where no set does.
    found : array (...) of bool
        Where a set was found. For a positive definite ``G`` the LCP has exactly one solution,
        so a problem without one is numerically singular and the caller solves it otherwise.
    """
    q = np.asarray(q, dtype=float)
    if q.ndim == 1 and np.ndim(G) == 2:
        return _enumerate_one(np.asarray(G, dtype=float), q)
    batch, m = q.shape[:-1], q.shape[-1]
    qs = q.reshape(-1, m)
    Gs = np.broadcast_to(np.asarray(G, dtype=float), (*batch, m, m)).reshape(-1, m, m)
    z = np.zeros_like(qs)
    found = np.zeros(len(qs), dtype=bool)
    velocity_scale = np.maximum(np.abs(qs).max(axis=1, initial=0.0), ROUNDING)
    for active in _active_sets(m):
        if found.all():
            break
        candidate = np.zeros_like(qs)
        if active.size:
            block = Gs[:, active[:, None], active]
            candidate[:, active] = _solve_blocks(block, -qs[:, active])
        with np.errstate(all="ignore"):
            slack = np.einsum("kij,kj->ki", Gs, candidate) + qs
            impulse_scale = np.maximum(np.abs(candidate).max(axis=1), ROUNDING)
            good = (
                ~found
                & np.isfinite(candidate).all(axis=1)
                & (candidate.min(axis=1) >= -COMPLEMENTARITY * impulse_scale)
                & (slack.min(axis=1) >= -COMPLEMENTARITY * velocity_scale)
            )
        z[good] = np.maximum(candidate[good], 0.0)
        found |= good
    return z.reshape(*batch, m), found.reshape(batch)


def _enumerate_one(G: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`enumerate_lcp` for one problem, in Python floats: the same sets, formulas and tests.

    One problem of a few contacts is dominated by the cost of calling numpy, so the blocks of
    one and two rows are solved with the same closed forms in plain arithmetic (identical in
    IEEE double), and only larger blocks go through LU.
    """
    m = len(q)
    rows, rhs = G.tolist(), q.tolist()
    velocity_scale = max(max(abs(x) for x in rhs), ROUNDING)
    for active in _active_sets(m):
        candidate = [0.0] * m
        if len(active) == 1:
            (i,) = active
            candidate[i] = -rhs[i] / rows[i][i] if rows[i][i] else math.inf
        elif len(active) == 2:
            i, j = active
            a, c, d, c2 = rows[i][i], rows[i][j], rows[j][j], rows[j][i]
            det = a * d - c * c2
            if det == 0.0:
                continue
            candidate[i] = (d * -rhs[i] - c * -rhs[j]) / det
            candidate[j] = (a * -rhs[j] - c * -rhs[i]) / det
        elif len(active) > 2:
            solved = _solve_blocks(G[np.ix_(active, active)][None], -q[active][None])[0]
            for i, x in zip(active.tolist(), solved.tolist(), strict=True):
                candidate[i] = x
        if not all(math.isfinite(x) for x in candidate):
            continue
        impulse_scale = max(max(abs(x) for x in candidate), ROUNDING)
        if min(candidate) < -COMPLEMENTARITY * impulse_scale:
            continue
        slack = [
            sum(g * x for g, x in zip(row, candidate, strict=True)) + b
            for row, b in zip(rows, rhs, strict=True)
        ]
        if min(slack) >= -COMPLEMENTARITY * velocity_scale:
            return np.maximum(np.array(candidate), 0.0), np.array(True)
    return np.zeros(m), np.array(False)


def solve_lcp(
    G: np.ndarray, q: np.ndarray, tol: float = 1e-10, refine: bool = True, method: str = "clarabel"
) -> LCPResult:
    """Solve ``0 <= G z + q _|_ z >= 0`` for a symmetric positive semidefinite ``G``.

    Parameters
    ----------
    G : array or scipy.sparse array (m, m)
        Symmetric positive semidefinite matrix.
    q : array (m,)
        Constant term.
    tol : float
        clarabel's tolerances (gap and feasibility).
    refine : bool
        Whether to polish clarabel's answer on its active set.
    method : {'clarabel', 'nnls'}
        The solver of coupled problems beyond `ENUMERATION_MAX` contacts (or where the
        enumeration finds no set, a numerically singular problem).
    """
    if is_diagonal(G):
        diagonal = G.diagonal()
        if (diagonal <= 0).any():
            raise SolverFailure("the LCP matrix has a zero diagonal entry")
        z = np.maximum(-q / diagonal, 0.0)
        method = "closed form" if len(q) == 1 else "decoupled (diagonal Delassus)"
        return LCPResult(z, G @ z + q, method)
    if len(q) <= ENUMERATION_MAX:
        z, found = enumerate_lcp(as_array(G), q)
        if found:
            return LCPResult(z, G @ z + q, "LCP (active-set enumeration)")
    if method == "nnls":
        return _nnls_lcp(as_array(G), q)
    identity = scipy.sparse.identity(len(q), format="csc") if is_sparse(G) else np.eye(len(q))
    result = clarabel_qp(G, q, identity, tol)
    return _finish(G, q, result.x, result, refine)


def _nnls_lcp(G: np.ndarray, q: np.ndarray) -> LCPResult:
    """The LCP as non-negative least squares, through a square root ``R`` of ``G``."""
    values, vectors = np.linalg.eigh(G)
    keep = values > 1e-13 * values.max()
    root = np.sqrt(values[keep])
    R = root[:, None] * vectors[:, keep].T
    target = -(vectors[:, keep].T @ q) / root
    try:
        z, _ = scipy.optimize.nnls(R, target, maxiter=50 * len(q))
    except RuntimeError as exc:
        raise SolverFailure(f"NNLS active-set method failed: {exc}") from None
    w = G @ z + q
    if w.min() < -1e-9 * max(np.abs(q).max(), ROUNDING):
        raise SolverFailure(f"NNLS answer violates the LCP by {-w.min():.3g}: no solution")
    return LCPResult(z, w, "LCP (active set, NNLS)")


def project_on_cone(
    M: np.ndarray, v: np.ndarray, Wn: np.ndarray, G: np.ndarray, tol: float, refine: bool
) -> LCPResult:
    """Project ``v`` on ``{z : Wn.T z >= 0}`` in the metric of ``M`` with clarabel.

    Returns the multipliers as an `LCPResult`: ``z`` is the impulse ``lam`` with
    ``proj = v + M^-1 Wn lam``, and ``w = Wn.T proj``. The QP is in velocities (n unknowns);
    its multipliers solve the LCP with matrix ``G = Wn.T M^-1 Wn`` and ``q = Wn.T v``.
    """
    result = clarabel_qp(M, -(M @ v), Wn.T, tol)
    return _finish(G, Wn.T @ v, result.y, result, refine)


def _finish(
    G: np.ndarray, q: np.ndarray, z: np.ndarray, result: QPResult, refine: bool
) -> LCPResult:
    """Polish clarabel's answer; a status other than 'Solved' is accepted only when polished."""
    z = np.maximum(z, 0.0)
    exact = polish(G, q, z) if refine and np.isfinite(z).all() else None
    if exact is not None:
        z = exact
    elif result.status != "Solved":
        raise SolverFailure(f"clarabel status {result.status} after {result.iterations} iterations")
    return LCPResult(
        z, G @ z + q, "LCP (clarabel)", result.status, result.iterations, exact is not None
    )
