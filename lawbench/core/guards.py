"""What lawbench holds a law's code to, from outside it: time, Ctrl-C, and its answer.

A law is code from anywhere (a plugin, a user's module), so nothing here trusts it.

`alarm` raises `stopped` inside the enclosed code once its seconds have passed, whatever that
code does, as long as it runs Python or returns to it: a timer signal (SIGALRM) interrupts a
sleep, a Python loop, and a native call at its return. Alarms nest: an inner one never delays
an outer one, and the outer one rings with its own message. A native call that does not return
(a long LAPACK factorization, code that blocks the signal) is stopped by a process boundary
instead: the study runner's worker processes (`lawbench.studies.guard`), or, in a command that
calls `end_process_when_stuck` (``lawbench solve``, ``lawbench check``), a watchdog thread that
ends the process with one line and exit code 4 `LAST_RESORT_S` seconds after an alarm's
deadline. The watchdog runs while the native call releases the interpreter's lock, as numpy's
linear algebra and every blocking system call do; a native loop that holds the lock can only
be stopped from another process. Code that an exception would leave half done for the rest of
the process (a compiler's import and first compilation) runs `held`: an alarm that rings
meanwhile rings again as it ends.

`user_interrupts` counts the SIGINTs the user sends while lawbench watches them, so that a
`KeyboardInterrupt` raised by a law's own code (a failure of that law) is told apart from the
user's Ctrl-C (which still ends the command): `from_user` states the rule.

`inputs` digests what a law receives, so that a law that writes into its problem or its options
is caught; `verify_answer` refuses an answer of the wrong type or shape, a non-finite number,
and reported energies or impulses that are not those of the answer's own velocities. Each
raises `SolverFailure` naming the law.

A `Budget` is what one solve may spend from inside: steps, events and wall-clock seconds, one
mechanism for every law. `lawbench.core.law.Law.resolve` opens one, in a `Watch` that also times
the solve and records its warnings, from the law's options; the law's loops spend from
`current_budget()`.
"""

from __future__ import annotations

import contextvars
import math
import os
import re
import signal
import threading
import time
import warnings
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

import numpy as np

from lawbench.core.errors import BudgetExceeded, InvalidProblem, SolverFailure
from lawbench.core.metric import all_finite
from lawbench.core.outcome import Outcome, generalized_impulse
from lawbench.core.problem import ImpactProblem

# What an outcome's energies may be: real numbers (a bool is none).
REAL = (int, float, np.integer, np.floating)
# The budget that a stop from outside the solve names.
WALL_CLOCK = "wall-clock guard"


def stopped(seconds: float) -> BudgetExceeded:
    """The error of a job stopped by the guard after ``seconds``."""
    return BudgetExceeded(
        f"no answer within {seconds:g} s: stopped by the {WALL_CLOCK}", WALL_CLOCK, seconds, seconds
    )


def in_main_thread() -> bool:
    """Whether this is the main thread, the only one that receives signals."""
    return threading.current_thread() is threading.main_thread()


# The longest alarm: the system's timer takes no more, and a budget of a year is no bound.
ALARM_LIMIT_S = 3.0e7


@contextmanager
def alarm(seconds: float | None) -> Iterator[None]:
    """Raise `stopped` inside the enclosed code once ``seconds`` have passed.

    No guard when ``seconds`` is None, beyond `ALARM_LIMIT_S`, or outside the main thread
    (signals reach only it).
    Inside another alarm the timer rings at the earlier of the two deadlines, and the outer
    alarm's deadline is restored on the way out.
    """
    if not seconds or seconds > ALARM_LIMIT_S or not in_main_thread():
        yield
        return
    watched = _Watchdog.watch(seconds)
    outer = signal.getsignal(signal.SIGALRM)
    outer_left = signal.getitimer(signal.ITIMER_REAL)[0]
    start = time.monotonic()
    outer_first = 0 < outer_left <= seconds

    def ring(signum: int, frame: Any) -> None:
        if _Held.depth:
            _Held.rang = True
            return
        if outer_first and callable(outer):
            outer(signum, frame)
        raise stopped(seconds)

    signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, outer_left if outer_first else seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, outer)
        _Watchdog.deadline = watched
        if outer_left > 0:
            # An outer deadline already past rings at once, in the outer alarm's own words.
            left = outer_left - (time.monotonic() - start)
            signal.setitimer(signal.ITIMER_REAL, max(left, 1e-6))


class _Held:
    """How many `held` blocks are open, and whether an alarm rang inside them."""

    depth = 0
    rang = False


@contextmanager
def held() -> Iterator[None]:
    """Run the enclosed code whole: an `alarm` that rings inside it rings again as it ends.

    For code that a stop half-way would leave broken for the rest of the process: numba's
    import, or its first compilation of a kernel, stopped by an exception, fails on every later
    call (a type registered twice, a library with no compiled object). Blocks nest; the alarm
    rings once the outermost ends. The signal cannot be blocked instead: the timer's signal goes
    to the process, and a thread of a numerical library that does not block it receives it.
    Outside the main thread, where no alarm rings, nothing is held.
    """
    if not in_main_thread():
        yield
        return
    _Held.depth += 1
    try:
        yield
    finally:
        _Held.depth -= 1
        if not _Held.depth and _Held.rang:
            _Held.rang = False
            signal.setitimer(signal.ITIMER_REAL, 1e-6)


# Seconds past an alarm's deadline before the watchdog of `end_process_when_stuck` ends the
# process: the alarm's own error, raised once the native call returns, is the clearer answer.
LAST_RESORT_S = 2.0
# Exit code of a process the watchdog ends: a solver failure's, as the command line gives it.
STUCK_EXIT = 4


class _Watchdog:
    """The deadline of the innermost alarm (None: no alarm open) and the thread that keeps it."""

    deadline: float | None = None
    thread: threading.Thread | None = None

    @classmethod
    def watch(cls, seconds: float) -> float | None:
        """Set the deadline of an alarm of ``seconds`` from now; return the one it replaces."""
        previous = cls.deadline
        if cls.thread is not None:
            deadline = time.monotonic() + seconds + LAST_RESORT_S
            cls.deadline = deadline if previous is None else min(previous, deadline)
        return previous

    @classmethod
    def keep(cls) -> None:
        while True:
            time.sleep(0.1)
            deadline = cls.deadline
            if deadline is not None and time.monotonic() > deadline:
                os.write(
                    2,
                    f"lawbench: the solve did not return to Python {LAST_RESORT_S:g} s after its "
                    f"wall-clock budget (stopped by the {WALL_CLOCK}; the process ends)\n".encode(),
                )
                os._exit(STUCK_EXIT)


def end_process_when_stuck() -> None:
    """From now on, end this process when a solve overstays an `alarm` inside native code.

    For a command line that runs the solves of one user's request: ending it is then what a
    subprocess guard would do, without the cost of starting one per solve.
    """
    if _Watchdog.thread is None:
        _Watchdog.thread = threading.Thread(target=_Watchdog.keep, daemon=True)
        _Watchdog.thread.start()


class _Interrupts:
    """The SIGINTs received while lawbench's handler is installed (see `user_interrupts`)."""

    count = 0

    @staticmethod
    def handler(signum: int, frame: Any) -> None:
        _Interrupts.count += 1
        signal.default_int_handler(signum, frame)


def watch_interrupts() -> None:
    """Count the user's Ctrl-C from now on, where Python's own handler would take it.

    The handler still raises `KeyboardInterrupt`; a handler of the caller's (or SIGINT
    ignored, as in a guarded worker) is left as it is.
    """
    if in_main_thread() and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _Interrupts.handler)


def user_interrupts() -> int:
    """SIGINTs counted so far (while watched): read before the code that may be interrupted."""
    return _Interrupts.count


def from_user(before: int) -> bool:
    """Whether a `KeyboardInterrupt` caught now is the user's Ctrl-C.

    ``before`` is `user_interrupts` when the code that raised it began. The rule: outside the
    main thread, or where SIGINT is ignored (a guarded worker), no signal raises it, so the code
    raised it itself; otherwise it is the user's when a SIGINT arrived meanwhile, or when
    SIGINTs are not watched (then lawbench cannot tell, and lets it end the command).
    """
    handler = signal.getsignal(signal.SIGINT)
    if not in_main_thread() or handler == signal.SIG_IGN:
        return False
    return handler is not _Interrupts.handler or _Interrupts.count != before


# Relative disagreement, beyond rounding, between the numbers a law reports and its velocities:
# an energy against ``v @ M @ v / 2``, and ``Wn Pn + Wt Pt`` against ``M (v+ - v-)``, each
# relative to the energies or momenta it is computed from. The built-in laws agree to 1e-15 on
# every scene; the margin is for ``M^-1`` applied to an ill-conditioned mass matrix.
CONSISTENCY = 1e-7


def _checksum(arrays: tuple[Any, ...]) -> int:
    """One hash of the numbers of numpy arrays and scipy.sparse matrices (None skipped).

    Each array's bytes in C order (`numpy.ndarray.tobytes`, whatever its layout), hashed as one
    tuple.
    """
    parts = []
    for array in arrays:
        if isinstance(array, np.ndarray):
            parts.append(array.tobytes())
        elif array is not None:
            parts += [array.data.tobytes(), array.indices.tobytes(), array.indptr.tobytes()]
    return hash(tuple(parts))


def inputs(
    problem: ImpactProblem, options: dict[str, Any], checksum: bool = True
) -> tuple[tuple, dict[str, Any]]:
    """A digest of what a law receives, to compare before and after its solve.

    The problem's part and the options' part (a copy of the options), so that a change names
    which it is. The problem's arrays are read-only (`ImpactProblem`) and its fields frozen, so
    no law writes into them by accident; only a law that makes an array writeable again can.
    ``checksum`` (for a law from outside lawbench's own packages) adds the hash of every number
    and contact, which catches that law. Without it (lawbench's own laws, whose tests hold them
    to their inputs) the problem's part is which arrays and contacts the problem holds.
    """
    held = (problem.M, problem.Wn, problem.Wt, problem.v, problem.gaps, problem.contacts)
    if not checksum:
        return tuple(map(id, held)), dict(options)
    try:
        contacts: object = hash(problem.contacts)
    except TypeError:  # a contact given an unhashable field
        contacts = repr(problem.contacts)
    return (*map(id, held), _checksum(held[:-1]), contacts), dict(options)


def verify_answer(law: str, problem: ImpactProblem, outcome: Any, own: bool = False) -> None:
    """Raise `SolverFailure` unless ``outcome`` answers ``problem`` in shape and numbers.

    Its fields have the problem's lengths, and its reported energies and impulses are those
    of its own velocities. For a law of lawbench's own packages (``own``), whose tests hold
    its outcomes unmodified, an outcome that `Outcome.from_impulses` built from ``problem``
    agrees with its impulses by construction (`Outcome.impulses_of`): of its numbers, only
    the energy after the impact is read: it is finite only where the velocity is, and a
    non-finite impulse makes the velocity so (no contact's column is zero).
    """
    if not isinstance(outcome, Outcome):
        raise SolverFailure(f"{law}: the law returned a {type(outcome).__name__}, not an Outcome")
    v_plus, Pn, Pt = outcome.v_plus, outcome.Pn, outcome.Pt
    n, m, md = problem.n, problem.m, problem.m * problem.d
    # An array's own shape first; np.shape reads any other value for the message.
    if (
        getattr(v_plus, "shape", None) != (n,)
        or getattr(Pn, "shape", None) != (m,)
        or getattr(Pt, "shape", None) not in ((md,), (0,))
    ):
        for field, length in (("v_plus", n), ("Pn", m), ("Pt", md)):
            shape = np.shape(getattr(outcome, field))
            if shape != (length,) and not (field == "Pt" and shape == (0,)):
                raise SolverFailure(f"{law}: {field} has shape {shape}, expected ({length},)")
    if own and outcome.impulses_of(problem) and math.isfinite(outcome.T_plus):
        return
    _refuse_malformed(law, problem, outcome)
    before, after = problem.momentum, problem.M.dot(v_plus)
    impulse = generalized_impulse(problem, Pn, Pt)
    residual = impulse - after + before
    # Python floats from here: numpy's scalars cost more than its small products.
    T_plus, T_minus = float(v_plus.dot(after)) / 2, problem.T_minus
    told_minus, told_plus = outcome.T_minus, outcome.T_plus
    # Squared 2-norms: dot products, the cheapest reductions of a small solve.
    scale = float(after.dot(after)) + float(before.dot(before)) + float(impulse.dot(impulse))
    if not math.isfinite(scale + told_minus + told_plus):
        refuse_non_finite(law, v_plus=v_plus, Pn=Pn, Pt=Pt, T_plus=float(told_plus))
        return  # finite numbers so large that their squares overflow: beyond these checks
    energy = CONSISTENCY * max(T_plus, T_minus)
    for field, told, kept in (("T_minus", told_minus, T_minus), ("T_plus", told_plus, T_plus)):
        if abs(told - kept) > energy:
            raise SolverFailure(
                f"{law}: reports {field} = {told:.6g} J where its velocities hold {kept:.6g} J"
            )
    if float(residual.dot(residual)) > CONSISTENCY * CONSISTENCY * scale:
        raise SolverFailure(
            f"{law}: its impulses Wn Pn + Wt Pt do not give its velocity change M (v+ - v-)"
        )


def _refuse_malformed(law: str, problem: ImpactProblem, outcome: Outcome) -> None:
    """Raise `SolverFailure` for a field of the wrong kind.

    The velocity and impulses are arrays of floats, the energies real numbers, the status one
    word, the diagnostics a dict, and ``v_minus`` (where given) the problem's velocity: what the
    checks, the tables and the JSON output read.
    """
    for field in ("v_plus", "Pn", "Pt"):
        value = getattr(outcome, field)
        if not isinstance(value, np.ndarray):
            raise SolverFailure(f"{law}: {field} is a {type(value).__name__}, not an array")
        if value.dtype.kind != "f":
            raise SolverFailure(f"{law}: {field} holds {value.dtype}, not floats")
    for field in ("T_minus", "T_plus"):
        value = getattr(outcome, field)
        if isinstance(value, bool) or not isinstance(value, REAL):
            raise SolverFailure(f"{law}: {field} is a {type(value).__name__}, not a real number")
    if not isinstance(outcome.status, str) or not re.fullmatch(r"\w+", outcome.status):
        raise SolverFailure(f"{law}: status {outcome.status!r} is not one word")
    if not isinstance(outcome.diagnostics, dict):
        kind = type(outcome.diagnostics).__name__
        raise SolverFailure(f"{law}: diagnostics is a {kind}, not a dict")
    v_minus = outcome.v_minus
    if v_minus is not None and v_minus is not problem.v:
        if np.shape(v_minus) != problem.v.shape or not np.array_equal(v_minus, problem.v):
            raise SolverFailure(f"{law}: v_minus is not the problem's velocity v")


def refuse_beyond_units(name: str, units: tuple[float, float, float], **fields: Any) -> None:
    """Raise `InvalidProblem` naming the first of ``fields`` that is not finite once scaled back.

    A scale-free law answers in ``units`` (mass, velocity, time) near the impact's scales; an
    answer that overflows in the problem's own units (impulses of 1e400 kg m/s) is a problem
    beyond double precision there, not a failure of the law.
    """
    for field, value in fields.items():
        if not _finite(value):
            raise InvalidProblem(
                f"{name}: the answer's {field}, found in units of {units[0]:g} kg and "
                f"{units[1]:g} m/s, leaves double precision in the problem's own units: give "
                "the problem in units nearer its masses and speeds"
            )


def refuse_non_finite(name: str, **fields: Any) -> None:
    """Raise `SolverFailure` naming the first of ``fields`` that holds a non-finite number."""
    for field, value in fields.items():
        if not _finite(value):
            raise SolverFailure(f"{name}: non-finite {field} {value}")


def _finite(value: Any) -> bool:
    """Whether a float or an array holds only finite numbers."""
    return math.isfinite(value) if isinstance(value, float) else not value.size or all_finite(value)


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
