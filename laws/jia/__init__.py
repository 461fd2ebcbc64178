"""Jia's laws: energy-based tangential compliance at one contact, state transitions at several.

Source: Y.-B. Jia, *Three-dimensional impact: energy-based modeling of tangential compliance*,
Int. J. Robotics Research 32(1), 2013, and Y.-B. Jia, M. T. Mason, M. A. Erdmann, *Multiple
impacts: a state transition diagram approach*, IJRR 32(1), 2013, as presented in Jia's talk
*Simultaneous three-dimensional impacts with friction and compliance* (2012). The equations and
their integration are in `lawbench.laws.jia.dynamics`.

- One contact: the contact point is a massless particle held by a normal spring and two
  tangential springs. The normal impulse drives the impact: the normal strain energy obeys
  ``dE_n/dI_n = -un``, the tangential impulse ``dI_t/dI_n = F_t / F_n`` follows from the spring
  energies, and the contact sticks while ``E_t < mu^2 eta^2 E_n`` (Coulomb's bound on the
  spring force), slips otherwise. At the end of compression the normal stiffness rises from
  ``k_0`` to ``k_0 / e^2`` with the force unchanged, so the spring keeps ``e^2`` of its energy:
  ``e`` is the energetic coefficient (``contact.restitution('energetic')``). The tangential
  stiffness ``k'`` never changes; ``eta0^2 = k_0 / k'`` is the contact's
  ``tangential_stiffness_ratio``. When it is None the law takes Mindlin's ratio for identical
  elastic bodies with Poisson's ratio 0.3, ``(2 - nu) / (2 (1 - nu)) = 17/14`` (Jia's bouncing
  ball; the talk rounds it to 1.2). The impact ends when the normal spring is empty again.
- Several contacts (Jia, Mason and Erdmann): every contact is a linear normal spring with the
  same stiffness increase at each of its ends of compression; a contact whose spring empties
  leaves the active set, and returns when its gap rate turns negative (no stiffness change on
  either event). The outcome depends on stiffness ratios only, taken from the contacts'
  ``stiffness``; the springs are linear, the contacts' ``exponent`` is not read, and contacts
  of different exponents are refused: the ratio of a stiffness in N/m to one in N/m^1.5
  depends on the unit of length, and so would the answer. The paper
  states it for chains of balls (a ball on a ball on the ground); the equations need only the
  Delassus matrix, which couples the contacts of any system. With friction (the talk's part
  III, simultaneous impacts with friction and compliance: the cue, the billiard ball and the
  table) every frictional contact also carries its own tangential springs, driven by its own
  normal impulse as at one contact: "the two normal impulses take turns to drive the system".
  No time passes within the impact: a reactivated contact ignores the gap it opened, so where a
  contact opens and closes again the outcome differs from the same springs integrated in time.
- Both: the stiffness rises at every end of compression, a second one after a return from
  restitution to compression included (the talk: "every end of compression of single
  impact"). A plastic contact (e = 0) becomes infinitely stiff: at one contact the impact ends
  with the compression (what the tangential springs hold is lost). In a chain, a contact held
  loaded by its neighbours can end compression, empty and return without end, its stiffness
  growing each time; that infinite sequence, and e = 0, are treated as their limit, a rigid
  plastic contact that holds its gap rate while it pushes (`lawbench.laws.jia.dynamics`, LOCK).

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart; ``Pt`` is the tangential impulse
in the columns of ``Wt`` (``|Pt| <= mu Pn`` holds along the whole impact, and ``Pt`` opposes
the particle's slip); ``v+ = v- + M^-1 (Wn Pn + Wt Pt)``. A closed contact that separates before
the impact is inactive until its gap rate turns negative.

Formulations (``diagnostics['formulation']``): frictionless with a diagonal Delassus matrix (one
contact included), the closed form ``Pn = -(1 + e) un- / G_jj`` (the energetic coefficient
equals Newton's there); otherwise the spring equations integrated with scipy's DOP853 at the
relative ``tol``, every transition (end of compression, slip, stick, separation,
reactivation, lock, release) an event; a gap rate above ``-100 tol |u-|`` (at most 1 % of
``|u-|``) does not count as approaching. Diagnostics: ``sequence`` (one contact: the modes
and events, for example slip, stick, end of compression, slip, end of impact; several: the
active sets),
``events`` (each transition with its ``tau`` and normal impulses), ``steps`` (integrator
steps), ``compression_loss`` (J, energy taken at the ends of compression), ``recompressed``
(contacts that separated and were compressed again). Option ``path``
returns the impulse curve: ``tau``, ``Pn`` (k, m), ``Pt`` (k, m d), ``En`` (k, m) and ``Et``
(k, m) the spring energies (J), ``un`` and ``ut`` the contact velocities.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.checks.regions import nonlinear_springs
from lawbench.core.errors import NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.core.metric import is_diagonal
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.core.verdicts import Claim
from lawbench.laws._claims import (
    ENERGETIC_DISSIPATION,
    FROZEN_CONFIGURATION,
    PAOLI_DISCONTINUITY,
    keeps_energy,
    never_creates_energy,
)
from lawbench.laws._options import bound, path_option
from lawbench.laws.jia.dynamics import SpringImpact, Springs
from lawbench.numerics.solvers import solve_lcp

APPROACH = 1e-12


class Jia(Law):
    """Jia's tangential compliance at every frictional contact and state transitions at several."""

    name = "jia"
    summary = (
        "Jia's energy-based tangential compliance at every frictional contact; "
        "Jia-Mason-Erdmann state transitions for several contacts"
    )
    source = (
        "Jia, IJRR 32(1) 2013 (tangential compliance); Jia, Mason and Erdmann, IJRR 32(1) 2013 "
        "(multiple impacts)"
    )
    tags = Tags(
        friction=True,
        several_contacts=True,
        spatial=True,
        stiffness=True,
        accuracy_knob="tol",
    )
    fitted = ("e", "mu", "tangential_stiffness_ratio")
    separating_rule = (
        "a separating contact is inactive until its gap rate turns negative, then it is "
        "compressed like any other"
    )
    findings = (
        PAOLI_DISCONTINUITY,
        FROZEN_CONFIGURATION,
        ENERGETIC_DISSIPATION,
        Claim(
            "dispersion",
            nonlinear_springs,
            "Jia, Mason and Erdmann, IJRR 32(1) 2013: every contact a linear normal spring",
            "the law's springs are linear and the contacts' exponent is not read, so with Hertz "
            "contacts the energy spreads over the bodies as it would with linear ones, unlike the "
            "compliant ground truth",
            (("ball_chain", "default"),),
        ),
    )
    guarantees = (
        keeps_energy(
            "Jia, Mason and Erdmann, IJRR 32(1) 2013",
            "at e = 1 no spring changes stiffness, so the springs give back all they store",
        ),
        never_creates_energy(
            "Jia, Mason and Erdmann, IJRR 32(1) 2013; Jia 2013",
            "energy leaves the springs only at the ends of compression and by tangential slip",
        ),
    )
    options = (
        Spec(
            "tol",
            1e-11,
            "relative tolerance of the integration along the impact",
            low=0.0,
            high=1e-2,
            low_open=True,
        ),
        path_option("the impulse curve (impulses, spring energies, contact velocities)"),
        bound("max_steps", 1_000_000, "budget of integrator steps"),
        bound("max_events", 10_000, "budget of contact state transitions"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        d = problem.d if problem.frictional else 0
        un = problem.un
        if not (un < -APPROACH * np.abs(np.concatenate([un, problem.ut])).max()).any():
            diagnostics = {"formulation": "no approaching contact", "sequence": [], "steps": 0}
            return Outcome.from_impulses(problem, np.zeros(problem.m), diagnostics=diagnostics)
        e = problem.restitution("energetic")
        if not d and is_diagonal(problem.delassus) and not options["path"]:
            Pn = np.where(un < 0, -(1 + e) * un / np.diag(problem.delassus), 0.0)
            formulation = "closed form" if problem.m == 1 else "decoupled (diagonal Delassus)"
            diagnostics = {"formulation": formulation, "sequence": [], "steps": 0}
            return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics)
        return _integrate(problem, d, e, options)


def _integrate(problem: ImpactProblem, d: int, e: np.ndarray, options: dict[str, Any]) -> Outcome:
    """Integrate Jia's springs; ``d`` tangential directions per contact (0: frictionless)."""
    m = problem.m
    _refuse_mixed_exponents(problem)
    eta0_sq = np.array([c.tangential_ratio for c in problem.contacts])
    stiffness = np.array([c.stiffness for c in problem.contacts])
    mu = problem.mu if d else np.zeros(m)
    springs = Springs(stiffness / stiffness[0], e, mu, eta0_sq)
    if d:
        G, u_minus = problem.contact_delassus, np.concatenate([problem.un, problem.ut])
    else:
        G, u_minus = problem.delassus, problem.un
    impact = SpringImpact(G, u_minus, springs, options["tol"], options["path"])
    state = impact.run()
    record = impact.record
    if d and m == 1:
        formulation = "tangential compliance, one contact (Jia 2013), integrated"
    elif d:
        formulation = (
            "tangential compliance at every contact, state transitions (Jia 2012), integrated"
        )
    elif m == 1:
        formulation = "normal spring, one contact (Jia 2013), integrated"
    else:
        formulation = "state transitions, frictionless chain (Jia, Mason, Erdmann 2013)"
    diagnostics = {
        "formulation": formulation,
        "sequence": record.sequence,
        "events": record.events,
        "steps": record.steps,
        "compression_loss": record.compression_loss,
        "recompressed": sorted(int(j) for j in record.recompressed),
    }
    if d:
        diagnostics["tangential_stiffness_ratio"] = eta0_sq[0] if m == 1 else eta0_sq.tolist()
    if any(c.exponent != 1 for c in problem.contacts) and m > 1:
        diagnostics["springs"] = "linear: the contacts' exponent is not read"
    path = _path(impact) if options["path"] else None
    Pt = state[impact.It] if d else None
    Pn = state[:m]
    if not d:
        # A contact left approaching slower than the reactivation threshold (100 tol, at most
        # 1 %, times the largest speed) would be reactivated with negligible energy and
        # stopped: its limit, a plastic stop, keeps the outcome admissible at the cost of an
        # impulse of that order.
        after = problem.un + problem.delassus @ Pn
        if (after < 0).any():
            stop = solve_lcp(problem.delassus, after).z
            Pn = Pn + stop
            diagnostics["plastic_stop"] = float(stop.max())
    return Outcome.from_impulses(problem, Pn, Pt, diagnostics=diagnostics, path=path)


def _refuse_mixed_exponents(problem: ImpactProblem) -> None:
    """Refuse contacts whose force exponents differ: their stiffness ratios have a unit.

    The springs are linear and only the ratios of the contacts' stiffnesses are read; with one
    exponent those ratios are numbers, with two (1 and 1.5: N/m against N/m^1.5) they depend
    on the unit of length, and so would the outcome.
    """
    exponents = sorted({c.exponent for c in problem.contacts})
    if len(exponents) > 1:
        raise NotApplicable(
            f"jia: the contacts' force exponents differ ({', '.join(f'{x:g}' for x in exponents)}):"
            " the ratios of their stiffnesses, which Jia's linear springs read, would depend on "
            "the unit of length"
        )


def _path(impact: SpringImpact) -> dict[str, np.ndarray]:
    """The impulse curve from the samples of ``impact``: impulses, energies, velocities."""
    m, d = impact.m, impact.d
    samples = np.array(impact.record.samples)
    states = samples[:, 1:]
    velocities = np.array([impact.velocity(s) for s in states])
    g = states[:, impact.g].reshape(len(states), m, d)
    return {
        "tau": samples[:, 0],
        "Pn": states[:, :m],
        "Pt": states[:, impact.It],
        "En": states[:, m : 2 * m] ** 2,
        "Et": np.sum(g**2, axis=2) * impact.kappa0 / (4 * impact.springs.eta0_sq),
        "un": velocities[:, :m],
        "ut": velocities[:, m:],
    }


LAWS.register(Jia())

# The study this law declares, as data: its impulse curve along one impact.
Jia.studies = (
    {
        "shape": "impact_path",
        "case": "ball_chain",
        "title": "Jia's impulse curve for two colliding balls",
        "params": {"n": 2},
    },
)
