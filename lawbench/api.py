"""The public entry points: solve a law on a scene or a problem, or evaluate it for the checks."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from lawbench.case import CASES, Case
from lawbench.checks import Trial
from lawbench.errors import InvalidProblem
from lawbench.law import LAWS, Law
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem

if TYPE_CHECKING:
    from lawbench.batch import OutcomeBatch, ProblemBatch


def solve(
    law: str | Law,
    case: str | Case | ImpactProblem,
    options: Mapping[str, Any] | None = None,
    **params: Any,
) -> Outcome:
    """Solve the impact of a scene, or of a problem given as it is, with ``law``.

    Parameters
    ----------
    law : str or Law
        A registered law name (``lawbench list``) or a law object.
    case : str, Case or ImpactProblem
        A registered scene name, a scene object, or an impact problem of your own.
    options : mapping, optional
        The law's options (ordering, variant, tolerance).
    **params
        The scene's parameters; the others take their defaults. None for a problem.

    Returns
    -------
    Outcome

    Raises
    ------
    InvalidProblem
        Unknown law, case, parameter or option, a bad value, or parameters given with a
        problem.
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
    law: str | Law,
    case: str | Case | ImpactProblem,
    options: Mapping[str, Any] | None = None,
    **params: Any,
) -> Trial:
    """Like `solve`, but return the whole `Trial` (complete parameters, problem, outcome).

    The trial is what `run_checks` reads.

    Examples
    --------
    >>> import numpy as np, lawbench
    >>> problem = lawbench.ImpactProblem.from_arrays(
    ...     M=np.eye(2), Wn=[[-1.0], [1.0]], v=[1.0, 0.0], e=1.0
    ... )
    >>> trial = lawbench.evaluate("poisson", problem)
    >>> trial.outcome.v_plus.tolist(), str(lawbench.run_checks(trial)["energy_gain"].verdict)
    ([0.0, 1.0], 'holds')
    """
    law = LAWS.get(law)
    if isinstance(case, ImpactProblem):
        if params:
            raise InvalidProblem(
                f"scene parameters {sorted(params)} given with a problem: a problem is solved "
                "as it is"
            )
        scene, full, problem = None, {}, case
    else:
        scene = CASES.get(case)
        full = scene.parameters(**params)
        problem = scene.build(**full)
    outcome = law.resolve(problem, **dict(options or {}))
    return Trial(law, scene, full, outcome.diagnostics["options"], problem, outcome)


def solve_batch(
    law: str | Law,
    batch: ProblemBatch | Sequence[ImpactProblem],
    options: Mapping[str, Any] | None = None,
) -> OutcomeBatch:
    """Solve many impact problems of one shape with ``law``, vectorized where the law can.

    Parameters
    ----------
    law : str or Law
        A registered law name or a law object.
    batch : ProblemBatch or sequence of ImpactProblem
        Stacked arrays (`ProblemBatch`), or problems of one shape to stack.
    options : mapping, optional
        The law's options, checked once.

    Returns
    -------
    OutcomeBatch
        Stacked outcomes; equal to solving one by one, to rounding.

    Examples
    --------
    >>> import numpy as np, lawbench
    >>> v = np.array([[1.0, 0.0, 0.0], [2.0, 1.0, 0.0]])
    >>> chain = [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]]
    >>> batch = lawbench.ProblemBatch(M=np.eye(3), Wn=chain, v=v, coefficients={"e": 1.0})
    >>> lawbench.solve_batch("moreau", batch).v_plus.round(6).tolist()
    [[-0.333333, 0.666667, 0.666667], [0.0, 1.0, 2.0]]
    """
    from lawbench.batch import ProblemBatch  # on first use: a single solve needs no batch

    if not isinstance(batch, ProblemBatch):
        batch = ProblemBatch.from_problems(list(batch))
    return LAWS.get(law).resolve_batch(batch, **dict(options or {}))
