"""What one solve may spend, and what every solve records: its budget, wall time and warnings.

A `Budget` is what one solve may spend: steps, events and wall-clock seconds, one mechanism for
every law. `lawbench.core.law.Law.resolve` opens one (a context manager, inside a `Watch`) from
the law's options for the time of the solve, and the law's loops spend from `current_budget()`.
"""

from __future__ import annotations

import contextvars
import math
import time
import warnings
from collections.abc import Mapping
from typing import Any

from lawbench.core.errors import BudgetExceeded


class Budget:
    """Steps, events and seconds one solve of law ``law`` may spend.

    Parameters
    ----------
    law : str
        The law's name, for the messages.
    max_seconds : float
        Wall-clock seconds from now.
    max_steps, max_events : int or None
        Counts of steps and of events; None for no bound.
    """

    def __init__(
        self,
        law: str,
        max_seconds: float = math.inf,
        max_steps: int | None = None,
        max_events: int | None = None,
    ) -> None:
        self.law, self.max_seconds = law, max_seconds
        self.max_steps, self.max_events = max_steps, max_events
        self.steps = self.events = 0
        self.start = time.monotonic()

    @classmethod
    def of(cls, law: str, options: Mapping[str, Any]) -> Budget:
        """The budget a law's checked ``options`` set (the ones it declares)."""
        return cls(
            law,
            options.get("max_seconds", math.inf),
            options.get("max_steps"),
            options.get("max_events"),
        )

    @property
    def spent_s(self) -> float:
        """Seconds since the budget was opened."""
        return time.monotonic() - self.start

    @property
    def seconds_left(self) -> float:
        """Seconds left before ``max_seconds`` runs out (never negative)."""
        return max(self.max_seconds - self.spent_s, 0.0)

    def step(self, what: str = "steps", note: str = "") -> None:
        """Spend one step and check the time.

        ``what`` names the steps in the message, ``note`` says where the method stood.
        """
        self.steps += 1
        if self.max_steps is not None and self.steps > self.max_steps:
            where = f"; {note}" if note else ""
            self._exceeded(f"step budget ran out ({self.max_steps} {what}{where}", "max_steps")
        self.check_time()

    def event(self, what: str = "events") -> None:
        """Spend one event and check the time."""
        self.events += 1
        if self.max_events is not None and self.events > self.max_events:
            self._exceeded(f"event budget ran out ({self.max_events} {what}", "max_events")
        self.check_time()

    def check_time(self) -> None:
        """Raise once ``max_seconds`` have passed."""
        if self.spent_s > self.max_seconds:
            self.out_of_time()

    def out_of_time(self) -> None:
        """Raise the time budget's `BudgetExceeded` (a solver given `seconds_left` stopped)."""
        self._exceeded(f"time budget ran out ({self.max_seconds:g} s", "max_seconds")

    def _exceeded(self, what: str, option: str) -> None:
        amount = {
            "max_steps": self.max_steps,
            "max_events": self.max_events,
            "max_seconds": self.max_seconds,
        }[option]
        # The seconds spent go with the error, not into its message: messages are
        # deterministic, and a table groups its failed cells by message.
        raise BudgetExceeded(f"{self.law}: {what}, {option})", option, amount, self.spent_s)

    def __enter__(self) -> Budget:
        """Open the budget: `current` gives it inside the block (blocks nest)."""
        self._token = _OPEN.set(self)
        return self

    def __exit__(self, *exc: object) -> None:
        _OPEN.reset(self._token)


_OPEN: contextvars.ContextVar[Budget | None] = contextvars.ContextVar("budget", default=None)


def current_budget() -> Budget:
    """The budget of the solve under way; an unbounded one outside any solve."""
    return _OPEN.get() or Budget("lawbench")


# The warnings filter that shows every warning, each time (`warnings.simplefilter`'s entry).
_ALWAYS = ("always", None, Warning, None, 0)


class Watch:
    """What every solve shares: its budget, its wall time, and the warnings it raised.

    Opened around a law's own solve, it opens the `Budget` the checked ``options`` set
    and records every warning instead of printing it. ``record`` then holds ``options``,
    ``wall_time_s`` and, where the solve raised any, ``warnings``, for the answer's diagnostics.
    """

    def __init__(self, law: str, options: dict[str, Any]) -> None:
        self.budget = Budget.of(law, options)
        self.warnings = warnings.catch_warnings(record=True)
        self.record: dict[str, Any] = {"options": options}

    def __enter__(self) -> Watch:
        self.budget.__enter__()
        self.caught = self.warnings.__enter__()
        # Every warning recorded, none printed: the filter "always" ahead of the caller's, in
        # the copy of the filters the block has. Put there before any warning is issued under
        # that copy, it needs no reset of the registries of warnings already shown (which
        # `warnings.simplefilter` would do, at half the cost of a small solve).
        warnings.filters.insert(0, _ALWAYS)
        self.start = time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        self.record["wall_time_s"] = time.perf_counter() - self.start
        self.warnings.__exit__(*exc)
        self.budget.__exit__(*exc)
        if self.caught:
            heard = {f"{w.category.__name__}: {w.message}" for w in self.caught}
            self.record["warnings"] = sorted(heard)
