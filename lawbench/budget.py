"""A wall-clock budget for the laws that integrate, so that no solve runs past its time."""

from __future__ import annotations

import time

from lawbench.errors import BudgetExceeded
from lawbench.spec import Spec

OPTION = Spec(
    "max_seconds", 60.0, "wall-clock budget of one solve", "s", "float", 0.0, low_open=True
)


class Deadline:
    """Raises `SolverFailure` once ``seconds`` have passed since it was made."""

    def __init__(self, law: str, seconds: float) -> None:
        self.law, self.seconds = law, seconds
        self.end = time.monotonic() + seconds

    def check(self) -> None:
        """Raise if the budget is spent."""
        if time.monotonic() > self.end:
            raise BudgetExceeded(
                f"{self.law}: time budget ran out ({self.seconds:g} s, max_seconds)",
                "max_seconds",
                self.seconds,
                self.seconds,
            )
