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
from dataclasses import dataclass
from typing import NamedTuple

import clarabel
import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse

from lawbench.core.errors import SolverFailure
from lawbench.core.guards import current_budget
from lawbench.core.metric import as_array, is_diagonal, is_sparse
from lawbench.numerics.active_sets import CANCELLING, EPS, ROUNDING, polish

# Contacts up to which active-set enumeration (2**m sets) is the exact, cheap method.
ENUMERATION_MAX = 6
# Relative violation of z >= 0 and w >= 0 accepted as rounding.
COMPLEMENTARITY = 1e-10
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
    P: np.ndarray,
    c: np.ndarray,
    A: np.ndarray,
    tol: float,
    max_iter: int = 200,
    b: np.ndarray | None = None,
) -> QPResult:
    """Solve ``min x.P x / 2 + c.x`` subject to ``A x >= b`` (``b = 0`` by default) with clarabel.

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
        np.zeros(A.shape[0]) if b is None else -np.asarray(b, dtype=float),
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
    over the contact velocities ``max |q|``. An open slack counts up to the velocity its own
    impulse gives its contact, ``G_jj z_j``: the complementarity ``z_j w_j = 0`` in units of
    velocity, contact by contact, so that an impulse of 0.5 on a ball of mass 1 is not
    dwarfed by impulses of 1e9 on its neighbours of mass 1e9 (an impulse scaled by the
    largest one let a light ball leave its chain with a slack of 0.08 open). The rounding of
    the slacks, sums of terms ``G_ij z_j`` that cancel, is allowed, unless it is all they hold
    (infinite then).
    """
    w = G @ z + q
    reach = np.asarray(abs(G) @ z).ravel()
    rounding = ROUNDING * reach
    velocity = max(float(np.abs(q).max(initial=0.0)), ROUNDING)
    if EPS * float(reach.max(initial=0.0)) > CANCELLING * velocity:
        return math.inf  # the slacks are the rounding of impulses that cancel (`CANCELLING`)
    below = float(np.max(-(w + rounding), initial=0.0)) / velocity
    opened = np.minimum(np.maximum(w - rounding, 0.0), np.asarray(G.diagonal()) * z)
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


def project_in_kinetic_metric(
    M: np.ndarray,
    v: np.ndarray,
    Wn: np.ndarray,
    G: np.ndarray,
    q: np.ndarray,
    tol: float,
    refine: bool,
) -> LCPResult:
    """Solve an impact's LCP ``0 <= G z + q _|_ z >= 0`` as a projection where ``M`` is ``I``.

    ``G = Wn.T M^-1 Wn`` and ``q = Wn.T v + b``. With ``M = L L.T`` and ``y = L.T w``, Moreau's
    projection ``min |y - L.T v|^2 / 2`` over ``(L^-1 Wn).T y >= -b`` has the impulses as its
    multipliers (``w = v + M^-1 Wn z``, ``Wn.T w + b = G z + q``). The QP in the impulses has
    the condition of ``G``, that of ``M`` where the contacts move bodies of very different
    masses (impulses of 1e9 on bodies of 1e9 beside ones of 1 on bodies of 1): clarabel ended
    it 'AlmostSolved' with impulses of 1e-26, the bodies untouched. Here the Hessian is the
    identity, and the constraints have the condition of ``G``'s square root.
    """
    L = np.linalg.cholesky(as_array(M))
    A = scipy.linalg.solve_triangular(L, as_array(Wn), lower=True)
    result = clarabel_qp(np.eye(len(v)), -(L.T @ v), A.T, tol, b=Wn.T @ v - q)
    return _finish(G, q, result.y, result, refine, tol, "projection in the kinetic metric")


def _finish(
    G: np.ndarray,
    q: np.ndarray,
    z: np.ndarray,
    result: QPResult,
    refine: bool,
    tol: float,
    form: str = "LCP",
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
        z, G @ z + q, f"{form} (clarabel)", result.status, result.iterations, exact is not None
    )
