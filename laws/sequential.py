"""Sequential impacts: binary Newton impacts, one contact at a time, until none approaches.

Source: the sequential treatment of multiple impacts in Brogliato, *An introduction to impact
dynamics* (2010), two balls and a wall, equations (27)-(28), and the three-ball chain. Each
binary impact applies Newton's law ``un+_j = -e_j un-_j`` at the one contact ``j`` chosen, the
others ignored: ``Pn_j = -(1 + e_j) un_j / G_jj`` with ``G`` the Delassus matrix; then every gap
rate is updated and the next approaching contact is chosen.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart. A contact approaches when its gap
rate is below ``-1e-12`` times the largest pre-impact gap rate magnitude, so sequences that
converge geometrically (e < 1 against a wall) end. The option ``order`` chooses among the
approaching contacts: the lowest index (``left_to_right``), the highest (``right_to_left``) or
the fastest approach (``fastest_first``, ties to the lowest index). The sequence of binary
impacts is in ``diagnostics['sequence']``; more than ``max_impacts`` of them raise
`SolverFailure` with the count (a sequence that does not end).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.errors import SolverFailure
from lawbench.law import LAWS, Capabilities, Law
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem
from lawbench.spec import Spec

APPROACH_TOLERANCE = 1e-12
ORDERS = {
    "left_to_right": lambda approaching, un: approaching[0],
    "right_to_left": lambda approaching, un: approaching[-1],
    "fastest_first": lambda approaching, un: approaching[np.argmin(un[approaching])],
}


class Sequential(Law):
    """Binary Newton impacts in a chosen order until no contact approaches."""

    name = "sequential"
    summary = "pairwise binary Newton impacts in a chosen order until no contact approaches"
    source = "Brogliato 2010, eqs. (27)-(28): sequences of binary impacts"
    capabilities = Capabilities(several_contacts=True, accuracy_knob="order")
    options = (
        Spec(
            "order",
            "left_to_right",
            "which approaching contact goes next",
            "",
            "str",
            choices=tuple(ORDERS),
        ),
        Spec("max_impacts", 100_000, "bound on the number of binary impacts", "", "int", 1),
        Spec("path", False, "return the velocities after each binary impact", "", "bool"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        G, e = problem.delassus, problem.restitution("newton")
        push = problem.solve_mass(problem.Wn)
        choose = ORDERS[options["order"]]
        un = problem.un.copy()
        threshold = -APPROACH_TOLERANCE * np.abs(un).max()
        Pn = np.zeros(problem.m)
        contacts: list[int] = []
        impulses: list[float] = []
        while (approaching := np.flatnonzero(un < threshold)).size:
            if len(contacts) == options["max_impacts"]:
                raise SolverFailure(
                    f"sequential: contacts still approach after {len(contacts)} binary impacts "
                    f"(max_impacts = {options['max_impacts']})"
                )
            j = int(choose(approaching, un))
            impulse = -(1.0 + e[j]) * un[j] / G[j, j]
            Pn[j] += impulse
            un += G[:, j] * impulse
            contacts.append(j)
            impulses.append(float(impulse))
        diagnostics = {
            "formulation": f"binary impacts, {options['order']}",
            "impacts": len(contacts),
            "sequence": [
                {"contact": j, "impulse": p} for j, p in zip(contacts, impulses, strict=True)
            ],
        }
        path = None
        if options["path"]:
            steps = np.zeros((len(contacts), problem.m))
            steps[np.arange(len(contacts)), contacts] = impulses
            path = {"v": problem.v + np.vstack([np.zeros(problem.m), np.cumsum(steps, 0)]) @ push.T}
        return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics, path=path)


LAWS.register(Sequential())
