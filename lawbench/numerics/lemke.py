"""Lemke's complementary pivoting algorithm for a general linear complementarity problem.

The problem: find ``z`` with ``w = M z + q``, ``0 <= w _|_ z >= 0``, for any square ``M``
(symmetric or not). Lemke's method (C.E. Lemke, *Bimatrix equilibrium points and mathematical
programming*, Management Science 11, 1965; Cottle, Pang and Stone, *The Linear Complementarity
Problem*, 1992, section 4.4) augments the problem with an artificial variable ``z0`` and a
covering vector ``d > 0``, ``w = M z + d z0 + q``, starts from the almost complementary basis
where ``z0`` makes every ``w`` non-negative, and pivots in the complement of the variable that
just left, until ``z0`` leaves (a solution) or the entering column has no positive entry (ray
termination).

Degenerate steps (ties in the ratio test) are broken by the lexicographic rule: the rows of
``[B^-1 q, B^-1]`` divided by the entering column are compared lexicographically, which keeps
every basis lexicographically feasible and so never visits a basis twice (no cycling); when the
artificial variable is among the tied rows it leaves at once. The first pivot (``z0`` enters)
takes, among the rows of largest ``-q_i / d_i``, the one of largest index: the lexicographic
choice for the starting tableau. The rule is deterministic.

Ray termination proves that no solution exists when ``M`` is copositive-plus (for example
symmetric positive semidefinite) and ``d > 0``; for other matrices it only says that Lemke's
path did not reach one. Either way it is reported as `RayTermination` (a `SolverFailure`)
with the pivot count; reaching the pivot bound is a `SolverFailure` too (Lemke's method is
finite but may take exponentially many pivots on contrived matrices).

Numerics: the problem is scaled so that ``max |M| = max |q| = 1``, pivots use an explicit
tableau, and the final basis is solved again from the original columns so the answer does not
carry the rounding accumulated over the pivots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lawbench.core.errors import InvalidProblem, SolverFailure

# Tableau entries smaller than this (relative to the largest entry of their column) are zero.
PIVOT_TOLERANCE = 1e-11
# Ratios closer than this (relative) are ties for the lexicographic rule.
TIE_TOLERANCE = 1e-11
# Largest violation of z >= 0 or w >= 0, relative to max |q|, accepted as rounding.
FEASIBILITY_TOLERANCE = 1e-9


class RayTermination(SolverFailure):
    """Lemke's path ended on a ray: no solution when ``M`` is copositive-plus."""


@dataclass(frozen=True)
class LemkeResult:
    """Solution of an LCP found by Lemke's method.

    Attributes
    ----------
    z : array (n,)
        The solution, ``z >= 0``.
    w : array (n,)
        ``M z + q >= 0``, complementary to ``z`` (both clipped at zero to rounding).
    pivots : int
        Number of pivots, the first one (bringing in ``z0``) included; 0 when ``q >= 0``.
    """

    z: np.ndarray
    w: np.ndarray
    pivots: int


def lemke(
    M: np.ndarray,
    q: np.ndarray,
    covering: np.ndarray | None = None,
    max_pivots: int | None = None,
) -> LemkeResult:
    """Solve ``w = M z + q``, ``0 <= w _|_ z >= 0`` by Lemke's complementary pivoting.

    Parameters
    ----------
    M : array (n, n)
        Any square matrix.
    q : array (n,)
        Constant term.
    covering : array (n,) or None
        Covering vector ``d > 0`` of the artificial variable; all ones by default.
    max_pivots : int or None
        Bound on the number of pivots; ``100 (n + 1)`` by default.

    Returns
    -------
    LemkeResult
        ``z``, ``w`` and the pivot count.

    Raises
    ------
    InvalidProblem
        For shapes that disagree, non-finite numbers or a covering vector that is not positive.
    SolverFailure
        When the pivot bound is reached, or as `RayTermination` on ray termination; the
        message names the pivot count.
    """
    M, q, d = _checked(M, q, covering)
    n = q.size
    if q.min() >= 0:
        return LemkeResult(np.zeros(n), q.copy(), 0)
    limit = 100 * (n + 1) if max_pivots is None else int(max_pivots)
    scale_m = float(np.abs(M).max()) or 1.0
    scale_q = float(np.abs(q).max())
    Ms, qs, ds = M / scale_m, q / scale_q, d / d.max()
    # Columns: w (0..n-1), z (n..2n-1), z0 (2n), right-hand side (2n+1); I w - M z - d z0 = q.
    columns = np.hstack([np.eye(n), -Ms, -ds[:, None]])
    tableau = np.hstack([columns, qs[:, None]])
    basis = list(range(n))
    artificial, rhs = 2 * n, 2 * n + 1

    ratios = -qs / ds
    tied = np.flatnonzero(ratios >= ratios.max() - TIE_TOLERANCE * max(1.0, ratios.max()))
    # The lexicographic maximum of rows tied in -q/d is the one of largest index.
    row = int(tied[-1])
    _pivot(tableau, basis, row, artificial)
    entering = row + n  # complement of w_row, which just left
    pivots = 1
    while True:
        if pivots >= limit:
            raise SolverFailure(
                f"Lemke: no solution reached within the bound of {limit} pivots "
                f"({pivots} pivots made)"
            )
        row = _leaving_row(tableau, basis, entering, n)
        if row is None:
            raise RayTermination(
                f"Lemke: ray termination after {pivots} pivots (entering variable "
                f"{_name(entering, n)} is unbounded): no solution, or a matrix outside the "
                "class Lemke's method processes"
            )
        leaving = basis[row]
        _pivot(tableau, basis, row, entering)
        pivots += 1
        if leaving == artificial:
            break
        entering = leaving + n if leaving < n else leaving - n
    return _solution(M, q, columns, tableau[:, rhs], qs, basis, scale_m, scale_q, pivots)


def _checked(
    M: np.ndarray, q: np.ndarray, covering: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``M``, ``q`` and the covering vector as float arrays, or raise InvalidProblem."""
    M = np.array(M, dtype=float, ndmin=2)
    q = np.array(q, dtype=float, ndmin=1)
    n = q.size
    if q.ndim != 1 or M.shape != (n, n) or n == 0:
        raise InvalidProblem(f"LCP: M has shape {M.shape} and q {q.shape}; need (n, n), (n,)")
    d = np.ones(n) if covering is None else np.array(covering, dtype=float, ndmin=1)
    if d.shape != (n,):
        raise InvalidProblem(f"LCP: covering vector has shape {d.shape}, expected ({n},)")
    for label, array in (("M", M), ("q", q), ("covering vector", d)):
        if not np.isfinite(array).all():
            raise InvalidProblem(f"LCP: {label} has a non-finite entry")
    if d.min() <= 0:
        raise InvalidProblem(f"LCP: covering vector entry {d.min():g}: must be > 0")
    return M, q, d


def _pivot(tableau: np.ndarray, basis: list[int], row: int, column: int) -> None:
    """Gauss-Jordan pivot on (row, column); ``column`` becomes basic in ``row``."""
    tableau[row] /= tableau[row, column]
    factors = tableau[:, column].copy()
    factors[row] = 0.0
    tableau -= np.outer(factors, tableau[row])
    basis[row] = column


def _leaving_row(tableau: np.ndarray, basis: list[int], entering: int, n: int) -> int | None:
    """Row of the leaving variable by the lexicographic ratio test; None for a ray."""
    column = tableau[:, entering]
    threshold = PIVOT_TOLERANCE * max(1.0, float(np.abs(column).max()))
    candidates = np.flatnonzero(column > threshold)
    if candidates.size == 0:
        return None
    # Compare [B^-1 q, B^-1] row by row: the right-hand side first, then the w columns.
    for key in [2 * n + 1, *range(n)]:
        ratios = tableau[candidates, key] / column[candidates]
        low = ratios.min()
        candidates = candidates[ratios <= low + TIE_TOLERANCE * max(1.0, abs(low))]
        artificial_rows = [r for r in candidates if basis[r] == 2 * n]
        if artificial_rows:
            return int(artificial_rows[0])
        if candidates.size == 1:
            return int(candidates[0])
    return int(candidates[0])


def _name(variable: int, n: int) -> str:
    """Readable name of a tableau variable: w_i, z_i or z0."""
    if variable == 2 * n:
        return "z0"
    return f"w_{variable}" if variable < n else f"z_{variable - n}"


def _solution(
    M: np.ndarray,
    q: np.ndarray,
    columns: np.ndarray,
    values: np.ndarray,
    qs: np.ndarray,
    basis: list[int],
    scale_m: float,
    scale_q: float,
    pivots: int,
) -> LemkeResult:
    """Solve the final complementary basis again from the original columns; check it."""
    try:
        exact = np.linalg.solve(columns[:, basis], qs)
    except np.linalg.LinAlgError:
        exact = values
    if not np.isfinite(exact).all() or exact.min() < -FEASIBILITY_TOLERANCE:
        exact = values
    n = qs.size
    x = np.zeros(2 * n + 1)
    x[basis] = exact
    z = x[n : 2 * n] * scale_q / scale_m
    w = M @ z + q
    worst = min(float(z.min()) * scale_m, float(w.min())) / scale_q
    if not np.isfinite(worst) or worst < -FEASIBILITY_TOLERANCE:
        raise SolverFailure(
            f"Lemke: the final basis after {pivots} pivots violates z >= 0 or w >= 0 by "
            f"{-worst:.3g} (relative): the problem is too ill-conditioned"
        )
    return LemkeResult(np.maximum(z, 0.0), np.maximum(w, 0.0), pivots)
