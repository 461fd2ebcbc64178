"""What a check reads and returns, and the registry of checks."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from lawbench.case import Case
from lawbench.law import Law
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem

# Relative tolerance of the verdicts: a law that is exact must pass them to rounding.
TOLERANCE = 1e-9


@dataclass(frozen=True)
class Trial:
    """One law solved on one case: everything a check may read."""

    law: Law
    case: Case
    params: dict[str, Any]
    options: dict[str, Any]
    problem: ImpactProblem
    outcome: Outcome
    # Settings of the checks that solve again (for example continuity's perturbation sizes).
    settings: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class CheckResult:
    """A check's value, verdict and reason; ``passed`` None means the check was skipped."""

    name: str
    value: float | None
    passed: bool | None
    detail: str

    def as_dict(self) -> dict[str, Any]:
        """The JSON form: ``{'value', 'passed', 'detail'}``."""
        return {"value": self.value, "passed": self.passed, "detail": self.detail}


Check = Callable[[Trial], CheckResult]
CHECKS: dict[str, Check] = {}
# The checks that read the one outcome of a trial; the others solve the case again.
SINGLE_SOLVE: list[str] = []


def check(name: str, several_solves: bool = False) -> Callable[[Callable[[Trial], tuple]], Check]:
    """Register a function returning ``(value, passed, detail)`` as the check ``name``.

    The function returns ``(None, None, reason)`` when the check does not apply.
    ``several_solves`` marks a check that solves the case again (costly; run on request).
    """

    def register(function: Callable[[Trial], tuple]) -> Check:
        def run(trial: Trial) -> CheckResult:
            return CheckResult(name, *function(trial))

        run.__doc__ = function.__doc__
        CHECKS[name] = run
        if not several_solves:
            SINGLE_SOLVE.append(name)
        return run

    return register


def run_checks(trial: Trial, names: list[str] | None = None) -> dict[str, CheckResult]:
    """Run the named checks on ``trial`` (by default every single-solve check), in order."""
    return {name: CHECKS[name](trial) for name in names or SINGLE_SOLVE}
