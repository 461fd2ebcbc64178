"""A law solved on a scene or a problem: the `Trial`, and the one way into every solve.

`make_trial` is that way: it takes a law (a registered name or a `Law`) and any source of a
problem (a scene with its parameters, an `ImpactProblem`, a `ContactProblem`, a `ProblemBatch`,
or anything that carries a ``problem`` with what was learned while obtaining it, such as a
problem file as read), checks the parameters once, builds the scene once, applies a named
transform (`lawbench.core.transforms`), and solves under the law's budget. The command line,
the study runner, the checks, the batch API and the bench call it; `solve`, `evaluate` and
`solve_batch` are its public faces. Everything a check reads is in the trial.

It also decides whether an impact's answer may be shown: an answer that breaks a promise (a check
that the law, or every law, guarantees fails: a numerical failure) raises `SolverFailure`, for
the command line and `solve` alike. The judges are registered in `PROMISES` by the checks
(`lawbench.checks`, which every law's package imports to state its claims); a caller that classes
every answer itself (the study runner, `run_checks`) asks for the answer as it is.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from lawbench.core.case import CASES, Case
from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.errors import InvalidProblem, SolverFailure
from lawbench.core.guards import alarm, watch_interrupts
from lawbench.core.law import LAWS, Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.transforms import apply

if TYPE_CHECKING:
    from lawbench.core.batch import OutcomeBatch, ProblemBatch


class Carried(Protocol):
    """A problem with what was learned while obtaining it (a file as read, a measurement)."""

    problem: ImpactProblem | ContactProblem
    facts: Any


Source = str | Case | ImpactProblem | ContactProblem | Carried


@dataclass(frozen=True)
class Trial:
    """One law solved on one problem: everything a check may read.

    ``case`` and ``params`` are the scene and its complete parameters when the problem was
    built from a registered scene; None and empty for a problem given as it is (or transformed).
    A contact-space problem's answer is a `ContactSolution`, a batch's an `OutcomeBatch`.
    """

    law: Law
    case: Case | None
    params: dict[str, Any]
    options: dict[str, Any]
    problem: ImpactProblem | ContactProblem | ProblemBatch
    outcome: Outcome | ContactSolution | OutcomeBatch
    # Settings of the checks that solve again (for example continuity's perturbation sizes).
    settings: dict[str, Any] = field(default_factory=dict)
    # What was learned while obtaining the problem (a file's form and storage), or None.
    facts: Any = None
    # The results of the checks run on this trial so far, by name: a check is run once.
    checked: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

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

    An answer that breaks a promise of the law, or of every law (a check that must hold fails:
    admissibility, impulse sign, friction cone, momentum, a reference, a guarantee), is never
    returned: it raises `SolverFailure`, as ``lawbench solve`` exits with status 4.

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
        The law's numerical method failed, or its answer breaks a promise.

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

    The trial is what `run_checks` reads. An answer that breaks a promise raises
    `SolverFailure`, as in `solve`; `run_checks` given a law and a scene shows its verdicts.

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
    return make_trial(law, case, params=params, options=options)


def make_trial(
    law: str | Law,
    source: Source | ProblemBatch,
    *,
    params: Mapping[str, Any] | None = None,
    options: Mapping[str, Any] | None = None,
    transform: str = "",
    settings: Mapping[str, Any] | None = None,
    max_seconds: float | None = None,
    judged: bool = True,
) -> Trial:
    """Solve ``source`` with ``law``: the one way into every solve.

    Parameters
    ----------
    law : str or Law
        A registered law name or a law object.
    source : str, Case, ImpactProblem, ContactProblem, ProblemBatch, or a carried problem
        A scene (its parameters in ``params``), a problem given as it is, or an object with a
        ``problem`` and the ``facts`` learned while obtaining it.
    params : mapping, optional
        The scene's parameters, checked once; the others take their defaults.
    options : mapping, optional
        The law's options, checked once by the law.
    transform : str
        A named transform of the built impact problem (``grazing=1e-08``), '' for none.
    settings : mapping, optional
        Settings of the checks that solve again, carried by the trial.
    max_seconds : float, optional
        A wall-clock bound on building the problem, and another on solving it. Whether given or
        not, each is stopped from outside (`lawbench.core.guards.alarm`) once the law's own
        ``max_seconds`` and `OUTSIDE_GRACE_S` have passed, whatever the law does, so that a law
        that ignores its budget still ends with `BudgetExceeded`. Between the two, the law's
        one-time work of the process (`Law.prepare`: compiling its kernels) is no part of
        either bound, nor of the solve's budget.
    judged : bool
        Whether an impact's answer that breaks a promise raises `SolverFailure` (the judges of
        `PROMISES`, run after the solve and outside its bound). False returns it as it is, for
        a caller that classes every answer with the checks' verdicts.

    Returns
    -------
    Trial

    Raises
    ------
    InvalidProblem
        An unknown law, scene, parameter, option or transform, a bad value, or parameters or a
        transform given with a source that takes none.
    NotApplicable, SolverFailure
        As the law's solve raises them; `SolverFailure` too for a ``judged`` answer that
        breaks a promise.
    """
    law = _law(law)
    options = _options(options)
    watch_interrupts()
    bound = _outside_bound(law, options, max_seconds)
    with alarm(bound):
        problem, scene, full, facts = _given(source, params, transform)
    law.prepare(problem)
    with alarm(bound):
        outcome = _answer(law, problem, options)
    values = outcome.diagnostics["options"]
    trial = Trial(law, scene, full, values, problem, outcome, dict(settings or {}), facts)
    if judged and isinstance(trial.outcome, Outcome):
        for judge in PROMISES:
            broken = judge(trial)
            if broken:
                raise SolverFailure(broken)
    return trial


# The judges of an impact's answer: each returns why the answer of a trial breaks a promise of
# its law or of every law, or ''. The checks register theirs (`lawbench.checks`).
PROMISES: list[Callable[[Trial], str]] = []


# Seconds past a law's own ``max_seconds`` before the guard from outside stops it: the law's
# budget, which says what it ran out of, speaks first.
OUTSIDE_GRACE_S = 1.0


def _outside_bound(law: Law, options: dict[str, Any], max_seconds: float | None) -> float:
    """The wall-clock bound of a solve: the law's ``max_seconds`` and grace, or ``max_seconds``."""
    own = law.option_values(options)["max_seconds"] + OUTSIDE_GRACE_S
    return own if max_seconds is None else min(own, max_seconds)


def _given(
    source: Source | ProblemBatch, params: Mapping[str, Any] | None, transform: str
) -> tuple[Any, Case | None, dict[str, Any], Any]:
    """The problem of ``source``, checked and built once, then transformed.

    With its scene, complete parameters and facts (None, {} and None where not known).
    """
    facts, scene, full = None, None, {}
    if hasattr(source, "facts"):
        source, facts = source.problem, source.facts
    if isinstance(source, str | Case):
        scene = CASES.get(source)
        full = scene.parameters(**(params or {}))
        problem = scene.build_from(full)
    elif params:
        raise InvalidProblem(
            f"scene parameters {sorted(params)} given with a problem: a problem is solved as it is"
        )
    else:
        problem = source
    if transform:
        problem = _transformed(transform, problem)
        scene, full = None, {}
    return problem, scene, full, facts


def _transformed(transform: str, problem: object) -> ImpactProblem:
    """The impact ``problem`` changed by the named ``transform``."""
    if not isinstance(problem, ImpactProblem):
        raise InvalidProblem(
            f"transform {transform!r} changes an impact problem, not a {type(problem).__name__}"
        )
    return apply(transform, problem)


def _answer(
    law: Law, problem: object, options: dict[str, Any]
) -> Outcome | ContactSolution | OutcomeBatch:
    """The law's answer to ``problem``, by the method that treats its kind."""
    if isinstance(problem, ImpactProblem):
        return law.resolve(problem, **options)
    if isinstance(problem, ContactProblem):
        return law.solve_contact(problem, **options)
    from lawbench.core.batch import ProblemBatch  # here: a single solve needs no batch

    if isinstance(problem, ProblemBatch):
        return law.resolve_batch(problem, **options)
    raise TypeError(
        f"case must be a scene name (str), a Case or an ImpactProblem, not {type(problem).__name__}"
    )


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

    if not isinstance(batch, ProblemBatch):
        _law(law)
        batch = ProblemBatch.from_problems(list(batch))
    return make_trial(law, batch, options=options).outcome


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
