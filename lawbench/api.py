"""The public entry points: solve a law on a case, or evaluate it with every check."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from lawbench.case import CASES, Case
from lawbench.checks import Trial
from lawbench.law import LAWS, Law
from lawbench.outcome import Outcome


def solve(
    law: str | Law, case: str | Case, options: Mapping[str, Any] | None = None, **params: Any
) -> Outcome:
    """Solve the impact of ``case`` with ``law``.

    Parameters
    ----------
    law : str or Law
        A registered law name (``lawbench list``) or a law object.
    case : str or Case
        A registered case name or a case object.
    options : mapping, optional
        The law's options (ordering, variant, tolerance).
    **params
        The case's parameters; the others take their defaults.

    Returns
    -------
    Outcome

    Raises
    ------
    InvalidProblem
        Unknown law, case, parameter or option, or a bad value.
    NotApplicable
        The law cannot treat the case.
    SolverFailure
        The law's numerical method failed.

    Examples
    --------
    >>> import lawbench
    >>> lawbench.solve("newton", "three_ball_chain", e=1).v_plus.round(6).tolist()
    [-0.333333, 0.666667, 0.666667]
    """
    return evaluate(law, case, options, **params).outcome


def evaluate(
    law: str | Law, case: str | Case, options: Mapping[str, Any] | None = None, **params: Any
) -> Trial:
    """Like `solve`, but return the whole `Trial` (complete parameters, problem, outcome)."""
    law, case = LAWS.get(law), CASES.get(case)
    full = case.parameters(**params)
    problem = case.build(**full)
    outcome = law.resolve(problem, **dict(options or {}))
    return Trial(law, case, full, outcome.diagnostics["options"], problem, outcome)
