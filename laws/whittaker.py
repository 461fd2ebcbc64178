"""Whittaker's law: Newton's normal restitution with Coulomb friction at the impulse level.

Source: E.T. Whittaker, *A treatise on the analytical dynamics of particles and rigid bodies*
(1904), as given by Brogliato, *An introduction to impact dynamics* (lectures, 2010), "Single
impact with Coulomb's friction, friction at the impulse level": Coulomb's law written with the
impulses, implicit in the post-impact slip, ``pt in -f pn sgn(vt+)``, with Newton's
``vn+ = -e vn-``; the three cases of a particle striking a wall (eq. 6); the rod striking the
ground (eqs. 7-8) and the energy gain of Kane and Levinson (1985, double pendulum) when
inertial coupling reverses the slip.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart, ``v+ = v- + M^-1 (Wn Pn + Wt Pt)``,
``ut = Wt.T v``; ``e`` is the contact's kinematic (Newton) coefficient. Per contact j:

- normal: ``0 <= un+_j + e_j min(un-_j, 0) _|_ Pn_j >= 0``; an approaching contact ends at
  ``un+ = -e un-``. A closed contact that separates before the impact (``un- >= 0``) receives
  no restitution term, only ``0 <= un+ _|_ Pn >= 0``: the choice of moreau's default
  (``separating='unilateral'``);
- friction: ``|Pt_j| <= mu_j Pn_j``, and ``Pt_j = -mu_j Pn_j ut+_j / |ut+_j|`` when
  ``ut+_j != 0`` (planar: ``Pt_j in -mu_j Pn_j sgn(ut+_j)``).

Modes of a contact: ``no impulse`` (Pn = 0), ``stick`` (ut+ = 0), ``slip +`` / ``slip -``
(planar, sign of ut+) or ``slip`` (spatial).

Formulations (``diagnostics['formulation']``):

- one contact: every mode in closed form, named by the mode of the answer ("closed form,
  stick", "closed form, slip", ...). In space the slip direction ``s`` solves
  ``(ut- D(s) + c (Gtn - mu Gtt s)) x s = 0`` with ``D(s) = Gnn - mu Gnt s`` and
  ``c = -(un- + e min(un-, 0))``: a trigonometric polynomial of degree 2 in the angle of ``s``,
  whose (at most four) roots are those of a quartic ("closed form, slip direction from a
  quartic"); every root is kept and checked;
- several planar contacts: the exact LCP in ``z = (Pn, Pt+, Pt-, lam)`` with ``Pt = Pt+ - Pt-``
  and the slip variable ``lam`` (`planar_friction_lcp`), solved by Lemke's method ("Lemke
  LCP");
- without friction (no tangential Jacobian, or mu = 0 everywhere): the unilateral LCP in Pn,
  moreau's default law ("closed form", "decoupled (diagonal Delassus)", "Lemke LCP");
- several spatial contacts: not treated (NotApplicable): the circular cone is not an LCP.

Uniqueness: one planar contact that approaches has exactly one solution whatever the
coupling: with Pn eliminated through the normal law, ut+ is an increasing affine function of Pt
(slope ``Gtt - Gnt^2 / Gnn > 0``) on the interval of admissible Pt (a half-line when
``mu |G_nt| >= G_nn``, G the contact Delassus matrix). With strong coupling
(``mu |G_nt| >= G_nn``) a contact at rest or separating can have two solutions (no impulse, or
an impulse that sticks or slips it), one spatial contact can have several even when it
approaches, and several contacts can have several or none; none was met only with dependent
contact directions (more of them than degrees of freedom), where the restitution and sticking
targets of different contacts can contradict each other.

Every solution is searched for: all modes of one contact, and all ``4^m`` mode combinations of
m planar contacts for ``m <= 4`` (`MAX_ENUMERATED`); beyond that ``diagnostics['uniqueness']``
is 'unchecked' and the answer is Lemke's. A mode whose linear system is singular (dependent
contacts) is searched by linear programming; for a spatial contact its least-norm impulses
are kept. Solutions are counted by their post-impact velocity. ``diagnostics['solutions']``
lists every solution found (modes, Pn, Pt, T+). Several: ``status`` is 'ambiguous' and the
answer is the one of least post-impact kinetic energy (the first in the listed order on a tie).
None: NotApplicable, naming the coupling of each contact (``diagnostics['coupling']``:
``mu |G_nt| / G_nn``, for several contacts ``sum_k mu_k |G_(n_j, t_k)| / G_(n_j, n_j)``) and
the rank of G when the contacts are dependent. Without friction the law has one post-impact
velocity (its Delassus matrix is positive semidefinite).

Energy: the change is the work of the impulses at the mean contact velocity,
``dT = (Pn.(un- + un+) + Pt.(ut- + ut+)) / 2``. Uncoupled contacts (``G_nt = 0``) that all
approach never gain energy for ``0 <= e <= 1``. Coupled ones can: the tangential impulse does
positive work when the slip reverses (the lectures' remark after eq. 9; Kane and Levinson's
double pendulum) or when sticking needs an impulse along the pre-impact slip (a rod striking a
rough floor with e close to 1). A known defect of the law, reported by the ``energy_gain``
check, never corrected here. A closed contact that separates before the impact and is dragged
into it can create energy too, as in moreau's law.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.optimize

from lawbench.core.errors import BudgetExceeded, InvalidProblem, NotApplicable, SolverFailure
from lawbench.core.law import LAWS, Law
from lawbench.core.metric import is_diagonal, kinetic_energy
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.tags import Tags
from lawbench.laws import _one_contact_batch
from lawbench.laws._claims import (
    PAOLI_DISCONTINUITY,
    RIGID_DISPERSION,
    SLIP_REVERSAL_GAIN,
    keeps_energy,
    separating_held,
)
from lawbench.numerics.lemke import RayTermination, lemke

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch

# Largest number of planar contacts whose 4^m mode combinations are enumerated.
MAX_ENUMERATED = 4
# Relative tolerance of the law's conditions on a candidate solution.
TOLERANCE = 1e-9
# The largest friction coefficient treated: the cone rows ``Pt -+ mu Pn`` are normalized by
# their norm ``sqrt(1 + mu^2)``, and the slip quartic's coefficients grow as mu, so beyond
# about 1e154 they leave double precision.
MU_RANGE = 1e150
CHOICE = "least post-impact kinetic energy (first listed on a tie)"
_PLANAR_SLIPS = (np.array([1.0]), np.array([-1.0]))


@dataclass(frozen=True)
class _Setup:
    """The law in contact coordinates: ``u(P) = bias + G P`` with ``P = (Pn, Pt)``.

    ``u`` holds ``un+ + e min(un-, 0)`` (m entries), then ``ut+`` (m*d entries); ``d`` is 0
    without friction.
    """

    problem: ImpactProblem
    G: np.ndarray
    bias: np.ndarray
    d: int
    speed: float
    impulse: float

    @classmethod
    def of(cls, problem: ImpactProblem, friction: bool) -> _Setup:
        G = problem.contact_delassus if friction else problem.delassus
        un = problem.un
        bias = un + problem.restitution("kinematic") * np.minimum(un, 0.0)
        if friction:
            bias = np.concatenate([bias, problem.ut])
        speed = max(float(np.abs(bias).max()), float(np.abs(un).max()), 1e-300)
        return cls(
            problem, G, bias, problem.d if friction else 0, speed, speed / G.diagonal().max()
        )

    @property
    def m(self) -> int:
        return self.problem.m

    def velocity_change(self, P: np.ndarray) -> np.ndarray:
        """Generalized velocity change ``M^-1 (Wn Pn + Wt Pt)`` of the impulses ``P``."""
        return self.problem.solve_mass((self.problem.W if self.d else self.problem.Wn) @ P)

    def split(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Normal impulses (m,) and tangential ones (m, d)."""
        return P[: self.m], P[self.m :].reshape(self.m, self.d)

    def coupling(self) -> list[float]:
        """``sum_k mu_k |G_(n_j, t_k)| / G_(n_j, n_j)`` per contact j: >= 1 is strong coupling.

        For one contact it is ``mu |G_nt| / G_nn``; for several, the other contacts' friction
        acting on contact j's normal rate counts too.
        """
        m, d = self.m, self.d
        blocks = self.G[:m, m:].reshape(m, m, d)
        return (np.linalg.norm(blocks, axis=2) @ self.problem.mu / self.G.diagonal()[:m]).tolist()


def planar_friction_lcp(problem: ImpactProblem) -> tuple[np.ndarray, np.ndarray]:
    """The LCP ``w = A z + b``, ``0 <= w _|_ z >= 0`` of the law at m planar contacts.

    Unknowns ``z = (Pn, Pt+, Pt-, lam)`` (4m), ``Pt = Pt+ - Pt-``; complementary pairs:
    ``un+ + e min(un-, 0) _|_ Pn``, ``lam + ut+ _|_ Pt+``, ``lam - ut+ _|_ Pt-`` and
    ``mu Pn - Pt+ - Pt- _|_ lam``. Slipping with ``ut+ > 0`` forces ``lam = ut+``, ``Pt- = mu Pn``
    and ``Pt+ = 0``; sticking leaves ``lam = 0`` and ``|Pt| <= mu Pn``.

    Raises
    ------
    InvalidProblem
        When the problem is not planar with a tangential Jacobian.
    """
    if problem.d != 1:
        raise InvalidProblem(f"planar_friction_lcp: d = {problem.d}, needs planar contacts")
    setup = _Setup.of(problem, friction=True)
    m, G = problem.m, setup.G
    Gnn, Gnt, Gtn, Gtt = G[:m, :m], G[:m, m:], G[m:, :m], G[m:, m:]
    eye, zero = np.eye(m), np.zeros((m, m))
    A = np.block(
        [
            [Gnn, Gnt, -Gnt, zero],
            [Gtn, Gtt, -Gtt, eye],
            [-Gtn, -Gtt, Gtt, eye],
            [np.diag(problem.mu), -eye, -eye, zero],
        ]
    )
    un_bias, ut = setup.bias[:m], setup.bias[m:]
    return A, np.concatenate([un_bias, ut, -ut, np.zeros(m)])


def _candidate(setup: _Setup, modes: tuple) -> np.ndarray | None:
    """Impulses of one mode combination, checked later; None when the mode is impossible.

    ``modes[j]`` is 'free' (no impulse), 'stick' (ut+ = 0), or a slip direction ``s`` (d,)
    with ``Pt_j = -mu_j Pn_j s``. The active rows of ``u(P) = 0`` form a square linear system
    in the unknown impulses ``x`` (``P = B x``). When it is singular (dependent contacts, more
    contact directions than degrees of freedom) its solutions form an affine family; for
    planar contacts the point of it deepest inside the mode's inequalities is found by linear
    programming (`_deepest_point`), for a spatial contact the least-norm one is kept.
    """
    m, d, size = setup.m, setup.d, setup.bias.size
    columns, rows = [], []
    for j, mode in enumerate(modes):
        if isinstance(mode, str) and mode == "free":
            continue
        column = np.zeros(size)
        column[j] = 1.0
        rows.append(j)
        if isinstance(mode, str):
            tangential = range(m + j * d, m + (j + 1) * d)
            columns.extend(np.eye(size)[k] for k in tangential)
            rows.extend(tangential)
        else:
            column[m + j * d : m + (j + 1) * d] = -setup.problem.contacts[j].mu * mode
        columns.append(column)
    if not columns:
        return np.zeros(size)
    B = np.column_stack(columns)
    A, b = setup.G[rows] @ B, -setup.bias[rows]
    x, _, rank, _ = np.linalg.lstsq(A, b, rcond=None)
    if rank == B.shape[1] or d == 2:
        return B @ x
    return _deepest_point(setup, modes, B, A, b)


def _deepest_point(
    setup: _Setup, modes: tuple, B: np.ndarray, A: np.ndarray, b: np.ndarray
) -> np.ndarray | None:
    """The impulses ``P = B x`` with ``A x = b`` farthest inside the planar modes' inequalities.

    Inequalities: ``Pn >= 0``; no impulse: ``un+ + e min(un-, 0) >= 0``; stick:
    ``|Pt| <= mu Pn``; slip: ``ut+`` of the mode's sign. Impulses are measured in
    ``setup.impulse`` and rates in ``setup.speed``; the margin ``t <= 1`` of the normalized rows
    is maximized (HiGHS). None when the equalities are inconsistent or the margin negative.
    """
    m, G, bias = setup.m, setup.G, setup.bias
    impulse_rows, rate_rows, rate_rhs = [], [], []
    for j, mode in enumerate(modes):
        normal, tangent = np.eye(2 * m)[j], np.eye(2 * m)[m + j]
        impulse_rows.append(-normal)
        if isinstance(mode, str) and mode == "free":
            rate_rows.append(-G[j])
            rate_rhs.append(bias[j])
        elif isinstance(mode, str):
            mu = setup.problem.contacts[j].mu
            impulse_rows.extend([tangent - mu * normal, -tangent - mu * normal])
        else:
            rate_rows.append(-mode[0] * G[m + j])
            rate_rhs.append(mode[0] * bias[m + j])
    scale = setup.impulse / setup.speed
    rate = np.array(rate_rows).reshape(-1, 2 * m)
    rows = np.vstack([np.array(impulse_rows) @ B, scale * rate @ B])
    rhs = np.concatenate([np.zeros(len(impulse_rows)), np.array(rate_rhs) / setup.speed])
    norms = np.linalg.norm(rows, axis=1)
    keep = norms > 0
    k = B.shape[1]
    result = scipy.optimize.linprog(
        np.append(np.zeros(k), -1.0),
        A_ub=np.column_stack([rows[keep], norms[keep]]),
        b_ub=rhs[keep],
        A_eq=np.column_stack([scale * A, np.zeros(len(b))]),
        b_eq=b / setup.speed,
        bounds=[(None, None)] * k + [(None, 1.0)],
        method="highs",
    )
    if result.status != 0 or result.x[-1] < -TOLERANCE:
        return None
    return B @ (setup.impulse * result.x[:k])


def _admissible(setup: _Setup, P: np.ndarray) -> bool:
    """Whether the impulses ``P`` satisfy every condition of the law, to ``TOLERANCE``."""
    if not np.isfinite(P).all():
        return False
    u = setup.bias + setup.G @ P
    Pn, Pt = setup.split(P)
    wn, ut = u[: setup.m], u[setup.m :].reshape(setup.m, setup.d)
    tol_u = TOLERANCE * setup.speed
    tol_p = TOLERANCE * max(setup.impulse, float(np.abs(P).max()))
    bound = setup.problem.mu * Pn if setup.d else np.zeros(setup.m)
    slip, tangential = np.linalg.norm(ut, axis=1), np.linalg.norm(Pt, axis=1)
    # Zero iff ut+ = 0 or Pt = -mu Pn ut+/|ut+|: Coulomb's direction on the cone boundary.
    direction = ut * bound[:, None] + slip[:, None] * Pt
    return bool(
        Pn.min() >= -tol_p
        and wn.min() >= -tol_u
        and np.all((Pn <= tol_p) | (np.abs(wn) <= tol_u))
        and np.all(tangential <= bound + tol_p)
        and np.all(
            np.linalg.norm(direction, axis=1)
            <= TOLERANCE * setup.speed * np.maximum(bound + tangential, setup.impulse)
        )
    )


def _modes(setup: _Setup, P: np.ndarray) -> list[str]:
    """Mode of each contact in the solution ``P``."""
    Pn, _ = setup.split(P)
    ut = (setup.bias + setup.G @ P)[setup.m :].reshape(setup.m, setup.d)
    labels = []
    for j in range(setup.m):
        if Pn[j] <= TOLERANCE * setup.impulse:
            labels.append("no impulse")
        elif setup.d == 0:
            labels.append("active")
        elif np.linalg.norm(ut[j]) <= TOLERANCE * setup.speed:
            labels.append("stick")
        elif setup.d == 1:
            labels.append("slip +" if ut[j, 0] > 0 else "slip -")
        else:
            labels.append("slip")
    return labels


def _solutions(setup: _Setup, candidates: list[np.ndarray | None]) -> list[np.ndarray]:
    """The admissible candidates, one per post-impact velocity, in the given order."""
    problem, kept, velocities = setup.problem, [], []
    norm = max(np.sqrt(2 * kinetic_energy(problem.M, problem.v)), 1e-300)
    for P in candidates:
        if P is None or not _admissible(setup, P):
            continue
        dv = setup.velocity_change(P)
        if all(np.sqrt((dv - w) @ problem.M @ (dv - w)) > 1e-8 * norm for w in velocities):
            kept.append(P)
            velocities.append(dv)
    return kept


def _enumerated(setup: _Setup, choices: tuple) -> list[np.ndarray | None]:
    """Candidates of every combination of the per-contact ``choices``."""
    return [_candidate(setup, modes) for modes in itertools.product(choices, repeat=setup.m)]


def _slip_directions(setup: _Setup) -> list[np.ndarray]:
    """Every slip direction of one spatial contact: roots of the quartic (see module doc).

    ``g(theta) = (ut- D(s) + c (Gtn - mu Gtt s)) x s`` is a trigonometric polynomial of
    degree 2; its Fourier coefficients are exact from 8 samples, and the roots of
    ``z^2 g = sum_k a_k z^(k+2)`` on the unit circle are its zeros. Each is polished by Newton's
    method. When ``g`` vanishes identically (``G_nt = 0``, isotropic ``Gtt``, ``ut- = 0``) no
    direction can slip, and none is returned.
    """
    G, mu = setup.G, setup.problem.contacts[0].mu
    gtn, Gtt, ut, c = G[1:, 0], G[1:, 1:], setup.bias[1:], -setup.bias[0]

    def g(theta: np.ndarray) -> np.ndarray:
        s = np.stack([np.cos(theta), np.sin(theta)])
        D = G[0, 0] - mu * gtn @ s
        a = np.outer(ut, D) + c * (gtn[:, None] - mu * Gtt @ s)
        return s[0] * a[1] - s[1] * a[0]

    a = np.fft.fft(g(2 * np.pi * np.arange(8) / 8)) / 8
    coefficients = a[[2, 1, 0, 7, 6]]
    scale = setup.speed * (G[0, 0] + np.abs(G).max())
    if np.abs(coefficients).max() <= 1e-14 * scale:
        return []
    orders = np.arange(-2, 3)
    directions = []
    for root in np.roots(coefficients):
        if abs(np.log(abs(root))) > 1e-4:
            continue
        theta = float(np.angle(root))
        for _ in range(20):
            z = np.exp(1j * orders * theta)
            value = float(np.real(a[orders] @ z))
            slope = float(np.real((1j * orders * a[orders]) @ z))
            if slope == 0.0 or abs(value / slope) < 1e-15:
                break
            theta -= value / slope
        directions.append(np.array([np.cos(theta), np.sin(theta)]))
    return directions


def _single_contact(setup: _Setup) -> list[np.ndarray | None]:
    """Candidates of one contact: no impulse, stick, every slip direction."""
    slips = _PLANAR_SLIPS if setup.d == 1 else tuple(_slip_directions(setup))
    return _enumerated(setup, ("free", "stick", *slips))


def _lemke_planar(setup: _Setup) -> tuple[np.ndarray | None, dict[str, Any]]:
    """Lemke's solution of `planar_friction_lcp` as impulses, or None with the reason."""
    m = setup.m
    try:
        result = lemke(*planar_friction_lcp(setup.problem))
    except BudgetExceeded:  # the solve's time ran out: no method follows
        raise
    except SolverFailure as exc:
        return None, {"lemke": str(exc)}
    z = result.z
    # The tangential impulse is a difference of pivoted variables, in the cone only to their
    # rounding: where no normal impulse acts that rounding alone would leave the cone.
    bound = setup.problem.mu * z[:m]
    Pt = np.clip(z[m : 2 * m] - z[2 * m : 3 * m], -bound, bound)
    return np.concatenate([z[:m], Pt]), {"pivots": result.pivots}


class Whittaker(Law):
    """Newton's normal law with Coulomb friction on the impulses, implicit in the slip."""

    name = "whittaker"
    summary = "Newton's restitution with Coulomb friction at the impulse level (Whittaker)"
    source = (
        "Whittaker 1904; Brogliato 2010, friction at the impulse level, eqs. (6)-(8); "
        "Kane and Levinson 1985"
    )
    tags = Tags(friction=True, several_contacts=True, spatial=True)
    fitted = ("e", "mu")
    separating_rule = (
        "a separating contact is held at un+ >= 0 without restitution, as in Moreau's "
        "unilateral law"
    )

    findings = (
        PAOLI_DISCONTINUITY,
        RIGID_DISPERSION,
        separating_held("energy_gain"),
        separating_held("energy_kept"),
        SLIP_REVERSAL_GAIN,
    )
    guarantees = (
        keeps_energy(
            "Brogliato 2010, Moreau's law: dT = sum Pn_j (un-_j + un+_j) / 2",
            "without friction the law is Moreau's: at e = 1 every contact that takes an impulse "
            "leaves with un+ = -un-",
        ),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        if not problem.frictional:
            return _frictionless(problem)
        if problem.d == 2 and problem.m > 1:
            raise NotApplicable(
                f"whittaker: {problem.m} spatial contacts; the impulse-level Coulomb law with "
                "circular cones is not an LCP and only one spatial contact is treated"
            )
        if problem.mu.max() > MU_RANGE:
            raise NotApplicable(
                f"whittaker: mu = {problem.mu.max():.3g}: its impulse-level cone leaves double "
                f"precision beyond mu = {MU_RANGE:g}"
            )
        setup = _Setup.of(problem, friction=True)
        extra: dict[str, Any] = {"coupling": setup.coupling()}
        first = None
        if problem.m == 1:
            candidates, checked = _single_contact(setup), True
        else:
            first, lemke_facts = _lemke_planar(setup)
            extra.update(lemke_facts)
            checked = problem.m <= MAX_ENUMERATED
            candidates = [] if first is None else [first]
            if checked:
                candidates += _enumerated(setup, ("free", "stick", *_PLANAR_SLIPS))
        solutions = _solutions(setup, candidates)
        if not solutions:
            raise _no_solution(setup, checked, extra)
        chosen = _choose(setup, solutions)
        modes = _modes(setup, chosen)
        if problem.m > 1:
            formulation = "Lemke LCP" if chosen is first else "mode enumeration"
        elif modes[0].startswith("slip") and setup.d == 2:
            formulation = "closed form, slip direction from a quartic"
        else:
            formulation = f"closed form, {modes[0].rstrip(' +-')}"
        uniqueness = "unchecked" if not checked else "unique" if len(solutions) == 1 else "several"
        return _outcome(setup, chosen, solutions, formulation, uniqueness, extra)

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """One contact: every mode in closed form for every problem, the least energy chosen.

        As `_resolve` chooses among the solutions; a problem without a solution, or whose modes
        need more than a closed form, is left to it (`lawbench.laws._one_contact_batch`).
        """
        if batch.m > 1:
            return None
        un = batch.un
        bias = un + batch.restitution("kinematic") * np.minimum(un, 0.0)
        found = _one_contact_batch.solutions(batch, bias, TOLERANCE)
        return found.least_energy(), "closed form (batch)"


def _choose(setup: _Setup, solutions: list[np.ndarray]) -> np.ndarray:
    """The solution of least post-impact kinetic energy; the first one on a tie."""
    return min(solutions, key=lambda P: _energy_after(setup, P))


def _energy_after(setup: _Setup, P: np.ndarray) -> float:
    return kinetic_energy(setup.problem.M, setup.problem.v + setup.velocity_change(P))


def _no_solution(setup: _Setup, checked: bool, extra: dict[str, Any]) -> Exception:
    """NotApplicable when every mode was checked, SolverFailure when Lemke alone failed.

    The reason names the coupling of each contact and, when the contact directions are
    dependent (more of them than degrees of freedom), the rank of the contact Delassus matrix:
    then the restitution and sticking targets of different contacts can contradict each other.
    """
    coupling = ", ".join(f"{value:.3g}" for value in extra["coupling"])
    strong = "strong" if max(extra["coupling"]) >= 1 else "weak"
    reason = f"{strong} normal-tangential coupling, mu |G_nt| / G_nn = {coupling}"
    if setup.m > 1:
        reason += " (summed over contacts)"
    rank, size = int(np.linalg.matrix_rank(setup.G)), setup.G.shape[0]
    if rank < size:
        reason += (
            f"; dependent contact directions (contact Delassus matrix of rank {rank} < {size})"
        )
    if not checked:
        return SolverFailure(
            f"whittaker: {extra.get('lemke', 'Lemke answer inadmissible')}; existence is not "
            f"checked beyond {MAX_ENUMERATED} contacts ({reason})"
        )
    return NotApplicable(f"whittaker: no solution in any mode ({reason})")


def _outcome(
    setup: _Setup,
    chosen: np.ndarray,
    solutions: list[np.ndarray],
    formulation: str,
    uniqueness: str,
    extra: dict[str, Any],
) -> Outcome:
    """The outcome of ``chosen``, with every solution listed in the diagnostics."""
    listed = []
    for P in solutions:
        Pn, Pt = setup.split(P)
        listed.append(
            {
                "modes": _modes(setup, P),
                "Pn": Pn.tolist(),
                "Pt": Pt.ravel().tolist(),
                "T_plus": _energy_after(setup, P),
            }
        )
    diagnostics = {
        "formulation": formulation,
        "solutions": listed,
        "uniqueness": uniqueness,
        **extra,
    }
    status = "ok"
    if len(solutions) > 1:
        status, diagnostics["choice"] = "ambiguous", CHOICE
    Pn, Pt = setup.split(chosen)
    return Outcome.from_impulses(
        setup.problem, Pn, Pt.ravel() if setup.d else None, status=status, diagnostics=diagnostics
    )


def _frictionless(problem: ImpactProblem) -> Outcome:
    """The unilateral law ``0 <= un+ + e min(un-, 0) _|_ Pn >= 0``: one post-impact velocity."""
    setup = _Setup.of(problem, friction=False)
    G, bias, extra = setup.G, setup.bias, {}
    if is_diagonal(G):
        Pn = np.maximum(-bias / np.diag(G), 0.0)
        formulation = "closed form" if problem.m == 1 else "decoupled (diagonal Delassus)"
    else:
        try:
            result = lemke(G, bias)
        except RayTermination as exc:
            raise NotApplicable(
                f"whittaker: no solution ({exc}); the Delassus matrix is positive "
                "semidefinite, so ray termination proves the contacts' conditions incompatible"
            ) from None
        Pn, formulation, extra = result.z, "Lemke LCP", {"pivots": result.pivots}
    return _outcome(setup, Pn, [Pn], formulation, "unique", extra)


LAWS.register(Whittaker())
