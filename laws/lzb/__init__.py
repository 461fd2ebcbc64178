"""The energetic multiple-impact law of Liu, Zhao and Brogliato (LZB).

Source: Brogliato, *An introduction to impact dynamics* (lectures, 2010), "Extension of the
Darboux-Keller's approach", equations (32)-(48); C. Liu, Z. Zhao, B. Brogliato, Proc. R. Soc. A
464 (2008) 3193-3211 and 465 (2009) 1-23; H. J. Zhang, C. Liu, Z. Zhao, B. Brogliato, Sci.
China Phys. Mech. Astron. 56 (2013) 875-881 (friction, eq. 7); N. S. Nguyen, B. Brogliato,
*Multiple impacts in dissipative granular chains* (Springer, 2014).

The law. Contact j is a spring ``F_j = K_j d_j^eta_j`` (eq. 32) storing the potential energy
``E_j = K_j d_j^(eta_j+1) / (eta_j+1)``, the work of its force mapped to the impulse level
(eqs. 36-39): ``dE_j = -un_j dP_j`` in compression. The impulse ``P_i`` of the *primary*
contact, the one storing the most energy, is the independent variable; every other contact
follows the distributing rule (eqs. 41, 44)
``dP_j / dP_i = (K_j/K_i)^(1/(eta+1)) (E_j/E_i)^(eta/(eta+1))``, the ratio of the two spring
forces (a per-contact exponent is allowed: the rule is then the ratio of the forces
``K^(1/(eta+1)) ((eta+1) E)^(eta/(eta+1))``); ``M dv = Wn dPn + Wt dPt`` (eq. 43). A contact is
in compression while ``un_j < 0``, in expansion after; its *cycle* ends when its energy is
released. It may be compressed again during an expansion (several compression/expansion
phases in one cycle, lectures' remark after eq. 42), and starts a new cycle if it approaches
after its cycle ended. Stronge's coefficient ``e*_j = contact.restitution("energetic")`` ends each
cycle (eq. 42): the work released in expansion is ``e*^2`` times the work of compression, both
summed over the cycle.

- ``variant="bi"`` (bi-stiffness, eqs. 47-48; Zhang et al. eq. 7; default): in expansion the
  energy falls as ``dE_j = -un_j dP_j / e*_j^2`` and the cycle ends at ``E_j = 0``: the
  expansion spring is stiffer and the force continuous. With ``e* = 0`` the cycle ends with its
  compression, the stored energy dissipated.
- ``variant="mono"`` (mono-stiffness, eq. 32 in both phases): ``dE_j = -un_j dP_j`` throughout;
  the cycle ends when ``E_j`` falls to ``(1 - e*^2) W_c`` (``W_c`` the compression work of the
  cycle) and that residue is dissipated at once (lectures, after eq. 42). Siconos'
  MultipleImpact ends it instead at ``(1 - e*^2)`` times the energy at the last end of
  compression; the two agree unless a contact is compressed again within a cycle.

The impact ends when every stored energy is released and no contact approaches. A gap rate
above ``-10 tol V`` (``V`` the largest pre-impact contact speed) counts as rest, normal or
tangential: closer to zero it is within the integrator's error. Coulomb friction (planar,
d = 1; Zhang et al. 2013): a loaded contact that slips has ``dPt_j = -mu_j dPn_j sign(ut_j)``;
one at rest sticks (``dut_j = 0``) when the tangential forces this needs lie in the cones, and
slips otherwise; the forces at rest solve Coulomb's law at the force level with the normal
forces given (a box-constrained quadratic problem), whenever a contact comes to rest; a
sticking contact whose force reaches its cone slips against that force. When sticking contacts
have redundant tangential directions their forces are split with the minimum norm. A spatial
frictional problem is refused.

Start from zero stored energy. Stepping in ``P_i`` is singular where ``E_i = 0``: the rule is 0/0 at
the start and ``dtau/dP_i = 1/F_i`` is unbounded at the start and the end of each loading, and a
fixed impulse step there converges to wrong answers however small the step. The state is written
instead in the regular variables ``d_j = ((eta_j+1) E_j / K_j)^(1/(eta_j+1))``, with ``dd_j = -un_j
dtau / xi_j`` (``xi = 1``, or ``e*^2`` in a bi-stiffness expansion) and ``dP_j = K_j d_j^eta_j
dtau``, where ``dtau = dP_i / F_i`` is common to all contacts (the rule says exactly that the
impulses grow as the forces) and is the time of the springs. A contact that approaches starts at
``d_j = 0`` with ``dd_j/dtau = -un_j > 0``: no first impulse has to be guessed. The integrator steps
in the primary impulse ``P_i`` while the primary stores at least 1% of the reference energy ``max_j
(un-_j)^2 / (2 G_jj)``, and in ``tau`` below that (at the start and the end of the loadings). The
primary changes, as an event, when another contact stores more energy (ties within 1e-6 relative
keep the current one).

Energy and accuracy. The equations keep ``T + sum_j E_j`` exactly (e* = 1, no friction); they
are integrated by scipy's DOP853 (option ``method``) at relative tolerance ``tol``, the
accuracy knob (absolute tolerance ``1e-3 tol`` in units of ``V``, of the smallest indentation
scale and of their impulse and energy), restarted at every event (end of compression,
recompression, end of a cycle, approach of an idle contact, slip stop, stick limit, change of
primary contact or of variable), each located by Brent's method on the dense output to
rounding, so the right-hand side is smooth within a segment. The error of ``v_plus`` falls in
proportion to ``tol``, and the kinetic energy of an elastic frictionless impact is kept to a
small multiple of ``tol`` (the tests measure both on the chains).

Relation with compliant contacts: with e* = 1 the law is the time integration of the same
unilateral springs (same stiffness ratios, exponents and masses) at a frozen configuration,
except that a contact whose energy went back to zero keeps no gap: it is compressed again as
soon as it approaches, where a spring would first close the gap it opened. The two agree while
no contact that separated approaches again (tested on two balls and a wall).

Energy locked in: when friction holds every loaded contact at rest and the forces give the
bodies no impulse (the lamina stuck on the anvil, ``mu |h0| >= |f0|``), nothing can change any
more; the impact ends there and the stored energy is dissipated (the cycle's ``residual``),
the plastic outcome of the lectures' "case of large friction".

Impacts that do not end: energy that can never leave (a rod held at both ends by friction at
e* = 1, a light ball rattling between heavy ones) or contacts recompressed again and again with
geometrically smaller energies (long chains with e* < 1, as in an inelastic collapse) make
many cycles; ``max_steps`` integrator steps, ``max_events`` events and ``max_seconds`` of
wall-clock time bound the run and raise `SolverFailure` naming the budget that ran out.

Conventions: ``un = Wn.T v < 0`` approaches, ``Pn >= 0`` pushes apart,
``v+ = v- + M^-1 (Wn Pn + Wt Pt)``, ``|Pt_j| <= mu_j Pn_j``. A closed contact that separates
before the impact receives no impulse unless the others make it approach. Stiffness in
N/m^exponent; with one exponent the outcome depends only on the stiffness ratios and masses, while
times and forces in the diagnostics are physical.

Formulations: ``"closed form (decoupled contacts)"`` without friction when the Delassus matrix
is diagonal and no path is asked (each contact is Stronge's single impact,
``Pn_j = -(1 + e*_j) un_j / G_jj``); ``"no approaching contact"``; otherwise
``"energetic impulse dynamics (...)"``.

Diagnostics: ``formulation``, ``variant``, ``tol``, ``steps`` (``impulse_steps`` +
``time_steps``), ``events``, ``peak_force`` (N, per contact: ``K d^eta`` at the largest
``d = ((eta+1) E / K)^(1/(eta+1))``), ``primary_switches`` and ``primaries`` (the successive
primary contacts, the first 1000), ``recompressed`` (contacts compressed again after a cycle
ended), ``cycles`` (per contact, one ``{"compression",
"restitution", "residual"}`` per cycle, in J: work of compression, work released in expansion,
energy dissipated at once when the cycle ends), ``normal_work`` and ``friction_work`` (J, per
contact; their sum is ``dT``), ``duration_s``. Option ``path`` returns ``t`` (s), ``Pn``,
``Pt``, ``v``, ``un``, ``stored_energy`` (J), ``force`` (N) and ``primary`` (-1 where the
integrator steps in time) after every step, at its midpoint, and on both sides of every event.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.special

from lawbench.core.law import LAWS, Law
from lawbench.core.metric import is_diagonal
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.laws._claims import (
    ENERGETIC_DISSIPATION,
    FROZEN_CONFIGURATION,
    PAOLI_DISCONTINUITY,
    keeps_energy,
    never_creates_energy,
)
from lawbench.laws._options import bound, path_option
from lawbench.laws.lzb.dynamics import RECORDED, REST_FACTOR, EnergeticImpact


class LiuZhaoBrogliato(Law):
    """The energetic multiple-impact law of Liu, Zhao and Brogliato."""

    name = "lzb"
    summary = (
        "energetic multiple impacts (Liu-Zhao-Brogliato): distributing rule from stiffness "
        "ratios and stored energies, Stronge's coefficient per contact"
    )
    source = "Brogliato 2010, eqs. (32)-(48); Liu, Zhao, Brogliato 2008, 2009; Zhang et al. 2013"
    tags = Tags(friction=True, several_contacts=True, stiffness=True, accuracy_knob="tol")
    fitted = ("e", "mu")
    separating_rule = (
        "a separating contact receives no impulse unless the others make it approach, "
        "then it is compressed like any other"
    )
    findings = (PAOLI_DISCONTINUITY, FROZEN_CONFIGURATION, ENERGETIC_DISSIPATION)
    guarantees = (
        keeps_energy(
            "Liu, Zhao and Brogliato, Proc. R. Soc. A 464 (2008), eq. (42)",
            "at e* = 1 every cycle gives back in expansion the work of its compression",
        ),
        never_creates_energy(
            "Liu, Zhao and Brogliato, Proc. R. Soc. A 464 (2008), eq. (42); Int. J. Solids "
            "Struct. 46 (2009)",
            "each cycle gives back e*^2 of its compression work and Coulomb friction only "
            "dissipates",
        ),
    )
    options = (
        Spec(
            "variant",
            "bi",
            "stiffness model: bi (stiffer expansion) or mono (residue dissipated at the end)",
            kind="str",
            choices=("bi", "mono"),
        ),
        Spec(
            "tol", 1e-10, "relative tolerance of the integrator", low=0.0, high=1e-2, low_open=True
        ),
        Spec(
            "method", "DOP853", "solve_ivp method", kind="str", choices=("DOP853", "RK45", "Radau")
        ),
        bound("max_steps", 200_000, "budget of integrator steps"),
        bound("max_events", 20_000, "budget of restarts at events"),
        path_option("impulses, velocities and stored energies along the impact"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        diagnostics: dict[str, Any] = {"variant": options["variant"], "tol": options["tol"]}
        speed = np.abs(np.concatenate([problem.un, problem.ut])).max()
        if not (problem.un < -REST_FACTOR * options["tol"] * speed).any():
            diagnostics.update(formulation="no approaching contact", **_nothing(problem.m))
            return Outcome.from_impulses(problem, np.zeros(problem.m), diagnostics=diagnostics)
        if not problem.frictional and is_diagonal(problem.delassus) and not options["path"]:
            Pn = _decoupled(problem, options["variant"], diagnostics)
            return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics)
        impact = EnergeticImpact(
            problem,
            options["variant"],
            options["tol"],
            options["method"],
            options["path"],
        )
        y = impact.run()
        Pn = impact.I * y[impact.iPn]
        Pt = impact.I * y[impact.iPt] if impact.friction else None
        _describe(impact, y, options, diagnostics)
        path = _path(impact, problem) if options["path"] else None
        return Outcome.from_impulses(problem, Pn, Pt, diagnostics=diagnostics, path=path)


LAWS.register(LiuZhaoBrogliato())


def _nothing(m: int) -> dict[str, Any]:
    """Diagnostics of an impact with no event at all."""
    return {
        "steps": 0,
        "impulse_steps": 0,
        "time_steps": 0,
        "events": 0,
        "peak_force": [0.0] * m,
        "primary_switches": 0,
        "primaries": [],
        "cycles": [[] for _ in range(m)],
        "normal_work": [0.0] * m,
        "friction_work": [0.0] * m,
        "duration_s": 0.0,
    }


def _decoupled(problem: ImpactProblem, variant: str, diagnostics: dict[str, Any]) -> np.ndarray:
    """Contacts that do not interact: Stronge's single impact at each, in closed form.

    Alone, a contact stores ``W_c = un^2 / (2 G_jj)``; its compression lasts
    ``d_m / |un| * B(a, 1/2) / (eta + 1)`` with ``a = 1 / (eta + 1)`` (from
    ``un^2 = 2 G_jj (W_c - E)``), a bi-stiffness expansion ``e*`` times as long, a
    mono-stiffness one the part ``1 - I_(1-e*^2)(a, 1/2)`` of it.
    """
    G, un, e = np.diag(problem.delassus), problem.un, problem.restitution("energetic")
    approach = np.maximum(-un, 0.0)
    Pn = (1 + e) * approach / G
    work = approach**2 / (2 * G)
    diagnostics.update(formulation="closed form (decoupled contacts)", **_nothing(problem.m))
    durations = [0.0]
    for j, contact in enumerate(problem.contacts):
        if approach[j] <= 0:
            continue
        K, eta = contact.stiffness, contact.exponent
        depth = ((eta + 1) * work[j] / K) ** (1 / (eta + 1))
        # Energy left when the cycle ends, dissipated at once: the mono-stiffness residue, or
        # the whole compression work when e* = 0.
        residual = (1 - e[j] ** 2) * work[j] if variant == "mono" or e[j] == 0 else 0.0
        diagnostics["cycles"][j] = [
            {
                "compression": float(work[j]),
                "restitution": float(e[j] ** 2 * work[j]),
                "residual": float(residual),
            }
        ]
        a = 1 / (eta + 1)
        compression = depth / approach[j] * scipy.special.beta(a, 0.5) * a
        if variant == "bi":
            expansion = e[j] * compression
        else:
            expansion = compression * (1 - scipy.special.betainc(a, 0.5, 1 - e[j] ** 2))
        diagnostics["peak_force"][j] = float(K * depth**eta)
        durations.append(compression + expansion)
    diagnostics["normal_work"] = (-(1 - e**2) * work).tolist()
    diagnostics["duration_s"] = float(max(durations))
    return Pn


def _describe(
    impact: EnergeticImpact, y: np.ndarray, options: dict[str, Any], diagnostics: dict[str, Any]
) -> None:
    """Fill the diagnostics of an integrated impact (physical units)."""
    energy = impact.V * impact.I
    friction = "Coulomb friction, " if impact.friction else ""
    diagnostics.update(
        formulation=f"energetic impulse dynamics ({options['variant']}-stiffness, {friction}"
        f"primary impulse or time, {options['method']})",
        steps=sum(impact.steps.values()),
        impulse_steps=impact.steps["impulse"],
        time_steps=impact.steps["time"],
        events=impact.events,
        peak_force=[
            float(K * (r.peak_s * impact.L) ** eta)
            for K, eta, r in zip(impact.K, impact.eta, impact.records, strict=True)
        ],
        recompressed=[j for j, r in enumerate(impact.records) if len(r.cycles) > 1],
        primary_switches=impact.switches,
        primaries=impact.primaries[:RECORDED],
        cycles=[
            [
                {
                    "compression": float(c.compression * energy),
                    "restitution": float(c.restitution * energy),
                    "residual": float(c.residual * energy),
                }
                for c in r.cycles
            ]
            for r in impact.records
        ],
        normal_work=(energy * y[impact.iW]).tolist(),
        friction_work=(energy * y[impact.iWt]).tolist() if impact.friction else [0.0] * impact.m,
        duration_s=float(y[-1] * impact.tau0),
    )


def _path(impact: EnergeticImpact, problem: ImpactProblem) -> dict[str, np.ndarray]:
    """Quantities at every kept state, in physical units.

    The first, the path's abscissa, is the total normal impulse ``sum_j Pn_j`` (N s): the law
    steps in impulses, and its answer depends on the stiffnesses' ratios only, while the
    springs' time ``t`` scales with the stiffnesses themselves.
    """
    history = np.array(impact.history)
    Y, primary = history[:, :-1], history[:, -1].astype(int)
    Pn = impact.I * Y[:, impact.iPn]
    Pt = impact.I * Y[:, impact.iPt] if impact.friction else np.zeros((len(Y), 0))
    impulse = Pn @ problem.Wn.T
    if impact.friction:
        impulse = impulse + Pt @ problem.Wt.T
    v = problem.v + problem.solve_mass(impulse.T).T
    d = impact.L * np.maximum(Y[:, impact.iS], 0.0)
    return {
        "Pn_sum": Pn.sum(axis=1),
        "t": impact.tau0 * Y[:, -1],
        "Pn": Pn,
        "Pt": Pt,
        "v": v,
        "un": v @ problem.Wn,
        "stored_energy": impact.K * d ** (impact.eta + 1) / (impact.eta + 1),
        "force": impact.K * d**impact.eta,
        "primary": primary,
    }


# The study this law declares, as data: the energy its contacts exchange along one impact.
LiuZhaoBrogliato.studies = (
    {
        "shape": "impact_path",
        "case": "bead_column",
        "title": "energy exchanged between the contacts of the bead column",
    },
)
