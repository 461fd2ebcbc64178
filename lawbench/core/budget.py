"""What one solve may spend: steps, events and wall-clock seconds, one mechanism for every law.

`lawbench.core.law.Law.resolve` opens a `Budget` (a context manager) from the law's options for the
time of the solve: ``max_seconds`` (every law has it), ``max_steps`` (a law that steps: integrator
steps, fixed-point iterations, binary impacts) and ``max_events`` (a law that restarts at events),
each when the law declares it. The law's loops spend from `current()` (the event integrator of
`lawbench.numerics.integrator` does it for the integrating laws; an iterative solver calls `step`
once per iteration), and a budget that runs out raises `BudgetExceeded` naming the option, its
amount and the seconds spent, which is what a budget cell of a table shows.
"""

from __future__ import annotations

import contextvars
import math
import signal
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from lawbench.core.errors import BudgetExceeded
from lawbench.core.spec import Spec

OPTION = Spec(
    "max_seconds", 60.0, "wall-clock budget of one solve", unit="s", low=0.0, low_open=True
)


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


def current() -> Budget:
    """The budget of the solve under way; an unbounded one outside any solve."""
    return _OPEN.get() or Budget("lawbench")


# The budget that a stop from outside the solve names.
WALL_CLOCK = "wall-clock guard"


def stopped(seconds: float) -> BudgetExceeded:
    """The error of a job stopped by the guard after ``seconds``."""
    return BudgetExceeded(
        f"no answer within {seconds:g} s: stopped by the {WALL_CLOCK}", WALL_CLOCK, seconds, seconds
    )


@contextmanager
def alarm(seconds: float | None) -> Iterator[None]:
    """Raise `stopped` inside the enclosed code once ``seconds`` have passed.

    No guard when ``seconds`` is None or outside the main thread (signals reach only it).
    """
    if not seconds or threading.current_thread() is not threading.main_thread():
        yield
        return

    def ring(signum: int, frame: Any) -> None:
        raise stopped(seconds)

    previous = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
