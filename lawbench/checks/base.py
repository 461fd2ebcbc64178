"""What a check reads and returns, and the registry of checks.

A check function reads a `Trial` and returns ``(value, passed, detail)``: ``passed`` None when
the check does not apply (the detail says why). `run_checks` turns that raw result into a
verdict of the taxonomy (`lawbench.core.verdicts`) from the law's findings and guarantees.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from lawbench.core.case import Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import Law
from lawbench.core.problem import ImpactProblem
from lawbench.core.trial import Trial, evaluate
from lawbench.core.verdicts import Claim, Verdict

if TYPE_CHECKING:
    import pandas as pd

# Relative tolerance of the verdicts: a law that is exact must pass them to rounding.
TOLERANCE = 1e-9


@dataclass(frozen=True)
class CheckResult:
    """A check's value, raw result, verdict and reason.

    Attributes
    ----------
    name : str
        The check.
    value : float or None
        What it measured; None when it does not apply.
    passed : bool or None
        Its raw result; None when it does not apply.
    detail : str
        The reason, in words.
    verdict : Verdict
        The class of the taxonomy.
    claim : Claim or None
        The finding or guarantee of the law that decided a failed check's verdict.
    """

    name: str
    value: float | None
    passed: bool | None
    detail: str
    verdict: Verdict = Verdict.UNEXPLAINED
    claim: Claim | None = None

    def as_dict(self) -> dict[str, Any]:
        """The JSON form: value, raw result, verdict, detail and the deciding claim's reason."""
        return {
            "value": self.value,
            "passed": self.passed,
            "verdict": str(self.verdict),
            "detail": self.detail,
            "claim": self.claim.describe() if self.claim else None,
        }


class CheckResults(dict[str, CheckResult]):
    """Check name -> result, as `run_checks` returns them, with a tidy frame and HTML view."""

    def to_frame(self) -> pd.DataFrame:
        """One row per check: name, verdict, value, raw result, detail, deciding claim.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        rows = [{"check": name, **result.as_dict()} for name, result in self.items()]
        columns = ["check", "verdict", "value", "passed", "detail", "claim"]
        return pd.DataFrame(rows, columns=columns)

    def _repr_html_(self) -> str:
        return self.to_frame().to_html(index=False)


def judge(trial: Trial, check: str, passed: bool | None, promised: bool) -> tuple[Verdict, Any]:
    """The verdict of a check's raw result on ``trial``, and the claim that decided it.

    Parameters
    ----------
    trial : Trial
        The solve the check read.
    check : str
        The check's name.
    passed : bool or None
        The check's result; None when it does not apply.
    promised : bool
        Whether every law promises this check everywhere.
    """
    if passed is None:
        return Verdict.REFUSED, None
    if passed:
        return Verdict.HOLDS, None
    for claim in trial.law.findings:
        if claim.check == check and claim.region(trial):
            return Verdict.LAW_PROPERTY, claim
    for claim in trial.law.guarantees:
        if claim.check == check and claim.region(trial):
            return Verdict.NUMERICAL_FAILURE, claim
    if promised:
        return Verdict.NUMERICAL_FAILURE, None
    return Verdict.UNEXPLAINED, None


Check = Callable[[Trial], CheckResult]
CHECKS: dict[str, Check] = {}
# The checks that read the one outcome of a trial; the others solve the problem again.
SINGLE_SOLVE: list[str] = []


def check(
    name: str, several_solves: bool = False, promised: bool = False
) -> Callable[[Callable[[Trial], tuple]], Check]:
    """Register a function returning ``(value, passed, detail)`` as the check ``name``.

    The function returns ``(None, None, reason)`` when the check does not apply.
    ``several_solves`` marks a check that solves the problem again (costly).
    ``promised`` marks a check every law promises everywhere (a failure is numerical unless a
    finding of the law says otherwise).
    """

    def register(function: Callable[[Trial], tuple]) -> Check:
        def run(trial: Trial) -> CheckResult:
            value, passed, detail = function(trial)
            verdict, claim = judge(trial, name, passed, promised)
            return CheckResult(name, value, passed, detail, verdict, claim)

        run.__doc__ = function.__doc__
        CHECKS[name] = run
        if not several_solves:
            SINGLE_SOLVE.append(name)
        return run

    return register


def run_checks(
    law: str | Law | Trial,
    case: str | Case | ImpactProblem | None = None,
    options: Mapping[str, Any] | None = None,
    *,
    checks: str | Sequence[str] | None = None,
    **params: Any,
) -> CheckResults:
    """Solve ``law`` on a scene or a problem, as `lawbench.solve` does, and run the checks.

    Parameters
    ----------
    law : str, Law or Trial
        A registered law name or a law object; or a trial already solved (`lawbench.evaluate`),
        given alone.
    case : str, Case or ImpactProblem
        A registered scene name, a scene object, or an impact problem of your own.
    options : mapping, optional
        The law's options.
    checks : str or sequence of str, optional
        The checks to run, in order; by default every single-solve check.
    **params
        The scene's parameters; the others take their defaults.

    Returns
    -------
    CheckResults
        Check name -> result.

    Raises
    ------
    TypeError
        An argument of the wrong type, or a trial given with a scene, options or parameters.
    InvalidProblem
        An unknown check, or what `lawbench.solve` raises for bad input.

    Examples
    --------
    >>> import lawbench
    >>> results = lawbench.run_checks("newton", "three_ball_chain", e=0.5)
    >>> str(results["energy_gain"].verdict)
    'holds'
    """
    if isinstance(law, Trial):
        given = {"case": case, "options": options, **params}
        extra = {name: value for name, value in given.items() if value is not None}
        if extra:
            name, value = next(iter(extra.items()))
            raise TypeError(
                f"run_checks() takes a trial alone, but {name} was given with it ({value!r}); "
                "name the checks with checks=[...]"
            )
        trial = law
    elif case is None:
        raise TypeError(
            "run_checks() needs the argument case (a scene name, a Case or an ImpactProblem) "
            "with a law, or a trial alone"
        )
    else:
        trial = evaluate(law, case, options, **params)
    return CheckResults({name: CHECKS[name](trial) for name in _check_names(checks)})


def _check_names(checks: object) -> list[str]:
    """The argument ``checks`` as a list of known check names (every single-solve one if None)."""
    if checks is None:
        return list(SINGLE_SOLVE)
    names = [checks] if isinstance(checks, str) else checks
    if not isinstance(names, Sequence) or not all(isinstance(n, str) for n in names):
        raise TypeError(f"checks must be a check name or a sequence of them, not {checks!r}")
    unknown = [name for name in names if name not in CHECKS]
    if unknown:
        raise InvalidProblem(f"unknown check {unknown[0]!r}; known: {', '.join(CHECKS)}")
    return list(names)
