"""Moreau's frictionless impact as a projection in the velocities or an LCP in the impulses.

Which of them answers is `Moreau._resolve`'s choice (the law's docstring); here each is solved
with clarabel and polished, and handed on where clarabel fails for want of precision.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.core.errors import BudgetExceeded, SolverFailure
from lawbench.core.problem import ImpactProblem
from lawbench.numerics.solvers import (
    LCPResult,
    project_in_kinetic_metric,
    project_on_cone,
    solve_lcp,
)


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


def lcp(problem: ImpactProblem, q: np.ndarray, options: dict[str, Any]) -> LCPResult:
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
