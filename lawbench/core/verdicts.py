"""The verdict taxonomy: every cell of every table gets exactly one class.

A check says whether something holds on one solve; the verdict says what that means for the
law, from what the law declares of itself:

- *holds*: the check passes;
- *law property*: it fails where one of the law's findings says its theory predicts it (a
  `Claim` in ``Law.findings``, with its source and the region where it applies);
- *numerical failure*: it fails where the law's theory says it must hold (a claim in
  ``Law.guarantees``, or a check every law promises): a bug until explained;
- *refused*: the law cannot treat the problem (`NotApplicable`), or the check does not apply
  to it, with the reason;
- *budget*: the law ran out of a named budget (`BudgetExceeded`: steps, events, iterations,
  seconds), with the amount;
- *unexplained*: anything else, a bug to fix or a finding to write.

Findings are looked at before guarantees: a region where the theory predicts a failure is
carved out of a wider promise.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from lawbench.core.errors import BudgetExceeded, InvalidProblem, NotApplicable, SolverFailure


class Verdict(StrEnum):
    """The class of a cell."""

    HOLDS = "holds"
    LAW_PROPERTY = "law property"
    NUMERICAL_FAILURE = "numerical failure"
    REFUSED = "refused"
    BUDGET = "budget"
    UNEXPLAINED = "unexplained"

    @classmethod
    def _missing_(cls, value: object) -> Verdict:
        raise InvalidProblem(
            f"verdict {value!r}: must be one of {', '.join(verdict.value for verdict in cls)}"
        )


# Classes a finished, trustworthy table may hold.
ACCEPTABLE = frozenset({Verdict.HOLDS, Verdict.LAW_PROPERTY, Verdict.REFUSED, Verdict.BUDGET})


@dataclass(frozen=True)
class Region:
    """A set of trials, described in words and decided by a predicate.

    The predicate reads a `lawbench.core.trial.Trial`. The trial holds the law, whose claims
    hold regions, so the type is named here only in words (``Any``): the core's modules import
    one way.

    Regions combine with ``&`` (both), ``|`` (either) and ``~`` (not).
    """

    text: str
    contains: Callable[[Any], bool]

    def __and__(self, other: Region) -> Region:
        return Region(f"{self.text} and {other.text}", lambda t: self(t) and other(t))

    def __or__(self, other: Region) -> Region:
        return Region(f"{self.text} or {other.text}", lambda t: self(t) or other(t))

    def __invert__(self) -> Region:
        return Region(f"not ({self.text})", lambda t: not self(t))

    def __call__(self, trial: Any) -> bool:
        """Whether ``trial`` lies in the region."""
        return bool(self.contains(trial))


EVERYWHERE = Region("every problem", lambda trial: True)


@dataclass(frozen=True)
class Claim:
    """What a law's theory says of one check in one region.

    In ``Law.findings`` a claim says the check fails there (a law property); in
    ``Law.guarantees`` it says the check holds there (a failure is numerical).

    Attributes
    ----------
    check : str
        The check's name.
    region : Region
        Where the claim applies.
    source : str
        The paper or book (and equation) the claim comes from.
    reason : str
        Why, in the physics' words.
    witnesses : tuple of (case, example)
        Named examples where a finding is shown; tests hold each to it.
    """

    check: str
    region: Region
    source: str
    reason: str
    witnesses: tuple[tuple[str, str], ...] = ()

    def describe(self) -> str:
        """One line: the reason, where it applies, and the source."""
        return f"{self.reason} (where: {self.region.text}; source: {self.source})"


def of_error(error: BaseException) -> Verdict:
    """The verdict of a cell whose solve raised ``error``."""
    if isinstance(error, NotApplicable):
        return Verdict.REFUSED
    if isinstance(error, BudgetExceeded):
        return Verdict.BUDGET
    if isinstance(error, SolverFailure):
        return Verdict.NUMERICAL_FAILURE
    return Verdict.UNEXPLAINED
