"""Moreau's plastic frictionless impact of many contacts as a projection in the velocities.

Whether it answers is `Moreau._resolve`'s choice (the law's docstring); where clarabel fails
for want of precision it hands the impact on to the LCP in the impulses (`Moreau`'s `_lcp`).
"""

from __future__ import annotations

from typing import Any

from lawbench.core.errors import BudgetExceeded, SolverFailure
from lawbench.core.problem import ImpactProblem
from lawbench.numerics.solvers import LCPResult, project_on_cone


def projected(problem: ImpactProblem, options: dict[str, Any]) -> LCPResult | None:
    """The plastic impact as a projection on the cone of admissible velocities, or None.

    None where clarabel's velocity QP fails for want of precision: a mass matrix with a stiff
    coordinate the contacts do not move (condition 1e9 and more) leaves its multipliers off by
    the contacts' own velocities, and the LCP on the Delassus matrix, which holds the contacts'
    coordinates only, is the well-conditioned form of the same law (an LCP without a solution
    fails there too, saying so). A spent budget stops the solve.
    """
    try:
        return project_on_cone(
            problem.M,
            problem.v,
            problem.Wn,
            problem.delassus,
            options["tol"],
            options["polish"],
        )
    except BudgetExceeded:
        raise
    except SolverFailure:
        return None
