"""Sequential impacts: binary Newton impacts, one contact at a time, until none approaches.

Source: the sequential treatment of multiple impacts in Brogliato, *An introduction to impact
dynamics* (2010), two balls and a wall, equations (27)-(28), and the three-ball chain. Each
binary impact applies Newton's law ``un+_j = -e_j un-_j`` at the one contact ``j`` chosen, the
others ignored: ``Pn_j = -(1 + e_j) un_j / G_jj`` with ``G`` the Delassus matrix; then every gap
rate is updated and the next approaching contact is chosen.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart. A contact approaches when its gap
rate is below ``-1e-12`` times the largest pre-impact gap rate magnitude, so sequences that
converge geometrically (e < 1 against a wall) end. The option ``order`` is the rule: sweeps
over the contacts by increasing index (``left_to_right``) or decreasing index
(``right_to_left``), striking each contact that approaches when its turn comes, until a sweep
strikes none; or always the fastest approaching contact (``fastest_first``, ties to the lowest
index). The sequence of binary
impacts is in ``diagnostics['sequence']`` (the first 10 000; ``diagnostics['impacts']`` counts
them all, and the option ``path`` returns the velocity after each). More than ``max_steps``
raise `SolverFailure` with the count: with small e a chain can need infinitely many impacts
(inelastic collapse, McNamara and Young, Phys. Fluids A 4, 1992), and the sequence only ends
here because approach speeds below the tolerance count as rest.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.core.guards import current_budget
from lawbench.core.law import LAWS, Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.laws._claims import RIGID_DISPERSION, keeps_energy, never_creates_energy
from lawbench.laws._options import bound, path_option

APPROACH_TOLERANCE = 1e-12
RECORDED = 10_000
ORDERS = ("left_to_right", "right_to_left", "fastest_first")


class Sequential(Law):
    """Binary Newton impacts in a chosen order until no contact approaches."""

    name = "sequential"
    summary = "pairwise binary Newton impacts in a chosen order until no contact approaches"
    source = "Brogliato 2010, eqs. (27)-(28): sequences of binary impacts"
    tags = Tags(several_contacts=True, accuracy_knob="order")
    separating_rule = (
        "binary impacts strike approaching contacts only: a separating contact takes part "
        "once the others make it approach"
    )
    findings = (RIGID_DISPERSION,)
    guarantees = (
        keeps_energy(
            "Brogliato 2010, binary impacts",
            "each binary impact at e = 1 keeps the energy of the pair",
        ),
        never_creates_energy(
            "Brogliato 2010, binary impacts",
            "each binary impact loses (1 - e^2) of the energy of the pair's relative motion",
        ),
    )
    options = (
        Spec(
            "order",
            "left_to_right",
            "which approaching contact goes next",
            kind="str",
            choices=ORDERS,
        ),
        bound("max_steps", 1_000_000, "bound on the number of binary impacts"),
        path_option("the velocities after each binary impact"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        impacts = _BinaryImpacts(problem)
        if options["order"] == "fastest_first":
            while impacts.un.min() < impacts.threshold:
                impacts.strike(int(np.argmin(impacts.un)))
        else:
            sweep = (
                range(problem.m) if options["order"] == "left_to_right" else range(problem.m)[::-1]
            )
            while impacts.un.min() < impacts.threshold:
                for j in sweep:
                    if impacts.un[j] < impacts.threshold:
                        impacts.strike(j)
        diagnostics = {
            "formulation": f"binary impacts, {options['order']}",
            "impacts": len(impacts.contacts),
            "sequence": [
                {"contact": j, "impulse": p}
                for j, p in zip(
                    impacts.contacts[:RECORDED], impacts.impulses[:RECORDED], strict=True
                )
            ],
        }
        path = impacts.path() if options["path"] else None
        return Outcome.from_impulses(problem, impacts.Pn, diagnostics=diagnostics, path=path)


class _BinaryImpacts:
    """The state of a sequence of binary impacts: gap rates, impulses, the impacts so far."""

    def __init__(self, problem: ImpactProblem) -> None:
        self.problem = problem
        self.spend = current_budget()
        self.G = problem.delassus
        self.e = problem.restitution("kinematic")
        self.un = problem.un.copy()
        self.threshold = -APPROACH_TOLERANCE * np.abs(self.un).max()
        self.Pn = np.zeros(problem.m)
        self.contacts: list[int] = []
        self.impulses: list[float] = []

    def strike(self, j: int) -> None:
        """Newton's binary impact at contact j alone, a step of the solve's budget."""
        self.spend.step(
            "binary impacts",
            "contacts still approach: a sequence that does not end, such as an inelastic collapse",
        )
        impulse = -(1.0 + self.e[j]) * self.un[j] / self.G[j, j]
        self.Pn[j] += impulse
        self.un += self.G[:, j] * impulse
        self.contacts.append(j)
        self.impulses.append(float(impulse))

    def path(self) -> dict[str, np.ndarray]:
        """Velocities before the first and after each binary impact, one row each."""
        problem, count = self.problem, len(self.contacts)
        steps = np.zeros((count + 1, problem.m))
        steps[np.arange(1, count + 1), self.contacts] = self.impulses
        return {"v": problem.v + np.cumsum(steps, axis=0) @ problem.solve_mass(problem.Wn).T}


LAWS.register(Sequential())
