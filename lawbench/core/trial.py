"""A law solved on a scene or a problem: the `Trial`, and the entry points that make one.

`solve`, `evaluate` and `solve_batch` take a law (a registered name or a `Law`) and a scene (a
registered name or a `Case`) or an `ImpactProblem`; a scene's parameters follow as keywords,
the law's options as ``options``. Everything a check reads is in the trial.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from lawbench.core.case import CASES, Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS, Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem

if TYPE_CHECKING:
    from lawbench.core.batch import OutcomeBatch, ProblemBatch


@dataclass(frozen=True)
class Trial:
    """One law solved on one problem: everything a check may read.

    ``case`` and ``params`` are the scene and its complete parameters when the problem was
    built from a registered scene; None and empty for a problem given as it is.
    """

    law: Law
    case: Case | None
    params: dict[str, Any]
    options: dict[str, Any]
    problem: ImpactProblem
    outcome: Outcome
    # Settings of the checks that solve again (for example continuity's perturbation sizes).
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def scene(self) -> str:
        """The scene's name, or 'problem' for a problem given as it is."""
        return self.case.name if self.case is not None else "problem"


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
    TypeError
        An argument of the wrong type; the message names it.
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
    law, given = _law(law), _options(options)
    if isinstance(case, ImpactProblem):
        if params:
            raise InvalidProblem(
                f"scene parameters {sorted(params)} given with a problem: a problem is solved "
                "as it is"
            )
        scene, full, problem = None, {}, case
    elif isinstance(case, str | Case):
        scene = CASES.get(case)
        full = scene.parameters(**params)
        problem = scene.build_from(full)
    else:
        raise TypeError(
            "case must be a scene name (str), a Case or an ImpactProblem, not "
            f"{type(case).__name__}"
        )
    outcome = law.resolve(problem, **given)
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
    from lawbench.core.batch import ProblemBatch  # on first use: a single solve needs no batch

    law = _law(law)
    if not isinstance(batch, ProblemBatch):
        batch = ProblemBatch.from_problems(list(batch))
    return law.resolve_batch(batch, **_options(options))


def _law(law: object) -> Law:
    """The law named by the argument ``law``: a registered name or a `Law`."""
    if not isinstance(law, str | Law):
        raise TypeError(f"law must be a law name (str) or a Law, not {type(law).__name__}")
    return LAWS.get(law)


def _options(options: object) -> dict[str, Any]:
    """The argument ``options`` as a dict: a mapping of option names to values, or None."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(
            f"options must be a mapping of option names to values, not {type(options).__name__}"
        )
    return dict(options)
