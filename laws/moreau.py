"""Moreau's impact law: projection on the tangent cone in the kinetic metric.

Source: J.J. Moreau (1983, 1985, 1988) as given by Brogliato, *An introduction to impact
dynamics* (2010), equations (16)-(17):
``v+ = -e v- + (1 + e) argmin { |z - v-|_M^2 / 2 : Wn.T z >= 0 }`` for one coefficient ``e``,
and per contact ``0 <= un+ + E un- _|_ Pn >= 0`` with ``E`` the kinematic coefficients.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart.

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

Formulations (``diagnostics['formulation']``): closed form for one contact, decoupled for a
diagonal Delassus matrix, the cone projection (a QP in the velocities, solved with clarabel)
for one coefficient when no closed contact separates, and the LCP in the impulses (a QP in
``Pn >= 0``, solved with clarabel) otherwise.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.law import LAWS, Capabilities, Law
from lawbench.mechanics import is_diagonal
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem
from lawbench.solvers import project_on_cone, solve_lcp
from lawbench.spec import Spec


class Moreau(Law):
    """Moreau's law: ``0 <= un+ + E min(un-, 0) _|_ Pn >= 0``, a cone projection for one e."""

    name = "moreau"
    summary = "Moreau's law: cone projection in the kinetic metric, LCP per contact (clarabel)"
    source = "Moreau 1988; Brogliato 2010, eqs. (16)-(17)"
    capabilities = Capabilities(several_contacts=True, accuracy_knob="tol")
    options = (
        Spec(
            "tol",
            1e-10,
            "clarabel's tolerances (gap and feasibility)",
            "",
            "float",
            0.0,
            1e-2,
            True,
        ),
        Spec("polish", True, "solve clarabel's active set exactly", "", "bool"),
        Spec(
            "separating",
            "unilateral",
            "what a closed contact separating before the impact receives",
            kind="str",
            choices=("unilateral", "restitution"),
        ),
    )

    findings = {
        ("three_ball_chain", "separating contact", "energy_gain"): (
            "contact 1 separates before the impact (un- = 0.75 m/s); dragged into the impact "
            "by ball 2 it is held at un+ = 0 without restitution, and its impulse adds "
            "Pn un- / 2 > 0 to the energy change: kinematic restitution per contact is not "
            "dissipative once a separating contact takes part"
        ),
    }

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        e, un = problem.restitution("newton"), problem.un
        if options["separating"] == "unilateral":
            restituted = np.minimum(un, 0.0)
        else:
            restituted = un
        single_e = len(set(e)) == 1 and np.array_equal(restituted, un)
        if single_e and not is_diagonal(problem.delassus):
            plastic = project_on_cone(
                problem.M,
                problem.v,
                problem.Wn,
                problem.delassus,
                options["tol"],
                options["polish"],
            )
            result, Pn = plastic, (1.0 + e[0]) * plastic.z
            formulation = "cone projection (clarabel)"
        else:
            result = solve_lcp(
                problem.delassus, un + e * restituted, options["tol"], options["polish"]
            )
            Pn, formulation = result.z, result.method
        diagnostics = {
            "formulation": formulation,
            "solver_status": result.solver_status,
            "iterations": result.iterations,
            "polished": result.polished,
        }
        return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics)


LAWS.register(Moreau())
