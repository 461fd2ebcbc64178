"""Coulomb's law in the impulses by nonsmooth Gauss-Seidel, each contact solved exactly.

The problem is FCLIB's local form (`lawbench.core.contact`): find ``P`` with, per contact j,
``K_j ∋ P_j _|_ uhat_j ∈ K*_j``, ``u = W P + q``, ``uhat_j = (un_j + mu_j |ut_j|, ut_j)``,
``K_j = {|Pt_j| <= mu_j Pn_j}`` (De Saxce and Feng 1991); ``W`` and ``q`` in FCLIB's order (per
contact its normal, then its ``dim - 1`` tangents), ``W`` as given, symmetric or not.
`in_local_order` brings a Delassus matrix of lawbench's order (the m normal components, then
contact j's tangential ones at ``m + j*d ... m + j*d + d - 1``) to it.

Nonsmooth Gauss-Seidel (Jean, CMAME 177, 1999; Acary, Brémond and Huber, "On solving contact
problems with Coulomb friction: formulations and numerical comparisons", 2018, section 4.1;
Siconos' ``fc3d_nsgs``) sweeps the contacts in order; contact j's local problem, the others
fixed, is ``u_j = W_jj P_j + b`` with ``W_jj`` its diagonal block and ``b`` the rest of
``(W P + q)_j``, and is solved exactly (`solve_contact`) by trying its three states in turn:

- take-off: ``P_j = 0``, the solution exactly when ``b_n >= 0``;
- stick: ``W P_j = -b``, the solution when it lies in the cone;
- slip: ``un_j = 0``, ``Pt_j = -mu_j Pn_j e`` with ``e`` the unit slip direction, so that
  ``Pn_j = -b_n / (W_nn - mu_j W_nt e)``. In the plane ``e = +-1`` (closed form). In space ``e``
  is ``(cos t, sin t)``, and ``ut_j`` parallel to ``e`` is a trigonometric polynomial of degree
  two in the slip angle ``t``: its roots are those of a quartic in ``z = exp(i t)`` on the unit
  circle (companion matrix), refined by Newton's method on the angle. A slip must have
  ``Pn_j > 0`` and ``ut_j . e >= 0``; when several roots qualify (strong normal-tangential
  coupling gives several local solutions) the one nearest the current impulse is kept.

A contact with ``mu_j = 0`` has the scalar projection ``Pn_j = max(-b_n / W_nn, 0)``. A local
problem none of whose states qualifies (a singular block, or rounding at a state's boundary) is
solved by Siconos' fallback, the projection iteration
``P_j <- proj_K(P_j - (u_j + (mu_j |ut_j|, 0)) / W_nn)`` (Acary et al. 2018, eq. 4.4).

Sweeps go on until the FC3D error (`lawbench.core.mechanics.fc3d_error`) is at most ``tol``, or
until the iteration is stationary: a sweep leaves ``P`` unchanged, or the error has not reached
a new low (by a millionth) for a thousand sweeps and for as many sweeps as the last low took (on
a singular Delassus matrix Gauss-Seidel can settle on a point that is no solution, as Siconos'
NSGS does on the same problems; a slow but steady descent always finds new lows). The error
costs about as much as a sweep, so, like Siconos' light-then-full evaluation, it is computed
when the relative change of ``P`` over a sweep falls below a gate (``tol`` at first, lowered by
the ratio of the error found to ``tol``), and every `CHECK_EVERY` sweeps. Each sweep spends one
step of the solve's budget (`lawbench.core.law`), so the loop ends at the law's ``max_steps``
or ``max_seconds``. `solve_polished` is the law's solve: the sweeps, then, where they became
stationary above ``tol``, Newton's method on the contact states they show
(`lawbench.numerics.cones.polish`), or a failure that gives ``W``'s rank.

The per-contact kernel and the sweep are compiled by numba where it is installed
(``pip install 'lawbench[fast]'``, `compiled`); the same functions run as plain Python without
it. The compilation (or its load from numba's cache) is a one-time cost of the process, not of a
solve: Moreau's law asks for it before a solve's budget and wall-clock bound start
(`lawbench.core.law.Law.prepare`), and the study runner before its workers start. numba's
import, the compilation and each call of a compiled kernel run whole
(`lawbench.core.guards.held`): stopped half-way by a wall-clock alarm, numba fails on every
later call in the process; a compiled kernel runs no Python, where the alarm's handler cannot
run anyway.
``W`` may be dense or scipy.sparse: it is held in compressed rows, so a sweep costs time
proportional to its non-zero entries.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
import scipy.sparse

from lawbench.core.errors import SolverFailure
from lawbench.core.guards import current_budget, held
from lawbench.core.mechanics import fc3d_error, project
from lawbench.numerics import cones

_F = TypeVar("_F", bound=Callable[..., Any])
# The kernels numba compiles, by their names in this module.
_KERNELS: list[str] = []


def _kernel(function: _F) -> _F:
    """Mark ``function`` for numba (`compiled`); until then it is plain Python."""
    _KERNELS.append(function.__name__)
    return function


def _whole(fast: bool) -> AbstractContextManager[None]:
    """`held` around a compiled kernel's call; nothing around plain Python, which may stop."""
    return held() if fast else nullcontext()


def compiled() -> bool:
    """Compile the kernels with numba, once, where it is installed; whether they are compiled.

    numba is imported here, at the first call, not with the module: its import costs a process
    0.25 s and 55 MB, and most processes that load Moreau's law never sweep. The module's names
    are bound to the compiled functions, which find each other there when they compile, and each
    kernel that a solve calls is called once on one spatial contact: numba compiles it then for
    the types every solve gives it, or loads it from its cache (``cache=True``, about 30 s cold
    on one core). That is a one-time cost of the process, not of a solve: call this before a
    solve's budget starts (`lawbench.core.law.Law.prepare`), as the one way into a solve and the
    study runner do.
    """
    with held():
        return _compile()


@functools.cache
def _compile() -> bool:
    """`compiled`'s work, done once."""
    try:
        import numba
    except ImportError:  # the optional extra 'fast' is not installed: plain Python
        return False
    namespace = globals()
    for name in _KERNELS:
        namespace[name] = numba.njit(cache=True)(namespace[name])
    _warm_up()
    return True


def _warm_up() -> None:
    """Call the kernels that Python calls (a sweep, the blocks, one contact's state) once."""
    W = scipy.sparse.csr_matrix(np.eye(3))
    q, mu = np.array([-1.0, 0.5, 0.0]), np.array([0.5])
    blocks = _blocks(W.indptr, W.indices, W.data, 3)
    inverse = inverses(blocks)
    _sweep(W.indptr, W.indices, W.data, blocks, inverse, q, mu, np.zeros(3))
    _in_a_state(blocks[0], inverse[0], q, 0.5, np.zeros(3))


# A block whose condition number exceeds this has no reliable stick solution.
SINGULAR = 1e12
# Newton steps at most refining a root of the slip angle (a root of the quartic off the unit
# circle gives a start that is no root), and the relative misalignment of the slip direction that
# still counts as a root.
ANGLE_STEPS, ALIGNED = 50, 1e-8
# Sweeps between two evaluations of the FC3D error while the change of P stays above the gate.
CHECK_EVERY = 10
# The iteration is stationary when its FC3D error has not reached a new low, by a fraction
# STALL_DROP, for STALL_SWEEPS sweeps and for as many sweeps as it took to reach the last low.
STALL_DROP, STALL_SWEEPS = 1e-6, 1000
# Projection steps of the fallback local solver.
FALLBACK_STEPS = 200
TINY = np.finfo(float).tiny

# Coulomb's cone projection, compiled for the fallback local solver.
_project = project
_KERNELS.append("_project")


@dataclass(frozen=True)
class GaussSeidelResult:
    """Impulses ``P`` (lawbench's order), the sweeps done and the FC3D error of ``P``."""

    P: np.ndarray
    sweeps: int
    error: float


def local_order(m: int, d: int) -> np.ndarray:
    """Positions in lawbench's order of FCLIB's per-contact order (n, t1[, t2]) of each contact."""
    tangential = m + np.arange(m)[:, None] * d + np.arange(d)
    return np.column_stack([np.arange(m), tangential]).ravel()


def in_local_order(G: Any, q: np.ndarray, m: int, d: int) -> tuple[Any, np.ndarray]:
    """``G`` (CSR) and ``q`` of lawbench's order (normals, then tangents) in FCLIB's order."""
    order = local_order(m, d)
    return scipy.sparse.csr_matrix(G)[order][:, order], np.asarray(q, dtype=float)[order]


def error_of(G: Any, q: np.ndarray, mu: np.ndarray, d: int, P: np.ndarray) -> float:
    """The FC3D error of ``P`` (lawbench's order) on ``G``, ``q`` (dense or sparse ``G``)."""
    W, local_q = in_local_order(G, q, len(mu), d)
    return fc3d_error(W, local_q, mu, P[local_order(len(mu), d)])


@_kernel
def _angle_terms(W: np.ndarray, b: np.ndarray, mu: float) -> tuple[np.ndarray, ...]:
    """``A``, ``B``, ``C`` of ``V(t) = A + B cos t + C sin t = (W_nn - mu W_nt e) ut`` (spatial)."""
    bn, bt, wnt = b[0], b[1:], W[0, 1:]
    A = -bn * W[1:, 0] + W[0, 0] * bt
    B = mu * (bn * W[1:, 1] - bt * wnt[0])
    C = mu * (bn * W[1:, 2] - bt * wnt[1])
    return A, B, C


@_kernel
def _refined(A: np.ndarray, B: np.ndarray, C: np.ndarray, angle: float) -> np.ndarray:
    """The unit direction at the root of ``e x V(t)`` Newton's method reaches from ``angle``."""
    for _ in range(ANGLE_STEPS):
        c, s = np.cos(angle), np.sin(angle)
        V0, V1 = A[0] + B[0] * c + C[0] * s, A[1] + B[1] * c + C[1] * s
        dV0, dV1 = C[0] * c - B[0] * s, C[1] * c - B[1] * s
        h = c * V1 - s * V0
        slope = -s * V1 - c * V0 + c * dV1 - s * dV0
        if slope == 0.0:
            break
        angle -= h / slope
        if abs(h / slope) <= 1e-15:
            break
    return np.array([np.cos(angle), np.sin(angle)])


@_kernel
def _slip_directions(W: np.ndarray, b: np.ndarray, mu: float) -> np.ndarray:
    """Every candidate unit slip direction ``e`` (rows): ``+1`` and ``-1`` in the plane.

    In space the roots in the slip angle ``t`` of ``h(t) = e x V(t)`` (`_angle_terms`).
    """
    if b.size == 2:
        return np.array([[1.0], [-1.0]])
    A, B, C = _angle_terms(W, b, mu)
    # 4 z^2 h(t) with cos t = (z + 1/z) / 2, sin t = (z - 1/z) / 2i: a quartic in z.
    twist = C[1] - B[0]
    coefficients = np.array(
        [
            complex(B[1] + C[0], -twist),
            complex(2.0 * A[1], 2.0 * A[0]),
            complex(2.0 * (B[1] - C[0]), 0.0),
            complex(2.0 * A[1], -2.0 * A[0]),
            complex(B[1] + C[0], twist),
        ]
    )
    scale = np.abs(coefficients).max()
    if scale == 0.0:
        return np.zeros((0, 2))
    roots = np.roots(coefficients / scale)
    directions = np.empty((roots.size, 2))
    for k in range(roots.size):
        directions[k] = _refined(A, B, C, np.angle(roots[k]))
    return directions


@_kernel
def _slip_along(W: np.ndarray, b: np.ndarray, mu: float, e: np.ndarray) -> np.ndarray:
    """The slipping impulse along the unit direction ``e``, or an empty array if it is none.

    ``Pn = -b_n / (W_nn - mu W_nt e) > 0``, ``Pt = -mu Pn e``, and ``ut`` along ``+e``.
    """
    size = b.size
    denominator = W[0, 0]
    for k in range(1, size):
        denominator -= mu * W[0, k] * e[k - 1]
    if denominator <= 0.0:
        return np.zeros(0)
    P = np.empty(size)
    P[0] = -b[0] / denominator
    for k in range(1, size):
        P[k] = -mu * P[0] * e[k - 1]
    ut = np.empty(size - 1)
    for a in range(1, size):
        total = b[a]
        for c in range(size):
            total += W[a, c] * P[c]
        ut[a - 1] = total
    along = 0.0
    for k in range(size - 1):
        along += ut[k] * e[k]
    across = 0.0
    for k in range(size - 1):
        across += (ut[k] - along * e[k]) ** 2
    largest = 0.0
    for value in b:
        largest = max(largest, abs(value))
    if along < 0.0 or np.sqrt(across) > ALIGNED * (_norm(ut) + largest):
        return np.zeros(0)
    return P


@_kernel
def _slip(W: np.ndarray, b: np.ndarray, mu: float, current: np.ndarray) -> np.ndarray:
    """The slipping impulse, or an empty array when no direction qualifies.

    In space first the root Newton's method reaches from the current slip direction; else,
    and in the plane, the qualifying slip nearest ``current``.
    """
    speed = np.linalg.norm(current[1:])
    if b.size == 3 and speed > 0.0:
        A, B, C = _angle_terms(W, b, mu)
        warm = _slip_along(W, b, mu, _refined(A, B, C, np.arctan2(-current[2], -current[1])))
        if warm.size:
            return warm
    best, distance = np.zeros(0), np.inf
    directions = _slip_directions(W, b, mu)
    for k in range(directions.shape[0]):
        P = _slip_along(W, b, mu, directions[k])
        if P.size and np.linalg.norm(P - current) < distance:
            best, distance = P, np.linalg.norm(P - current)
    return best


@_kernel
def _projected(W: np.ndarray, b: np.ndarray, mu: float, current: np.ndarray) -> np.ndarray:
    """The fallback: projection steps ``P <- proj_K(P - uhat / W_nn)`` from ``current``."""
    P = current.copy()
    rho = 1.0 / max(W[0, 0], TINY)
    for _ in range(FALLBACK_STEPS):
        u = W @ P + b
        normal, tangential = _project(
            P[0] - rho * (u[0] + mu * np.linalg.norm(u[1:])), P[1:] - rho * u[1:], mu
        )
        P[0], P[1:] = normal, tangential
    return P


@_kernel
def solve_contact(
    W: np.ndarray, inverse: np.ndarray, b: np.ndarray, mu: float, current: np.ndarray
) -> np.ndarray:
    """One contact's impulse for its local velocity ``u = W P + b``: take-off, stick or slip.

    Parameters
    ----------
    W : array (1 + d, 1 + d)
        The contact's block of the Delassus matrix, in the order (n, t1[, t2]).
    inverse : array (1 + d, 1 + d)
        ``W``'s inverse, or NaN for a block too close to singular to stick reliably.
    b : array (1 + d,)
        The rest of the contact's local velocity, same order.
    mu : float
        Friction coefficient, >= 0.
    current : array (1 + d,)
        The current impulse: where the slip is not unique the one nearest it is kept, and the
        fallback starts from it.

    Returns
    -------
    array (1 + d,)
        ``P`` with ``K ∋ P _|_ (un + mu |ut|, ut) ∈ K*`` (the module's docstring gives the
        states and their sources).
    """
    P = _in_a_state(W, inverse, b, mu, current)
    return P if P.size else _projected(W, b, mu, current)


@_kernel
def _in_a_state(
    W: np.ndarray, inverse: np.ndarray, b: np.ndarray, mu: float, current: np.ndarray
) -> np.ndarray:
    """`solve_contact`'s take-off, stick or slip impulse; empty when no state holds."""
    P = np.zeros(b.size)
    if b[0] >= 0.0:
        return P
    if mu == 0.0:
        if W[0, 0] > 0.0:
            P[0] = -b[0] / W[0, 0]
        return P
    if np.isfinite(inverse[0, 0]):
        for a in range(b.size):
            for c in range(b.size):
                P[a] -= inverse[a, c] * b[c]
        if P[0] > 0.0 and _norm(P[1:]) <= mu * P[0]:
            return P
    return _slip(W, b, mu, current)


@_kernel
def _norm(x: np.ndarray) -> float:
    """The 2-norm of a short vector, by a loop (no BLAS call)."""
    total = 0.0
    for value in x:
        total += value * value
    return np.sqrt(total)


def one_contact(G: np.ndarray, q: np.ndarray, mu: float) -> np.ndarray | None:
    """The impulse of a one-contact problem ``u = G P + q`` in its exact state, or None.

    None when neither take-off, stick nor slip holds: no impulse in the Coulomb cone satisfies
    the law (Coulomb's law with kinematic restitution can have no solution when the normal
    and tangential directions are strongly coupled, as Painlevé's examples).
    """
    # As the compiled kernel's types are (`_warm_up`): no compilation in a solve.
    G, q = np.require(G, float, "CW"), np.require(q, float, "CW")
    with _whole(compiled()):
        P = _in_a_state(G, inverses(G[None])[0], q, float(mu), np.zeros(q.size))
    return P if P.size else None


@_kernel
def _sweep(
    indptr: np.ndarray,
    indices: np.ndarray,
    data: np.ndarray,
    blocks: np.ndarray,
    inverses: np.ndarray,
    q: np.ndarray,
    mu: np.ndarray,
    P: np.ndarray,
) -> float:
    """One Gauss-Seidel sweep over the contacts in place (FCLIB's order); ``|change of P|^2``.

    Explicit loops: numba hands ``@`` and fancy indexing of these small arrays to BLAS calls
    and temporaries, which cost more than the arithmetic.
    """
    size = blocks.shape[1]
    change = 0.0
    b, old = np.empty(size), np.empty(size)
    for j in range(mu.size):
        start = j * size
        for a in range(size):
            row = start + a
            total = q[row]
            for k in range(indptr[row], indptr[row + 1]):
                total += data[k] * P[indices[k]]
            b[a] = total
        for a in range(size):
            old[a] = P[start + a]
        for a in range(size):
            for c in range(size):
                b[a] -= blocks[j, a, c] * old[c]
        new = solve_contact(blocks[j], inverses[j], b, mu[j], old)
        for a in range(size):
            change += (new[a] - old[a]) ** 2
            P[start + a] = new[a]
    return change


@_kernel
def _blocks(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, size: int) -> np.ndarray:
    """The diagonal blocks (m, size, size) of a CSR matrix in FCLIB's order."""
    m = (indptr.size - 1) // size
    blocks = np.zeros((m, size, size))
    for j in range(m):
        for a in range(size):
            row = j * size + a
            for k in range(indptr[row], indptr[row + 1]):
                column = indices[k] - j * size
                if 0 <= column < size:
                    blocks[j, a, column] += data[k]
    return blocks


def inverses(blocks: np.ndarray) -> np.ndarray:
    """The inverse of each block, NaN for a block whose condition number exceeds `SINGULAR`."""
    regular = np.linalg.cond(blocks) < SINGULAR
    found = np.full_like(blocks, np.nan)
    found[regular] = np.linalg.inv(blocks[regular])
    return found


def solve_nsgs(
    W: Any, q: np.ndarray, mu: np.ndarray, dim: int, tol: float, start: np.ndarray | None = None
) -> GaussSeidelResult:
    """Coulomb's law ``K ∋ P _|_ uhat ∈ K*`` by nonsmooth Gauss-Seidel (module docstring).

    Parameters
    ----------
    W : array or scipy.sparse matrix (m*dim, m*dim)
        The Delassus operator in FCLIB's order (per contact: normal, then tangents), as given:
        it need not be symmetric.
    q : array (m*dim,)
        Local velocity without impulses (restitution included), same order.
    mu : array (m,)
        Friction coefficients, >= 0.
    dim : int
        2 (plane) or 3 (space).
    tol : float
        The FC3D error at which the sweeps stop.
    start : array (m*dim,), optional
        Initial impulses (zero by default).

    Returns
    -------
    GaussSeidelResult
        The impulses (FCLIB's order), the sweeps and their FC3D error. The error exceeds
        ``tol`` only when the iteration is stationary (module docstring).

    Raises
    ------
    BudgetExceeded
        When the solve's budget (steps: sweeps, or seconds) runs out first.
    """
    fast = compiled()
    m, size = len(mu), dim
    W = scipy.sparse.csr_matrix(W, dtype=float)
    if not W.has_canonical_format or not W.data.all():
        W = W.copy()
        W.sum_duplicates()
        W.eliminate_zeros()
    # C-contiguous and writable (a problem's arrays are read-only), as the types the kernels
    # are compiled for in `_warm_up`: a read-only array would compile them again in the solve.
    local_q, mu = np.require(q, float, "CW"), np.require(mu, float, "CW")
    rows = tuple(np.require(a, None, "CW") for a in (W.indptr, W.indices, W.data))
    with _whole(fast):
        blocks = _blocks(*rows, size)
    inverse = inverses(blocks)
    P = np.zeros(m * size) if start is None else np.array(start, dtype=float)
    spend, sweeps, gate, error, note = current_budget(), 0, tol, np.inf, ""
    reference, reference_sweep = np.inf, 0
    while True:
        spend.step("Gauss-Seidel sweeps", note)
        with _whole(fast):
            try:
                change = _sweep(*rows, blocks, inverse, local_q, mu, P)
            except np.linalg.LinAlgError:  # a block's inverse or an impulse overflowed
                raise SolverFailure(
                    f"Gauss-Seidel: sweep {sweeps + 1} met a number beyond double precision "
                    f"(a contact's block of W too small to invert, or |q| up to "
                    f"{float(np.abs(local_q).max()):.3g})"
                ) from None
        sweeps += 1
        light = np.sqrt(change) / max(float(np.linalg.norm(P)), TINY)
        if light <= gate or sweeps % CHECK_EVERY == 0:
            error = fc3d_error(W, local_q, mu, P)
            if error <= tol or change == 0.0:
                break
            if error < (1.0 - STALL_DROP) * reference:
                reference, reference_sweep = error, sweeps
            elif sweeps - reference_sweep >= max(STALL_SWEEPS, reference_sweep):
                break
            # The error is about proportional to the change: wait until it should be at tol.
            gate = min(gate, light * tol / error)
            note = f"last change of P {light:.3g}, last FC3D error {error:.3g}, tolerance {tol:g}"
    return GaussSeidelResult(P, sweeps, error)


def solve_polished(
    W: Any, q: np.ndarray, mu: np.ndarray, dim: int, tol: float, polish: bool
) -> tuple[np.ndarray, dict[str, Any]]:
    """`solve_nsgs` to ``tol``, then `cones.polish` (with ``polish``) where the sweeps stall.

    A polish (dense Newton steps on the contact states) of an answer already within ``tol``
    would cost more than the sweeps: it is tried only on an iteration that became stationary
    above ``tol``, and kept where it lowers the FC3D error. Returns the impulses (FCLIB's
    order) and the diagnostics of a law's answer (formulation, sweeps, polished, FC3D error).

    Raises
    ------
    SolverFailure
        When the sweeps became stationary above ``tol`` and the polish did not reach it.
    """
    m = len(mu)
    result = solve_nsgs(W, q, mu, dim, tol)
    P, error, polished = result.P, result.error, False
    if not error <= tol and polish:  # a NaN error is no answer either
        back = np.argsort(local_order(m, dim - 1))
        G, lawbench_q = scipy.sparse.csr_matrix(W)[back][:, back].toarray(), q[back]
        refined = cones.polish(G, lawbench_q, mu, dim - 1, P[back], True)
        if refined is not None:
            refined = refined[local_order(m, dim - 1)]
            refined_error = fc3d_error(W, q, mu, refined)
            if refined_error <= error:
                P, error, polished = refined, refined_error, True
    if not error <= tol:
        raise SolverFailure(
            f"Gauss-Seidel stationary after {result.sweeps} sweeps at FC3D error {error:.3g}, "
            f"above the tolerance {tol:g}{_rank_note(W)}"
        )
    diagnostics = {
        "formulation": "NSGS, exact local solver" + (" (numba)" if compiled() else ""),
        "solver_status": "converged",
        "iterations": result.sweeps,
        "sweeps": result.sweeps,
        "polished": polished,
        "fc3d_error": error,
    }
    return P, diagnostics


# The largest Delassus matrix whose rank a failure message states (an SVD, O(n^3)).
RANK_NOTE_MAX = 2000


def _rank_note(W: Any) -> str:
    """``'; W has rank r of n'`` for a singular Delassus matrix small enough to decompose.

    Gauss-Seidel's sweeps contract only where ``W`` is regular: on a singular one (more contact
    directions than the bodies' coordinates, as in granular packings) they can settle away
    from any solution, and the rank says so.
    """
    n = W.shape[0]
    if n > RANK_NOTE_MAX:
        return ""
    values = np.linalg.svd(scipy.sparse.csr_matrix(W).toarray(), compute_uv=False)
    rank = int((values > n * np.finfo(float).eps * values[0]).sum())
    return f"; W is singular, rank {rank} of {n}" if rank < n else ""
