"""What a check reads and returns, and the registry of checks.

A check function reads a `Trial` and returns ``(value, passed, detail)``: ``passed`` None when
the check does not apply (the detail says why). `run_checks` turns that raw result into a
verdict of the taxonomy (`lawbench.verdicts`) from the law's findings and guarantees.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from lawbench.case import Case
from lawbench.law import Law
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem
from lawbench.verdicts import Claim, Verdict, judge

if TYPE_CHECKING:
    import pandas as pd

# Relative tolerance of the verdicts: a law that is exact must pass them to rounding.
TOLERANCE = 1e-9


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


def run_checks(trial: Trial, names: list[str] | None = None) -> CheckResults:
    """Run the named checks on ``trial`` (by default every single-solve check), in order."""
    return CheckResults({name: CHECKS[name](trial) for name in names or SINGLE_SOLVE})
