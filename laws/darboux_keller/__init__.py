"""Darboux-Keller impulse-time dynamics at one contact with Coulomb friction.

Source: G. Darboux (1880), J.B. Keller (1986) and W.J. Stronge (1990), as given by Brogliato,
*An introduction to impact dynamics* (lectures, 2010): the normal impulse ``Pn`` replaces time
(equations 2-3), the impact is a compression until the normal contact velocity vanishes, then a
restitution ended by one of three rules (option ``termination``), each reading its own
coefficient of the contact:

- ``newton`` (``restitution('kinematic')``): ``un = -e un-``;
- ``poisson`` (``restitution('kinetic')``): ``Pn = (1 + e) Pn_c``, ``Pn_c`` the compression
  impulse;
- ``energetic`` (default, Stronge; ``restitution('energetic')``): the work of the normal force in
  restitution is ``e^2`` times minus its work in compression, ``W_r = -e^2 W_c`` with
  ``W = int un dPn``.

Friction is Coulomb's law at the force level along the impulse: slip ``dPt/dPn = -mu ut/|ut|``,
stick ``ut = 0``. The contact velocity ``u = (un, ut)`` obeys ``du/dPn = G [1, dPt/dPn]`` with
``G`` the contact Delassus matrix (``ImpactProblem.contact_delassus``); in 3D the slip direction
turns (lectures, eq. 15). Planar problems are solved exactly, phase by phase: velocities affine
and work quadratic in ``Pn``, slip stop, end of compression and termination at closed-form
roots. Stick, once reached, lasts when ``mu >= |Gtn / Gtt|`` (friction strong against the
normal-tangential coupling; in 3D ``mu >= |Gtt^-1 Gtn|``); otherwise the slip reverses.
Spatial slip with a turning direction is integrated with ``solve_ivp`` (Radau, option
``tol``, the accuracy knob) until it stops; the rest is exact again: stick, or slip in a
fixed direction (Darboux's proposition, lectures after eq. 15). The machinery is in
`lawbench.laws.darboux_keller.dynamics`.

When friction stops slip and the stuck contact's impulse no longer moves the system (the
lamina on an anvil with ``mu |h0| >= |f0|``) the restitution cannot start and the impact ends
there, plastic whatever the termination (lectures, "case of large friction").

Known facts: the energetic termination never creates kinetic energy (Stronge 1990, 1991:
``dT = W_c + W_r + friction work <= (1 - e^2) W_c <= 0``). Newton's termination can when slip
halts or reverses (Stronge, J. Appl. Mech. 58, 1991): the normal velocity grows at a different
rate in restitution than in compression, and ``un+ = -e un-`` then releases more normal work
than compression stored. Poisson's termination gained no energy in any of several thousand
random single-contact trials, planar or spatial, in line with Djerassi (Multibody Syst. Dyn.,
2009: in 2D, Poisson's and Stronge's hypotheses give energy-consistent solutions); the claim
that it can gain energy at one contact is not reproduced here. Without friction (no ``Wt`` or
``mu = 0``) the three give the same outcome for the same ``e`` (lectures, frictionless single
impacts).

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart, ``v+ = v- + M^-1 (Wn Pn + Wt
Pt)``; ``|Pt| <= mu Pn`` holds by construction. One contact only (the base class refuses more
closed contacts); a closed contact that does not approach (``un- >= 0``) gets no impulse.

Diagnostics: ``formulation`` ("exact (frictionless)", "exact piecewise (planar)", "exact
piecewise (spatial)" when no turning slip occurs, "ODE (spatial)"); ``phases`` and
``phase_impulses`` (each phase or event with the normal impulse where it starts: phases
"frictionless", "slip", "stick", "slip reversal", "slip (fixed direction)"; events "end of
compression", "end of impact", "end of impact (no expansion)");
``compression_impulse``; ``work_compression`` and ``work_restitution`` (normal work);
``ode_steps``. Option ``path`` returns ``Pn``, ``Pt`` (k, d), ``un``, ``ut`` (k, d), ``Wn`` (the
normal work) and ``v`` (k, n) along the impact.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.checks.regions import option
from lawbench.core.law import LAWS, Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.laws._claims import keeps_energy, never_creates_energy
from lawbench.laws._options import bound, path_option
from lawbench.laws.darboux_keller import batch as batch_phases
from lawbench.laws.darboux_keller.dynamics import (
    ImpactRecord,
    SingleContactImpact,
    State,
    path_arrays,
)

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch

# Each termination reads the contact's coefficient of its own kind.
COEFFICIENT = {"newton": "kinematic", "poisson": "kinetic", "energetic": "energetic"}


class DarbouxKeller(Law):
    """Impulse-time dynamics at one contact; Newton, Poisson or Stronge termination."""

    name = "darboux_keller"
    summary = (
        "impulse-time dynamics at one contact with Coulomb stick/slip; "
        "Newton, Poisson or Stronge termination"
    )
    source = "Darboux 1880, Keller 1986, Stronge 1990; Brogliato 2010, eqs. (2)-(4), (12)-(15)"
    tags = Tags(friction=True, several_contacts=False, spatial=True, accuracy_knob="tol")
    fitted = ("e", "mu")
    separating_rule = "a separating contact takes no impulse"
    guarantees = (
        keeps_energy(
            "Stronge 1990; Brogliato 2010, eqs. (12)-(15)",
            "without friction the three terminations agree, and at e = 1 the expansion gives "
            "back the work of compression",
        ),
        never_creates_energy(
            "Stronge 1990; Brogliato 2010, eqs. (12)-(15)",
            "Stronge's termination gives back e^2 of the normal work of compression and "
            "friction only dissipates",
            option("termination", "energetic"),
        ),
    )
    options = (
        Spec(
            "termination",
            "energetic",
            "end of restitution: Newton's kinematic, Poisson's kinetic or Stronge's energetic "
            "coefficient",
            kind="str",
            choices=tuple(COEFFICIENT),
        ),
        Spec(
            "tol",
            1e-9,
            "relative tolerance of the ODE of turning spatial slip (planar problems are exact)",
            low=1e-13,
            high=1e-2,
        ),
        path_option("impulses, contact velocities and work along the impact"),
        bound("max_steps", 100_000, "budget of integrator steps of turning slip"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        contact, d = problem.contacts[0], problem.d
        mu = contact.mu if d else 0.0
        termination = options["termination"]
        u_minus = np.concatenate([problem.un, problem.ut])
        diagnostics: dict[str, Any] = {"termination": termination}
        if problem.un[0] >= 0:
            record = ImpactRecord()
            record.sample(np.zeros(1), np.zeros((1, d)), u_minus[None, :], np.zeros(1))
            diagnostics["formulation"] = "no impact (the contact does not approach)"
            final = compression = State(0.0, np.zeros(d), u_minus, 0.0)
        else:
            e = contact.restitution(COEFFICIENT[termination])
            impact = SingleContactImpact(
                problem.contact_delassus, u_minus, mu, termination, e, options["tol"]
            )
            final, record = impact.run(), impact.record
            compression = record.compression
            if mu == 0:
                diagnostics["formulation"] = "exact (frictionless)"
            elif d == 1:
                diagnostics["formulation"] = "exact piecewise (planar)"
            else:
                spatial = "ODE (spatial)" if record.steps else "exact piecewise (spatial)"
                diagnostics["formulation"] = spatial
        diagnostics.update(
            phases=record.phases,
            phase_impulses=record.phase_impulses,
            compression_impulse=float(compression.P),
            work_compression=float(compression.W),
            work_restitution=float(final.W - compression.W),
            ode_steps=record.steps,
        )
        path = _path(problem, record) if options["path"] else None
        return Outcome.from_impulses(
            problem,
            np.array([final.P]),
            final.Pt if d else None,
            diagnostics=diagnostics,
            path=path,
        )

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """The exact piecewise phases of every impact at once (`batch.impulses`).

        Planar and frictionless impacts; spatial ones with friction, whose slip may turn, and
        those the phases refuse, are left to `_resolve`.
        """
        termination = options["termination"]
        u_minus = np.concatenate([batch.un, batch.ut], axis=1)
        P = batch_phases.impulses(
            batch.contact_delassus,
            u_minus,
            batch.mu[:, 0],
            termination,
            batch.restitution(COEFFICIENT[termination])[:, 0],
        )
        return P, "exact piecewise (batch)"


def _path(problem: ImpactProblem, record: ImpactRecord) -> dict[str, np.ndarray]:
    """The recorded path, with the generalized velocity ``v`` (k, n) along it."""
    path = path_arrays(record)
    impulse = problem.Wn @ path["Pn"][None, :]
    if problem.d:
        impulse = impulse + problem.Wt @ path["Pt"].T
    path["v"] = problem.v + problem.solve_mass(impulse).T
    return path


LAWS.register(DarbouxKeller())

# The study this law declares, as data: its stick and slip phases along one impact.
DarbouxKeller.studies = (
    {
        "shape": "impact_path",
        "case": "lamina",
        "title": "stick and slip phases along the normal impulse",
    },
)
