"""Impulses in Coulomb cones: the second-order cone QP of the frictional laws, for clarabel.

The unknown is the contact impulse ``P = (Pn, Pt)`` ordered as the contact Delassus matrix:
the m normal components first, then the m*d tangential ones (contact j's are ``m + j*d ...
m + j*d + d - 1``). Contact j's impulse lies in its Coulomb cone
``K_j = {|Pt_j| <= mu_j Pn_j}`` (for ``mu_j = 0``: ``Pn_j >= 0`` and ``Pt_j = 0``). The problem

    min  P.G P / 2 + q.P   subject to  P_j in K_j for every contact j,

with ``G`` symmetric positive semidefinite, has the optimality conditions
``K_j ∋ P_j _|_ (G P + q)_j ∈ K*_j``, the dual cone being ``K*_j = {mu_j |w_t| <= w_n}``.
clarabel solves ``min x.P x / 2 + c.x`` subject to ``A x + s = b``, ``s`` in a product of cones:
here ``b = 0`` and the slack of contact j is ``s_j = (mu_j Pn_j, Pt_j)`` in the second-order
cone ``SecondOrderConeT(1 + d)``; a frictionless contact gets ``NonnegativeConeT(1)`` for
``Pn_j`` and ``ZeroConeT(d)`` for ``Pt_j``.

`polish` refines an interior-point answer: each contact's state (no impulse, impulse inside
the cone, impulse on its boundary) is read from the answer and the equations of that state are
solved by Newton's method, so the direction of a slipping impulse does not carry the square
root of the solver's tolerance. `residual` measures how far an answer is from the cone
complementarity conditions.
"""

from __future__ import annotations

from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.sparse

from lawbench.core.errors import SolverFailure
from lawbench.core.guards import current_budget
from lawbench.core.mechanics import project
from lawbench.core.metric import binary_scale
from lawbench.numerics.solvers import clarabel_settings

NEWTON_STEPS = 30
# A slip speed below this fraction of the largest pre-impact speed is read as no slip.
ZERO_SLIP = 1e-6
EPS = np.finfo(float).eps


@dataclass(frozen=True)
class ConeResult:
    """Impulses ``P`` (normal then tangential) of a cone QP, with clarabel's facts."""

    P: np.ndarray
    status: str
    iterations: int
    polished: bool


def solve_cone_qp(
    G: np.ndarray,
    q: np.ndarray,
    mu: np.ndarray,
    d: int,
    tol: float,
    refine: bool = True,
    max_iter: int = 200,
) -> ConeResult:
    """Solve ``min P.G P / 2 + q.P`` over the Coulomb cones with clarabel.

    Parameters
    ----------
    G : array (m*(1+d), m*(1+d))
        Symmetric positive semidefinite matrix (the contact Delassus matrix).
    q : array (m*(1+d),)
        Linear term, normal components first.
    mu : array (m,)
        Friction coefficients, >= 0.
    d : int
        Tangential directions per contact (1 planar, 2 spatial).
    tol : float
        clarabel's tolerances (gap and feasibility).
    refine : bool
        Whether to `polish` clarabel's answer.
    max_iter : int
        Bound on clarabel's iterations.

    Returns
    -------
    ConeResult
        clarabel's answer, polished when asked and successful.

    Raises
    ------
    SolverFailure
        When clarabel's status is not 'Solved' and its answer could not be polished.
    """
    m, size = len(mu), len(q)
    # Scaled to unit magnitudes (by powers of two, exact): clarabel's tolerances are absolute
    # as well as relative, and a problem whose velocities are 1e-7 m/s ended 'Solved' with its
    # complementarity broken by half the approach speed. P = (s / g) P^ solves the scaled one.
    g, s = binary_scale(np.abs(G).max()), binary_scale(np.abs(q).max())
    G, q = G / g, q / s
    # Contact j's slack -A P is (mu_j Pn_j, Pt_j), or (Pn_j, Pt_j) when it is frictionless.
    cols, values, cones = [], [], []
    for j in range(m):
        cols += [j, *range(m + j * d, m + (j + 1) * d)]
        values += [-mu[j] if mu[j] > 0 else -1.0] + [-1.0] * d
        if mu[j] > 0:
            cones.append(clarabel.SecondOrderConeT(1 + d))
        else:
            cones += [clarabel.NonnegativeConeT(1), clarabel.ZeroConeT(d)]
    A = scipy.sparse.csc_matrix((values, (range(size), cols)), shape=(size, size))
    solver = clarabel.DefaultSolver(
        scipy.sparse.csc_matrix(np.triu(G)),
        np.asarray(q, dtype=float),
        A,
        np.zeros(size),
        cones,
        clarabel_settings(tol, max_iter),
    )
    solution = solver.solve()
    P, status = np.array(solution.x), str(solution.status)
    exact = polish(G, q, mu, d, P, False) if refine and np.isfinite(P).all() else None
    if exact is None and status == "MaxTime":
        current_budget().out_of_time()
    if exact is None and status != "Solved":
        raise SolverFailure(f"clarabel status {status} after {solution.iterations} iterations")
    answer = (P if exact is None else exact) * (s / g)
    return ConeResult(answer, status, solution.iterations, exact is not None)


def split(x: np.ndarray, m: int, d: int) -> tuple[np.ndarray, np.ndarray]:
    """Normal components (m,) and tangential components (m, d) of a contact vector."""
    return x[:m], x[m:].reshape(m, d)


def modified_velocity(
    G: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int, P: np.ndarray, coupled: bool
) -> np.ndarray:
    """``G P + q``, plus ``mu_j |(G P + q)_t,j|`` on the normal components when ``coupled``.

    With ``coupled`` this is De Saxce's modified velocity, whose cone complementarity with
    ``P`` is Coulomb's law; without, the velocity of the cone QP itself.
    """
    u = G @ P + q
    if coupled:
        m = len(mu)
        u[:m] += mu * np.linalg.norm(split(u, m, d)[1], axis=1)
    return u


def residual(
    G: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int, P: np.ndarray, coupled: bool
) -> float:
    """Largest natural residual ``|P_j - proj_K_j(P_j - u_j / G_jj)|`` over the contacts.

    Zero exactly when ``K_j ∋ P_j _|_ u_j ∈ K*_j`` for every contact, ``u`` the
    `modified_velocity`; in impulse units.
    """
    m = len(mu)
    Pn, Pt = split(P, m, d)
    un, ut = split(modified_velocity(G, q, mu, d, P, coupled), m, d)
    stiffness = np.diag(G)[:m]
    stiffness = np.where(stiffness > 0, stiffness, stiffness.max())
    worst = 0.0
    for j in range(m):
        rho = 1.0 / stiffness[j]
        normal, tangential = project(Pn[j] - rho * un[j], Pt[j] - rho * ut[j], mu[j])
        worst = max(worst, abs(Pn[j] - normal), float(np.abs(Pt[j] - tangential).max()))
    return worst


def _states(
    G: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int, P: np.ndarray, coupled: bool
) -> list[str]:
    """Each contact's state read from an approximate solution: 'free', 'stick' or 'slip'.

    Primal ``x = (mu Pn, Pt)`` and dual ``z = (un / mu, ut)`` are complementary in the
    second-order cone; their spectral values ``x0 -+ |x_t|`` say which of them vanishes
    ('free': x, 'stick': z) or whether both lie on the boundary ('slip'). ``G_jj`` converts
    impulses to velocities so the comparison does not depend on units.
    """
    m = len(mu)
    Pn, Pt = split(P, m, d)
    un, ut = split(modified_velocity(G, q, mu, d, P, coupled), m, d)
    scale = max(float(np.abs(q).max()), 1e-300)
    states = []
    for j in range(m):
        g = G[j, j]
        if mu[j] == 0:
            states.append("free" if g * Pn[j] < un[j] else "stick")
            continue
        x0, xt = g * mu[j] * Pn[j], g * float(np.linalg.norm(Pt[j]))
        z0, zt = un[j] / mu[j], float(np.linalg.norm(ut[j]))
        if x0 + xt < z0 - zt:
            states.append("free")
        elif z0 + zt < x0 - xt or zt <= ZERO_SLIP * scale:
            # A slip speed within the interior point's accuracy gives no slip direction: the
            # contact sticks (the residual test of `polish` then decides).
            states.append("stick")
        else:
            states.append("slip")
    return states


def _fixed(mu: np.ndarray, d: int, states: list[str]) -> np.ndarray:
    """Mask of the impulse components the states set to zero.

    Every component of a free contact, and the tangential ones of a frictionless contact.
    """
    m = len(mu)
    fixed = np.zeros(m * (1 + d), dtype=bool)
    for j, state in enumerate(states):
        tangential = slice(m + j * d, m + (j + 1) * d)
        fixed[j] = state == "free"
        fixed[tangential] = state == "free" or mu[j] == 0
    return fixed


def _newton_system(
    G: np.ndarray,
    q: np.ndarray,
    mu: np.ndarray,
    d: int,
    P: np.ndarray,
    coupled: bool,
    states: list[str],
) -> tuple[np.ndarray, np.ndarray]:
    """Equations of the given contact states at ``P`` and their Jacobian.

    'stick': ``u_j = 0``; 'slip': ``un_j = mu_j |ut_j|`` (0 when ``coupled``) and
    ``Pt_j = -mu_j Pn_j ut_j / |ut_j|``; an active frictionless contact: ``un_j = 0``. The rows
    of the components `_fixed` sets to zero are left at zero.
    """
    m = len(mu)
    u = G @ P + q
    F, J = np.zeros_like(P), np.zeros_like(G)
    for j, state in enumerate(states):
        normal, tangential = j, slice(m + j * d, m + (j + 1) * d)
        if state == "free":
            continue
        F[normal], J[normal] = u[normal], G[normal]
        if mu[j] == 0:
            continue
        if state == "stick":
            F[tangential], J[tangential] = u[tangential], G[tangential]
            continue
        ut = u[tangential]
        speed = max(float(np.linalg.norm(ut)), np.finfo(float).tiny)
        t = ut / speed
        if not coupled:
            F[normal] -= mu[j] * speed
            J[normal] -= mu[j] * t @ G[tangential]
        F[tangential] = P[tangential] + mu[j] * P[normal] * t
        J[tangential] = mu[j] * P[normal] * (np.eye(d) - np.outer(t, t)) / speed @ G[tangential]
        J[tangential, m + j * d : m + (j + 1) * d] += np.eye(d)
        J[tangential, normal] += mu[j] * t
    return F, J


def polish(
    G: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int, P: np.ndarray, coupled: bool
) -> np.ndarray | None:
    """Solve the contact states of an approximate cone solution exactly.

    Newton's method on the equations of the states `_states` reads from ``P``, the components
    they set to zero held at zero (least squares steps, so dependent contacts get the
    least-norm correction). Returns the refined impulses when their `residual` is no larger
    than that of ``P``, else None.
    """
    states = _states(G, q, mu, d, P, coupled)
    free = ~_fixed(mu, d, states)
    exact = np.where(free, P, 0.0)
    worst = np.inf
    for _ in range(NEWTON_STEPS):
        # A slip whose speed Newton's steps drive to zero leaves its direction undecided: the
        # approximate solution then stands.
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            F, J = _newton_system(G, q, mu, d, exact, coupled, states)
        if not (np.isfinite(F).all() and np.isfinite(J).all()):
            return None
        # Newton's method on equations that hold converges quadratically; equations that a
        # singular system cannot meet stall, and each further dense step costs O(n^3) for
        # nothing: stop once a step no longer halves the largest equation's residual.
        largest = float(np.abs(F[free]).max()) if free.any() else 0.0
        if largest > worst / 2:
            break
        worst = largest
        step = np.linalg.lstsq(J[np.ix_(free, free)], -F[free], rcond=None)[0]
        exact[free] += step
        if not step.size or np.abs(step).max() <= 4 * EPS * max(np.abs(exact).max(), 1e-300):
            break
    if not np.isfinite(exact).all():
        return None
    if residual(G, q, mu, d, exact, coupled) <= residual(G, q, mu, d, P, coupled):
        return exact
    return None
