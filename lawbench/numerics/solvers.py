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
from typing import NamedTuple

import clarabel
import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse
import scipy.sparse.linalg

from lawbench.core.budget import current_budget
from lawbench.core.errors import SolverFailure
from lawbench.core.metric import SPARSE_SHARE, as_array, is_diagonal, is_sparse

ROUNDING = 1e-12
# Contacts up to which active-set enumeration (2**m sets) is the exact, cheap method.
ENUMERATION_MAX = 6
# Blocks larger than this with at most SPARSE_SHARE non-zero entries are solved as sparse.
SPARSE_SIZE = 64
# Relative violation of z >= 0 and w >= 0 accepted as rounding.
COMPLEMENTARITY = 1e-10
# Largest rounding of the slacks w = G z + q, eps max_i sum_j |G_ij z_j|, over the velocities
# max |q|, of an active set's solution: beyond it the slacks are rounding, not velocities. An
# LCP without a solution (opposite normals, one contact restituted) has on a near-singular set
# impulses of 1e16 whose slacks cancel to anything, and the set passed for its solution.
CANCELLING = 1e-5
EPS = float(np.finfo(float).eps)
# clarabel's certificates that a QP has no solution: for an LCP's QP, that the LCP has none.
NO_SOLUTION = frozenset({"PrimalInfeasible", "DualInfeasible"})


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
    settings.time_limit = current_budget().seconds_left
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


class LCPResult(NamedTuple):
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
        block = G if rows.size == len(q) else G[np.ix_(rows, rows)]
        try:
            exact[active] = _solve_block(block, -q[active])
        except (np.linalg.LinAlgError, ValueError):
            return None
    slack = G @ exact + q
    velocity_scale = max(np.abs(q).max(), ROUNDING)
    impulse_scale = max(np.abs(exact).max(), ROUNDING)
    # A slack is a sum of terms G_ij z_j that cancel down to the size of q: their rounding too,
    # unless it is all the slack holds (`CANCELLING`).
    reach = abs(G) @ np.abs(exact)
    rounding = ROUNDING * reach
    if exact.min() < -1e-10 * impulse_scale or (slack < -1e-10 * velocity_scale - rounding).any():
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


@functools.cache
def _active_sets(m: int) -> tuple[np.ndarray, ...]:
    """Every subset of m contacts as index arrays, smallest first, then in lexicographic order."""
    return tuple(
        np.array(subset, dtype=int)
        for size in range(m + 1)
        for subset in itertools.combinations(range(m), size)
    )


def _solve_blocks(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve the stacked systems ``A[k] x[k] = b[k]`` of three rows or more.

    By LU, or their least-norm solution when one is singular (the caller rejects the answer).
    """
    try:
        return np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return (np.linalg.pinv(A) @ b[..., None])[..., 0]


def _solve_set(
    G: list[list[np.ndarray]], q: list[np.ndarray], active: tuple[int, ...]
) -> list[np.ndarray]:
    """The impulses of the ``active`` contacts that zero their slack, for a stack of problems.

    ``G`` and ``q`` are given entry by entry (arrays over the stack). Blocks of one and two rows
    by their closed forms (a singular one gives non-finite numbers, which the caller rejects);
    larger ones by `_solve_blocks`.
    """
    if not active:
        return []
    if len(active) == 1:
        (i,) = active
        return [-q[i] / G[i][i]]
    if len(active) == 2:
        i, j = active
        a, c, d = G[i][i], G[i][j], G[j][j]
        det = a * d - c * G[j][i]
        return [(d * -q[i] - c * -q[j]) / det, (a * -q[j] - c * -q[i]) / det]
    block = np.stack([np.stack([G[i][j] for j in active], -1) for i in active], -2)
    solved = _solve_blocks(block, np.stack([-q[i] for i in active], -1))
    return [solved[:, k] for k in range(len(active))]


def _enumerate_batch(G: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`enumerate_lcp` for a stack of problems, G (B, m, m) and q (B, m).

    Each entry of G, q and z is one array over the stack, so that every step is an elementwise
    operation on B numbers: numpy's reductions over a handful of contacts are slow. The tests
    are those of the one-problem path (an inactive contact's zero impulse passes them).
    """
    batch, m = q.shape
    g = [[G[:, i, j] for j in range(m)] for i in range(m)]
    rhs = [q[:, i] for i in range(m)]
    z = [np.zeros(batch) for _ in range(m)]
    found = np.zeros(batch, dtype=bool)
    floor = -COMPLEMENTARITY * functools.reduce(np.maximum, map(np.abs, rhs), ROUNDING)
    for active in _active_sets(m):
        if found.all():
            break
        with np.errstate(all="ignore"):
            solved = _solve_set(g, rhs, tuple(active.tolist()))
            scale = functools.reduce(np.maximum, map(np.abs, solved), ROUNDING)
            good = ~found
            for x in solved:
                good &= np.isfinite(x) & (x >= -COMPLEMENTARITY * scale)
            for i in range(m):
                terms = [g[i][j] * x for j, x in zip(active.tolist(), solved, strict=True)]
                good &= sum(terms, start=0.0) + rhs[i] >= floor
                reach = sum(map(np.abs, terms), start=0.0)
                good &= EPS * reach <= -floor / COMPLEMENTARITY * CANCELLING
        for j, x in zip(active.tolist(), solved, strict=True):
            z[j] = np.where(good, np.maximum(x, 0.0), z[j])
        found |= good
    return np.stack(z, axis=-1), found


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
        solved = _enumerate_one(np.asarray(G, dtype=float), q)
        if solved is None:
            return np.zeros_like(q), np.array(False)
        return solved[0], np.array(True)
    batch, m = q.shape[:-1], q.shape[-1]
    G = np.broadcast_to(np.asarray(G, dtype=float), (*batch, m, m)).reshape(-1, m, m)
    z, found = _enumerate_batch(G, q.reshape(-1, m))
    return z.reshape(*batch, m), found.reshape(batch)


def _enumerate_one(G: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """`enumerate_lcp` for one problem: ``(z, w = G z + q)``, or None where no set is found.

    One problem of a few contacts is dominated by the cost of calling numpy, so it is solved in
    Python floats: two contacts by their closed form, more by the same enumeration.
    """
    solved = _two_contacts(G, q) if len(q) == 2 else _enumerate_sets(G, q)
    return None if solved is None else (np.array(solved[0]), np.array(solved[1]))


def _two_contacts(G: np.ndarray, q: np.ndarray) -> tuple[list[float], list[float]] | None:
    """The LCP of two contacts in closed form, as `enumerate_lcp` solves it.

    The active sets {}, {0}, {1}, {0, 1} in that order, each set's equations solved by the
    formulas of `_solve_set` and held to the same tests, so the answer is the same. The tests
    are ordered so that the usual candidate passes them with a few comparisons.
    """
    (a, b), (c, d) = G.tolist()
    q0, q1 = q.tolist()
    det = a * d - b * c
    candidates = (
        (0.0, 0.0),
        (-q0 / a if a else math.inf, 0.0),
        (0.0, -q1 / d if d else math.inf),
        ((d * -q0 - b * -q1) / det, (a * -q1 - b * -q0) / det) if det else (math.inf, 0.0),
    )
    floor = -COMPLEMENTARITY * max(abs(q0), abs(q1), ROUNDING)
    for z0, z1 in candidates:
        low = min(z0, z1)
        if low < 0.0 and low < -COMPLEMENTARITY * max(abs(z0), abs(z1), ROUNDING):
            continue
        if not (a * z0 + b * z1 + q0 >= floor and c * z0 + d * z1 + q1 >= floor):
            continue
        reach = max(abs(a * z0) + abs(b * z1), abs(c * z0) + abs(d * z1))
        if math.isfinite(z0 + z1) and not _cancels(reach, floor):
            z0, z1 = max(z0, 0.0), max(z1, 0.0)
            return [z0, z1], [a * z0 + b * z1 + q0, c * z0 + d * z1 + q1]
    return None


def _enumerate_sets(G: np.ndarray, q: np.ndarray) -> tuple[list[float], list[float]] | None:
    """`enumerate_lcp` for one problem, in Python floats: the same sets, formulas and tests.

    Blocks of one and two rows are solved with the closed forms of `_solve_set` in plain
    arithmetic (identical in IEEE double), and only larger blocks go through LU.
    """
    m = len(q)
    rows, rhs = G.tolist(), q.tolist()
    floor = -COMPLEMENTARITY * max(max(abs(x) for x in rhs), ROUNDING)
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
            with np.errstate(all="ignore"):
                solved = _solve_blocks(G[np.ix_(active, active)][None], -q[active][None])[0]
            for i, x in zip(active.tolist(), solved.tolist(), strict=True):
                candidate[i] = x
        if not all(math.isfinite(x) for x in candidate):
            continue
        impulse_scale = max(max(abs(x) for x in candidate), ROUNDING)
        if min(candidate) < -COMPLEMENTARITY * impulse_scale:
            continue
        if min(_affine(rows, candidate, rhs)) >= floor and not _cancels(
            max(sum(abs(g * x) for g, x in zip(row, candidate, strict=True)) for row in rows),
            floor,
        ):
            z = [max(x, 0.0) for x in candidate]
            return z, _affine(rows, z, rhs)
    return None


def _cancels(reach: float, floor: float) -> bool:
    """Whether slacks summed from terms up to ``reach`` are rounding (`CANCELLING`).

    ``floor`` is the enumeration's ``-COMPLEMENTARITY max |q|``.
    """
    return EPS * reach > -floor / COMPLEMENTARITY * CANCELLING


def _affine(rows: list[list[float]], z: list[float], q: list[float]) -> list[float]:
    """``G z + q`` in Python floats, G given by its rows."""
    return [
        sum(g * x for g, x in zip(row, z, strict=True)) + b for row, b in zip(rows, q, strict=True)
    ]


def solve_lcp(
    G: np.ndarray,
    q: np.ndarray,
    tol: float = 1e-10,
    refine: bool = True,
    method: str = "clarabel",
    decoupled: bool | None = None,
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
    decoupled : bool, optional
        Whether ``G`` is diagonal, where the caller knows it (`ImpactProblem.decoupled`);
        None tests it here.
    """
    if decoupled is None:
        decoupled = is_diagonal(G)
    if decoupled:
        diagonal = G.diagonal()
        if (diagonal <= 0).any():
            raise SolverFailure("the LCP matrix has a zero diagonal entry")
        z = np.maximum(-q / diagonal, 0.0)
        method = "closed form" if len(q) == 1 else "decoupled (diagonal Delassus)"
        return LCPResult(z, G @ z + q, method)
    if len(q) <= ENUMERATION_MAX:
        solved = _enumerate_one(as_array(G), q)
        if solved is not None:
            return LCPResult(*solved, "LCP (active-set enumeration)")
    if method == "nnls":
        return _nnls_lcp(as_array(G), q)
    identity = scipy.sparse.identity(len(q), format="csc") if is_sparse(G) else np.eye(len(q))
    result = clarabel_qp(G, q, identity, tol)
    return _finish(G, q, result.x, result, refine, tol)


def _lcp_violation(G: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """How far ``z >= 0`` is from solving ``0 <= G z + q _|_ z``, over the LCP's own scales.

    The larger of a negative slack ``w = G z + q`` and a slack left open where ``z`` pushes,
    over the contact velocities ``max |q|`` (and the impulses ``max z``); the rounding of the
    slacks, sums of terms ``G_ij z_j`` that cancel, is allowed, unless it is all they hold
    (infinite then).
    """
    w = G @ z + q
    reach = np.asarray(abs(G) @ z).ravel()
    rounding = ROUNDING * reach
    velocity = max(float(np.abs(q).max(initial=0.0)), ROUNDING)
    if EPS * float(reach.max(initial=0.0)) > CANCELLING * velocity:
        return math.inf  # the slacks are the rounding of impulses that cancel (`CANCELLING`)
    impulse = max(float(z.max(initial=0.0)), ROUNDING)
    below = float(np.max(-(w + rounding), initial=0.0)) / velocity
    opened = np.maximum(w - rounding, 0.0) * z / impulse
    return max(below, float(opened.max(initial=0.0)) / velocity)


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
    return _finish(G, Wn.T @ v, result.y, result, refine, tol)


def _finish(
    G: np.ndarray, q: np.ndarray, z: np.ndarray, result: QPResult, refine: bool, tol: float
) -> LCPResult:
    """Polish clarabel's answer; a status other than 'Solved' is accepted only when polished.

    An infeasibility certificate is never polished: the LCP then has no solution (its QP is
    unbounded, as where two closed contacts push along opposite normals and the restitution
    of one asks the other to approach), and clarabel's last iterate, impulses of 1e15 whose
    slacks cancel within their rounding, would pass for one. An answer left unpolished must
    still solve the LCP to ``sqrt(tol)`` of its own scales (`_lcp_violation`): clarabel's
    tolerances are relative to the QP's objective, and a velocity QP whose mass matrix holds a
    stiff coordinate no contact moves (a condition of 1e9 and more) is 'Solved' with
    multipliers whose slacks, on the contacts, are of the size of the approach itself.
    """
    if result.status in NO_SOLUTION:
        raise SolverFailure(
            f"clarabel status {result.status} after {result.iterations} iterations: the LCP has "
            "no solution"
        )
    z = np.maximum(z, 0.0)
    exact = polish(G, q, z) if refine and np.isfinite(z).all() else None
    if exact is not None:
        z = exact
    elif result.status == "MaxTime":
        current_budget().out_of_time()
    elif result.status != "Solved":
        raise SolverFailure(f"clarabel status {result.status} after {result.iterations} iterations")
    else:
        violation = _lcp_violation(G, q, z)
        if not violation <= tol**0.5:
            by = (
                f"by {violation:.3g} of the contact velocities (beyond sqrt(tol) = {tol**0.5:.3g})"
                if math.isfinite(violation)
                else f"with impulses up to {z.max():.3g} whose slacks are their rounding"
            )
            raise SolverFailure(
                f"clarabel status Solved after {result.iterations} iterations, but its "
                f"impulses break the LCP {by}: the problem is too ill-conditioned for its QP, "
                "or the LCP has no solution"
            )
    return LCPResult(
        z, G @ z + q, "LCP (clarabel)", result.status, result.iterations, exact is not None
    )
