"""Moreau's impact law: projection on the tangent cone in the kinetic metric, Coulomb cones.

Source: J.J. Moreau (1983, 1985, 1988) as given by Brogliato, *An introduction to impact
dynamics* (2010), equations (16)-(17):
``v+ = -e v- + (1 + e) argmin { |z - v-|_M^2 / 2 : Wn.T z >= 0 }`` for one coefficient ``e``,
and per contact ``0 <= un+ + E un- _|_ Pn >= 0`` with ``E`` the kinematic coefficients.
With friction, Moreau's (1988) contact law in the local velocities ``u+ = W.T v+``
(``W = [Wn, Wt]``) and impulses ``P_j = (Pn_j, Pt_j)`` in the Coulomb cones
``K_j = {|Pt_j| <= mu_j Pn_j}``, written with De Saxce and Feng's (1991) bipotential:
the modified velocity ``uhat_j = (un+_j + e_j r_j + mu_j |ut+_j|, ut+_j)`` satisfies
``K_j ∋ P_j _|_ uhat_j ∈ K*_j``, ``K*_j = {mu_j |w_t| <= w_n}`` the dual cone. This is
exactly Coulomb's law with the normal law above: no impulse and ``un+_j + e_j r_j >= 0``
(free), ``un+_j + e_j r_j = 0`` with ``ut+_j = 0`` and ``|Pt_j| <= mu_j Pn_j`` (stick), or
``un+_j + e_j r_j = 0`` with ``Pt_j = -mu_j Pn_j ut+_j / |ut+_j|`` (slip). Acary, Cadoux,
Lemarechal and Malick (ZAMM 91, 2011) solve it as a fixed point over convex problems, and
Anitescu (Math. Program. 105, 2006) drops the term ``mu_j |ut+_j|``, a convex relaxation.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart; ``ut = Wt.T v``, contact j's
tangential columns ``j*d ... j*d + d - 1`` (``d = 1`` planar, 2 spatial); ``Pt_j`` opposes the
post-impact slip ``ut+_j``; ``r_j`` is the restituted gap rate (option ``separating``): the
restitution acts on the normal direction only.

A closed contact that already separates before the impact (``un- > 0``) lies outside the law's
premise (``v- in -T(q)``: every closed contact approaching or at rest), so the law must say what
it receives. Option ``separating``:

- ``unilateral`` (default): no restitution term, only ``0 <= un+ _|_ Pn >= 0``. The law solved
  is ``0 <= un+ + E min(un-, 0) _|_ Pn >= 0``: admissible with non-negative impulses always.
  With the term, the contact would be allowed to approach after the impact at ``-e un-``.
- ``restitution``: the formulas above as written, the term ``E un-`` on every closed contact.
  For one coefficient this is the cone projection, which never creates energy for
  ``0 <= e <= 1``, but its outcome can approach at a contact that separated.

Energy: ``dT = sum_j Pn_j (un-_j + un+_j) / 2``. When no closed contact separates this is
``sum_j (1 - e_j) Pn_j un-_j / 2 <= 0`` for both choices. A separating contact with a positive
impulse adds ``Pn_j un-_j / 2 > 0`` (``unilateral``) or ``(1 - e_j) Pn_j un-_j / 2``
(``restitution``): such a contact, dragged into the impact by its neighbours, can create
energy. Neither choice is both admissible and dissipative on every scene; the checks
``admissible`` and ``energy_gain`` report which property fails.

Formulations (``diagnostics['formulation']``). Without friction (no ``Wt``, or every ``mu = 0``):
closed form for one contact, decoupled for a diagonal Delassus matrix, the LCP in the impulses
solved exactly by active-set enumeration up to ``ENUMERATION_MAX`` contacts
(`lawbench.numerics.solvers.enumerate_lcp`; for one coefficient its solution is ``(1 + e)`` times
the plastic projection's), and beyond that the cone projection (a QP in the velocities, solved with
clarabel) for one coefficient when no closed contact separates, or the LCP in the impulses (a QP in
``Pn >= 0``, solved with clarabel) otherwise; where clarabel fails on that LCP, the same law as a
projection in the coordinates where the kinetic metric is the identity ("projection in the kinetic
metric (clarabel)", `lawbench.numerics.solvers.project_in_kinetic_metric`). Each clarabel answer is
polished on its active set, found by principal pivoting where clarabel's does not hold
(`lawbench.numerics.active_sets`): bodies of masses 1e9 and 1 leave an interior point's answer
right on the heavy bodies only. With friction, the second-order cone QP in the
impulses ``min P.G P / 2 + (q + s).P`` over the cones ``K_j`` (``G`` the contact Delassus matrix,
``q = u- + (E r, 0)``, ``s`` on the normal components), solved with clarabel
(`lawbench.numerics.cones`). A sparse problem (`ImpactProblem.sparse`, long chains) stays sparse on
the frictionless path, from the Delassus matrix to clarabel and the polish's block solve, so a chain
costs time linear in its length; with friction it is solved dense. Option ``friction``:

- ``coulomb`` (default, "SOCP fixed point (clarabel)"): the exact law. Starting from
  ``s = 0``, each step fixes ``s_j = mu_j |ut+_j|`` from the previous solution and solves the
  convex problem, until ``s`` changes by less than ``tol`` times the largest ``|q|``. Its
  optimality conditions are then De Saxce's. The iteration need not converge: the law may
  have several solutions or none when normal and tangential directions are strongly coupled,
  and even where it has one the plain iterates can cycle between two values; past 20 steps the
  update is averaged (``s <- (s + mu |ut+|) / 2``), which breaks such cycles. More than
  ``max_steps`` steps raise `BudgetExceeded` with the count.
- ``relaxed`` ("SOCP relaxed (clarabel)"): one convex problem with ``s = 0``, Anitescu's
  relaxation. Its conditions are ``un+_j + e_j r_j >= mu_j |ut+_j|`` instead of ``>= 0``: a
  slipping contact leaves with the extra normal rate ``mu_j |ut+_j|`` (it may separate where
  Coulomb's law keeps it closed); sticking and free contacts are as in Coulomb's law.

Option ``method`` chooses the solver of the exact frictional law (``friction="coulomb"``); the
frictionless formulations above do not depend on it:

- ``fixed_point``: the fixed point over cone QPs above.
- ``nsgs`` ("NSGS, exact local solver"): nonsmooth Gauss-Seidel over the contacts (Jean 1999;
  Acary, Brémond and Huber 2018), each contact's local problem solved exactly in its take-off,
  stick or slip state (`lawbench.numerics.gauss_seidel`), until the FC3D error of the impulses
  is at most ``tol``; a sweep is one of the ``max_steps`` steps. ``polish`` then refines the
  answer on its contact states and keeps the refinement where its FC3D error is no larger.
  An iteration that becomes stationary above ``tol`` raises `SolverFailure`. It solves Coulomb's
  law only (``friction="relaxed"`` raises `InvalidProblem`). Far cheaper per step than a cone
  QP, it can stall where the Delassus matrix is singular (more contact directions than
  coordinates), where the fixed point's interior-point steps still find the contact states.
  Diagnostics: ``sweeps`` (and ``iterations``, the same), ``polished``, ``fc3d_error``.
- ``auto`` (default): at one contact Gauss-Seidel's exact local solver (take-off, stick or
  slip in closed form); the fixed point on an impact of 2 to ``FIXED_POINT_MAX`` contacts,
  where a cone QP is cheap and settles the cases of several solutions; Gauss-Seidel with the
  polish on a larger impact and in contact space, then the fixed point where the sweeps become
  stationary above ``tol`` or run out of their bound: Acary, Brémond and Huber's comparison of
  FC3D solvers (NSGS with an exact local solver the robust choice on FCLIB's large problems)
  and Siconos' default. Diagnostics name the ``method`` that answered and, under ``after``,
  the failures it followed.

Option ``max_steps`` bounds each method's steps; at its default 0 the problem's size sets them:
``FIXED_POINT_STEPS`` cone QPs, and ``SWEEPS_PER_CONTACT`` sweeps per contact (at least
``SWEEPS_MIN``), since a sweep carries information one contact further.

In contact space (`Law.solve_contact`: FCLIB's local form, ``W``, ``q`` and ``mu`` as a file
holds them, the impact with ``e = 0``) every method solves Coulomb's law on ``W`` as given:
Gauss-Seidel sweeps it, and the fixed point's cone QPs take its symmetric part while the rest,
``skew = W - (W + W.T) / 2``, joins the friction term in the linear term they iterate
(``q + (mu |ut+|, 0) + skew P``); at the fixed point the QP's conditions are De Saxce's on
``W`` itself. A Delassus matrix of a mechanical system is symmetric; files from the field can
be asymmetric by 1e-3, and Anitescu's relaxation, one convex problem, refuses them.

An answer that leaves a contact approaching (``un+ + e r`` below ``-sqrt(tol)`` of the largest
local velocity) breaks the normal law: with ``mu`` near 1e300 the modified velocity loses ``un``
to rounding and a zero impulse passes the cone conditions. With one contact the law's states
are then enumerated exactly (take-off, stick, slip: `lawbench.numerics.gauss_seidel.one_contact`)
and the one that holds is the answer; when none holds, as on the lamina with ``mu |h0| > |f0|``
and ``e > 0``, the law has no solution and raises `NotApplicable`. With several contacts it is a
`SolverFailure`.

``polish`` refines each cone QP's answer and the final one on the contact states they show
(Newton's method on the equations of each state) and keeps a refinement when it satisfies the
cone conditions better; an answer clarabel only 'AlmostSolved' must be refined or raises
`SolverFailure`. Diagnostics: ``fixed_point_steps`` (cone QPs solved), ``iterations``
(clarabel's, summed over them), ``solver_status`` (the last one's), ``polished``.

With ``e = 0`` the exact law never creates energy, ``dT = -sum_j mu_j Pn_j |ut+_j| - P.G P / 2``;
with ``e > 0`` it can, like Whittaker's law (the same law at one contact): on the falling rod
and the double pendulum the slip reverses and ``-e Pn un-`` outweighs the losses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.checks.regions import option, separating_contact
from lawbench.core.contact import ContactProblem
from lawbench.core.errors import BudgetExceeded, InvalidProblem, NotApplicable, SolverFailure
from lawbench.core.guards import current_budget
from lawbench.core.law import LAWS, Law
from lawbench.core.metric import as_array
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.core.verdicts import Claim
from lawbench.laws import _one_contact_batch
from lawbench.laws._claims import (
    PAOLI_DISCONTINUITY,
    RIGID_DISPERSION,
    SLIP_REVERSAL_GAIN,
    keeps_energy,
    separating_held,
)
from lawbench.laws.moreau.answers import refuse_cancelling, refuse_outside_cones
from lawbench.laws.moreau.frictionless import projected
from lawbench.laws.moreau.methods import (
    FIXED_POINT_MAX,
    FIXED_POINT_STEPS,
    SWEEPS_MIN,
    SWEEPS_PER_CONTACT,
    in_turn,
    methods_for,
    out_of_time,
)
from lawbench.numerics import cones
from lawbench.numerics.gauss_seidel import (
    compiled,
    error_of,
    in_local_order,
    local_order,
    one_contact,
    solve_polished,
)
from lawbench.numerics.solvers import (
    ENUMERATION_MAX,
    LCPResult,
    enumerate_lcp,
    project_in_kinetic_metric,
    solve_lcp,
)

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch


class Moreau(Law):
    """Moreau's law: ``0 <= un+ + E min(un-, 0) _|_ Pn >= 0``; Coulomb cones with friction."""

    name = "moreau"
    summary = (
        "Moreau's law: cone projection in the kinetic metric, LCP per contact; Coulomb cones "
        "as second-order cones (clarabel)"
    )
    source = (
        "Moreau 1988; Brogliato 2010, eqs. (16)-(17); De Saxce and Feng 1991; Acary et al. "
        "2011; Anitescu 2006"
    )
    tags = Tags(friction=True, several_contacts=True, spatial=True, accuracy_knob="tol")
    fitted = ("e", "mu")
    takes_sparse = True
    # Its frictionless impulses solve the LCP that clarabel and Siconos' Lemke are timed on.
    bench_roles = ("lcp",)

    def prepare(self, problem: object = None) -> None:
        """Compile the Gauss-Seidel kernels (`compiled`) where a solve may sweep: with friction."""
        if problem is None or getattr(problem, "frictional", True):
            compiled()

    def rule_for_separating(self, options: dict[str, Any]) -> str:
        """The rule of option ``separating``."""
        if options["separating"] == "unilateral":
            return "a separating contact is held at un+ >= 0 without restitution (e min(un-, 0))"
        return "every closed contact is restituted, un+ >= -e un-, a separating one too"

    options = (
        Spec(
            "tol",
            1e-10,
            "clarabel's tolerances (gap and feasibility); with friction also the fixed point's "
            "(change of mu |ut+| over the largest local velocity)",
            low=0.0,
            high=1e-2,
            low_open=True,
        ),
        Spec(
            "polish",
            True,
            "solve clarabel's active set (with friction: contact states) exactly",
            kind="bool",
        ),
        Spec(
            "separating",
            "unilateral",
            "what a closed contact separating before the impact receives",
            kind="str",
            choices=("unilateral", "restitution"),
        ),
        Spec(
            "friction",
            "coulomb",
            "Coulomb's law exactly (fixed point over cone QPs) or Anitescu's convex relaxation",
            kind="str",
            choices=("coulomb", "relaxed"),
        ),
        Spec(
            "method",
            "auto",
            "the solver of the frictional problem: fixed point over cone QPs (clarabel), "
            "nonsmooth Gauss-Seidel with an exact solver per contact, or auto: the fixed point "
            f"on 2 to {FIXED_POINT_MAX} contacts of an impact, Gauss-Seidel on one, beyond and "
            "in contact space, then the fixed point where the sweeps stall or run out (Acary, "
            "Bremond and "
            "Huber 2018; Siconos' default solver is NSGS)",
            kind="str",
            choices=("auto", "fixed_point", "nsgs"),
        ),
        Spec(
            "max_steps",
            0,
            "bound on the steps of each method: cone QPs of the fixed point, sweeps of "
            f"Gauss-Seidel; 0 follows the problem's size: {FIXED_POINT_STEPS} cone QPs, "
            f"{SWEEPS_PER_CONTACT} sweeps per contact (at least {SWEEPS_MIN})",
            kind="int",
            low=0,
        ),
    )

    findings = (
        PAOLI_DISCONTINUITY,
        RIGID_DISPERSION,
        separating_held("energy_gain", separating_contact & option("separating", "unilateral")),
        separating_held("energy_kept", separating_contact & option("separating", "unilateral")),
        Claim(
            "admissible",
            separating_contact & option("separating", "restitution"),
            "Brogliato 2010, Moreau's law (premise v- in -T(q))",
            "the cone projection restitutes the separating contact's rate too, and can leave it "
            "approaching after the impact",
        ),
        SLIP_REVERSAL_GAIN,
    )
    guarantees = (
        keeps_energy(
            "Brogliato 2010, Moreau's law: dT = sum Pn_j (un-_j + un+_j) / 2",
            "at e = 1 every contact that takes an impulse leaves with un+ = -un-, so each term "
            "of dT vanishes",
        ),
    )

    @staticmethod
    def _refuse_relaxed_nsgs(options: dict[str, Any]) -> None:
        if options["method"] == "nsgs" and options["friction"] == "relaxed":
            raise InvalidProblem(
                "moreau: method 'nsgs' solves Coulomb's law exactly; Anitescu's relaxation "
                "(friction 'relaxed') is solved by method 'fixed_point'"
            )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        self._refuse_relaxed_nsgs(options)
        e, un = problem.restitution("kinematic"), problem.un
        if options["separating"] == "unilateral":
            restituted = np.minimum(un, 0.0)
        else:
            restituted = un
        if problem.frictional:
            return _resolve_friction(problem, e * restituted, options)
        large = problem.m > ENUMERATION_MAX
        single_e = large and (e == e[0]).all() and np.array_equal(restituted, un)
        plastic = projected(problem, options) if single_e and not problem.decoupled else None
        if plastic is not None:
            result, Pn = plastic, (1.0 + e[0]) * plastic.z
            formulation = "cone projection (clarabel)"
        else:
            result = _lcp(problem, un + e * restituted, options)
            Pn, formulation = result.z, result.method
        diagnostics = {
            "formulation": formulation,
            "solver_status": result.solver_status,
            "iterations": result.iterations,
            "polished": result.polished,
        }
        return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics)

    def _solve_contact(
        self, problem: ContactProblem, options: dict[str, Any]
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Coulomb's law on ``W``, ``q`` as given: the impact with ``e = 0`` in contact space.

        ``nsgs`` sweeps ``W`` itself; the fixed point's cone QPs take ``W``'s symmetric part and
        iterate its rest with the friction term (`_contact_fixed_point`); ``auto`` sweeps first
        and hands sweeps that stall or run out to the fixed point (`_methods`). Each answers to an
        FC3D error of at most ``tol``, the measure of a contact-space problem, or fails saying
        where it stopped.
        """
        self._refuse_relaxed_nsgs(options)
        solvers = {
            "nsgs": lambda: solve_polished(
                problem.W, problem.q, problem.mu, problem.dim, options["tol"], options["polish"]
            ),
            "fixed_point": lambda: _contact_fixed_point(problem, options),
        }
        methods = methods_for(options, problem.m, in_contact_space=True)
        r, diagnostics = in_turn(solvers, methods, options, problem.m)
        return _leaving(problem, r, options["tol"]), diagnostics

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """The per-contact LCP by active-set enumeration, for every problem at once.

        With friction, one contact: every mode of Coulomb's law in closed form
        (`lawbench.laws._one_contact_batch`), where the law has exactly one solution (the one
        the cone QPs find, when their fixed point settles within ``max_steps``: where it would
        not, the batch still gives that solution); a problem with several or none is left to
        `_resolve`, and so is Anitescu's relaxation.
        """
        if batch.m > ENUMERATION_MAX:
            return None
        un = batch.un
        restituted = np.minimum(un, 0.0) if options["separating"] == "unilateral" else un
        bias = un + batch.restitution("kinematic") * restituted
        if batch.frictional:
            if batch.m > 1 or options["friction"] == "relaxed":
                return None
            found = _one_contact_batch.solutions(batch, bias, COULOMB_TOLERANCE)
            return found.unique(), "closed form (batch)"
        Pn, found = enumerate_lcp(batch.delassus, bias)
        if not found.all():
            return None
        return Pn, "LCP (active-set enumeration, batch)"


def _lcp(problem: ImpactProblem, q: np.ndarray, options: dict[str, Any]) -> LCPResult:
    """The LCP in the impulses, or where clarabel fails on it, the projection it is.

    The projection in the kinetic metric (`project_in_kinetic_metric`) holds ``M``'s condition
    in its constraints' square root, where the LCP holds all of it in its Hessian: a chain of
    balls of masses 1e9 and 1 with a contact given twice. It takes ``M`` dense; a sparse
    problem keeps the LCP's failure. A spent budget stops the solve.
    """
    tol, polish = options["tol"], options["polish"]
    try:
        return solve_lcp(problem.delassus, q, tol, polish, decoupled=problem.decoupled)
    except BudgetExceeded:
        raise
    except SolverFailure as failure:
        if problem.sparse:
            raise
        try:
            return project_in_kinetic_metric(
                problem.M, problem.v, problem.Wn, problem.delassus, q, tol, polish
            )
        except BudgetExceeded:
            raise
        except SolverFailure as second:
            raise SolverFailure(f"{second} (after the LCP: {failure})") from None


UNDAMPED = 20
# Relative tolerance of Coulomb's conditions on a mode's closed form at one contact.
COULOMB_TOLERANCE = 1e-9


def _resolve_friction(
    problem: ImpactProblem, restitution: np.ndarray, options: dict[str, Any]
) -> Outcome:
    """Impulses in the Coulomb cones by the method of option ``method`` (`_methods`).

    ``restitution`` is ``E r``, added to the normal local velocities. Gauss-Seidel sweeps the
    contact Delassus matrix as it comes (sparse for a sparse problem); the fixed point's cone
    QPs and polish take it dense.
    """
    m, d, mu, G = problem.m, problem.d, problem.mu, problem.contact_delassus
    q = np.asarray(problem.W.T @ problem.v)
    q[:m] += restitution
    solvers = {
        "nsgs": lambda: _gauss_seidel(G, q, mu, d, options),
        "fixed_point": lambda: _fixed_point(as_array(G), q, mu, d, options),
    }
    methods = methods_for(options, m, in_contact_space=False)
    P, diagnostics = in_turn(solvers, methods, options, m)
    scale = float(np.abs(q).max())
    if _approaching(G @ P + q, m, options["tol"], scale):
        P = _one_contact_or_refuse(G, q, mu)
        diagnostics["formulation"] += ", then the contact's exact state"
    refuse_cancelling(G, P, options["tol"], scale)
    refuse_outside_cones(P, mu, d, options["tol"])
    return Outcome.from_impulses(problem, P[:m], P[m:], diagnostics=diagnostics)


def _approaching(u: np.ndarray, m: int, tol: float, scale: float) -> bool:
    """Whether a contact still approaches after the impact, breaking ``un+ + E r >= 0``.

    ``u`` is ``G P + q``; below ``-sqrt(tol)`` of the largest local velocity ``scale`` the
    answer breaks the normal law. With ``mu`` near 1e300 the modified velocity
    ``un + mu |ut|`` loses ``un`` to rounding, and a zero impulse passes the cone conditions
    while the contact goes on approaching.
    """
    return bool(u[:m].min() < -(tol**0.5) * scale)


def _leaving(problem: ContactProblem, r: np.ndarray, tol: float) -> np.ndarray:
    """``r`` when no contact approaches after it (`_approaching`), else the exact state.

    Each method stops at its own test; the normal law is checked here on ``u`` itself, against
    velocities only, so that no size of impulses (``W`` of 1e-100, impulses of 1e100) and no
    ``mu`` near 1e300 (whose modified velocity loses ``un`` to rounding) hides an approach.
    """
    u = problem.velocity(r)
    # Velocities only: impulses, in other units, would make any approach look small.
    scale = max(float(np.abs(problem.q).max()), float(np.abs(u).max()))
    if not _approaching(u[:: problem.dim], problem.m, tol, scale):
        return r
    return _one_contact_or_refuse(problem.W.toarray(), problem.q, problem.mu)


def _one_contact_or_refuse(G: np.ndarray, q: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """The exact state of a one-contact problem the solver missed, or the reason there is none.

    Raises
    ------
    NotApplicable
        When take-off, stick and slip all fail (`gauss_seidel.one_contact`): the law has no
        solution.
    SolverFailure
        With several contacts, where the states are not enumerated.
    """
    if len(mu) > 1:
        raise SolverFailure(
            "moreau: a contact still approaches after the impact: the cone conditions hold "
            "only to rounding here"
        )
    P = one_contact(as_array(G), q, mu[0])
    if P is None:
        raise NotApplicable(
            "moreau: take-off, stick and slip all fail at this contact: with kinematic "
            "restitution and Coulomb friction the law has no solution when the normal and "
            "tangential directions are this strongly coupled (as in Painleve's examples)"
        )
    return P


def _fixed_point(
    G: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int, options: dict[str, Any]
) -> tuple[np.ndarray, dict[str, Any]]:
    """One cone QP (relaxed) or their fixed point (exact): impulses and diagnostics.

    A cone QP's matrix is symmetric: it takes ``G``'s symmetric part, and the rest of ``G``
    (zero for a mechanical system's Delassus matrix; a file's W can have some) joins the shift
    of the linear term that the fixed point updates, ``shift = (mu |ut+|, 0) + skew P``, so
    that at the fixed point the QP's conditions are Coulomb's law on ``G`` itself.
    """
    m = len(mu)
    exact, tol = options["friction"] == "coulomb", options["tol"]
    symmetric = (G + G.T) / 2
    skew = G - symmetric
    shift, steps, iterations, note = np.zeros(q.size), 0, 0, ""
    spend = current_budget()
    while True:
        spend.step("Coulomb fixed-point steps", note)
        result = cones.solve_cone_qp(symmetric, q + shift, mu, d, tol, options["polish"])
        steps, iterations = steps + 1, iterations + result.iterations
        P, polished = result.P, result.polished
        if not exact:
            break
        slip = mu * np.linalg.norm(cones.split(G @ P + q, m, d)[1], axis=1)
        target = np.pad(slip, (0, m * d)) + skew @ P
        change = np.abs(target - shift).max()
        if change <= tol * np.abs(q).max():
            break
        # Plain substitution first; past UNDAMPED steps average, which breaks the two-cycles
        # the plain iteration can fall into.
        shift = shift + (1.0 if steps < UNDAMPED else 0.5) * (target - shift)
        note = f"last change of mu |ut+| {change:.3g}, tolerance {tol:g}"
    if exact and options["polish"]:
        # The last cone QP had the previous s; solve Coulomb's law itself on its states.
        refined = cones.polish(G, q, mu, d, P, True)
        P, polished = (P, polished) if refined is None else (refined, True)
    diagnostics = {
        "formulation": f"SOCP {'fixed point' if exact else 'relaxed'} (clarabel)",
        "solver_status": result.status,
        "iterations": iterations,
        "fixed_point_steps": steps,
        "polished": polished,
    }
    return P, diagnostics


def _contact_fixed_point(
    problem: ContactProblem, options: dict[str, Any]
) -> tuple[np.ndarray, dict[str, Any]]:
    """`_fixed_point` on a contact-space problem: impulses in FCLIB's order and diagnostics.

    Raises
    ------
    NotApplicable
        For Anitescu's relaxation of an asymmetric ``W``: one convex problem is symmetric.
    SolverFailure
        When the fixed point settles above an FC3D error of ``tol`` on ``W`` itself.
    """
    if options["friction"] == "relaxed" and problem.asymmetry > 0.0:
        raise NotApplicable(
            f"moreau: Anitescu's relaxation is one convex problem only for a symmetric W; "
            f"this W's asymmetry is {problem.asymmetry:.3g}"
        )
    m, d = problem.m, problem.dim - 1
    back = np.argsort(local_order(m, d))
    G = problem.W[back][:, back].toarray()
    P, diagnostics = _fixed_point(G, problem.q[back], problem.mu, d, options)
    r = P[local_order(m, d)]
    error = problem.error(r)
    if error > options["tol"]:
        raise SolverFailure(
            f"moreau: the fixed point settled after {diagnostics['fixed_point_steps']} cone "
            f"QPs at FC3D error {error:.3g} on W, above the tolerance {options['tol']:g}"
        )
    return r, diagnostics


def _gauss_seidel(
    G: np.ndarray, q: np.ndarray, mu: np.ndarray, d: int, options: dict[str, Any]
) -> tuple[np.ndarray, dict[str, Any]]:
    """`solve_polished` on the Delassus matrix of lawbench's order, in FCLIB's order and back.

    Raises
    ------
    NotApplicable, SolverFailure
        As `solve_polished`; at one contact a stationary iteration is replaced by the
        contact's exact state, or the reason the law has none.
    """
    m = len(mu)
    order = local_order(m, d)
    W, local_q = in_local_order(G, q, m, d)
    try:
        local_P, diagnostics = solve_polished(
            W, local_q, mu, d + 1, options["tol"], options["polish"]
        )
    except SolverFailure as failure:
        if m > 1 or out_of_time(failure):
            raise
        # One contact's states decide: its exact one, or the reason the law has none.
        P = _one_contact_or_refuse(G, q, mu)
        diagnostics = {"formulation": "the contact's exact state", "solver_status": "enumerated"}
        diagnostics["fc3d_error"] = error_of(G, q, mu, d, P)
        return P, diagnostics
    P = np.empty_like(local_P)
    P[order] = local_P
    return P, diagnostics


LAWS.register(Moreau())
