"""The per-job wall-clock guard: no job runs past its seconds, whatever the law does.

Two forms, one rule: a job that has not answered after its budget is stopped and counts as a
`BudgetExceeded` of the budget ``wall-clock guard``, with the seconds.

- `Guard` keeps a few worker processes; a task (a module-level function and its arguments)
  runs in one of them and gives a `Result`: its value, the error it raised, or ``time-out``.
  The worker of a task that runs out of time is killed and replaced, so no task can hang its
  caller even inside compiled code; a worker that dies is replaced the same way, and a worker
  ends with the process that started it (no orphan keeps computing). Warnings a task raises
  are recorded with its result instead of being printed.
- `lawbench.core.guards.alarm` guards a job in this process (the serial executor, every
  `lawbench.core.trial.make_trial`): a timer signal raises the `BudgetExceeded` inside the
  job. It interrupts Python code, and native code when it returns, only in the main thread;
  ``lawbench solve`` and ``lawbench check`` end their own process when a native call overstays
  it (`lawbench.core.guards.end_process_when_stuck`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
import warnings
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import multiprocessing.process
    from multiprocessing.connection import Connection

TIME_OUT = "time-out"
WARNINGS_KEPT = 10
# Seconds a worker may take to receive a task (start up, import what the task's function and
# arguments need) before the task's own budget starts: a task is timed from when it begins, so
# that a loaded machine's slow imports stop no task, and a worker stuck importing still ends.
STARTUP_S = 120.0
# Seconds a worker whose end of the pipe closed is given to end, so that its exit code is read.
REAP_S = 1.0
# What a worker sends when it begins a task, before its result.
_BEGUN = "begun"
# Seconds a cell may run before the guard stops it, unless told otherwise.
BUDGET_S = 600.0
# Where guarded cells run (`lawbench.studies.runner.Executor`): this process, local workers, Dask.
EXECUTORS = ("serial", "processes", "dask")


@dataclass(frozen=True)
class Result:
    """What a task gave: ``status`` 'ok', 'error' or 'time-out'."""

    status: str
    value: Any = None
    error_class: str = ""
    error_message: str = ""
    warnings: tuple[str, ...] = ()
    seconds: float = 0.0


def _end_with_parent() -> None:
    """End this worker as soon as the process that started it ends, even when killed."""
    import multiprocessing
    from multiprocessing.connection import wait

    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch() -> None:
        wait([parent.sentinel])
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


@contextmanager
def _deaf_to_ctrl_c() -> Iterator[None]:
    """Ignore SIGINT meanwhile, in the main thread: a process started now inherits it.

    A Ctrl-C reaches every process of the terminal's group; the parent alone answers it (it
    stops the run, ends its workers and prints one line), so a worker must not take it, even
    while it still imports (each would print a traceback).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _serve(connection: Connection) -> None:
    """The loop of a worker: receive a task, run it, send its result back."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _end_with_parent()
    while True:
        try:
            message = connection.recv()
        except (EOFError, OSError):  # the parent is gone, or a law forked and its copy reads
            return
        if message is None:
            return
        number, function, args, before = message
        if before is not None:
            with contextlib.suppress(Exception):  # the task meets the failure and records it
                before()
        connection.send((_BEGUN, number))
        start = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                value, error_class, error_message = function(*args), "", ""
            except Exception as exc:  # a task's failure is its result
                value, error_class, error_message = None, type(exc).__name__, str(exc)
        seen = sorted({f"{w.category.__name__}: {w.message}" for w in caught})
        reply = (number, value, error_class, error_message, tuple(seen[:WARNINGS_KEPT]))
        reply += (time.perf_counter() - start,)
        try:
            connection.send(reply)
        except Exception as exc:  # an answer that cannot be sent back
            connection.send((number, None, type(exc).__name__, str(exc), (), reply[-1]))


@dataclass(eq=False)
class _Worker:
    process: multiprocessing.process.BaseProcess
    connection: Connection
    task: int | None = None
    deadline: float = 0.0
    budget: float = 0.0


@dataclass
class _Task:
    number: int
    function: Callable[..., Any]
    args: tuple[Any, ...]
    budget: float
    before: Callable[[], Any] | None = None


class Guard:
    """A pool of ``workers`` processes running tasks under wall-clock budgets.

    Parameters
    ----------
    workers : int
        Number of worker processes.
    budget_s : float
        Default budget of a task, in seconds of wall time.
    """

    def __init__(self, workers: int, budget_s: float) -> None:
        self.workers, self.budget_s = max(1, workers), budget_s
        # Spawned workers start clean: no thread or solver state copied from the parent.
        # multiprocessing loads here: a solve guarded in this process needs `alarm` alone.
        import multiprocessing

        self._context = multiprocessing.get_context("spawn")
        self._pool: list[_Worker] = []
        self._queue: deque[_Task] = deque()
        self._results: dict[int, Result] = {}
        self._count = 0

    def submit(
        self,
        function: Callable[..., Any],
        *args: Any,
        budget: float | None = None,
        before: Callable[[], Any] | None = None,
    ) -> int:
        """Queue ``function(*args)``; return the handle of its result.

        ``before()`` runs in the worker first, outside the task's budget, like the worker's
        imports: the one-time work of a process that the task needs (compiling a law's kernels).
        """
        self._count += 1
        self._queue.append(_Task(self._count, function, args, budget or self.budget_s, before))
        return self._count

    def result(self, handle: int) -> Result:
        """The result of a submitted task, waiting for it (other tasks run meanwhile)."""
        while handle not in self._results:
            self._step()
        return self._results.pop(handle)

    def as_completed(self, handles: Iterable[int]) -> Iterator[tuple[int, Result]]:
        """``(handle, result)`` of each of ``handles``, in the order they finish."""
        waiting = set(handles)
        while waiting:
            done = waiting & self._results.keys()
            if not done:
                self._step()
                continue
            for handle in sorted(done):
                waiting.discard(handle)
                yield handle, self._results.pop(handle)

    def start(self) -> None:
        """Start every worker now: their start-up (imports) overlaps what the caller does next."""
        while len(self._pool) < self.workers:
            self._pool.append(self._start())

    def close(self) -> None:
        """Stop every worker."""
        for worker in self._pool:
            self._stop(worker, kill=worker.task is not None)
        self._pool.clear()

    def __enter__(self) -> Guard:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _start(self) -> _Worker:
        parent, child = self._context.Pipe()
        process = self._context.Process(target=_serve, args=(child,), daemon=True)
        with _deaf_to_ctrl_c():
            process.start()
        child.close()
        return _Worker(process, parent)

    def _stop(self, worker: _Worker, kill: bool) -> None:
        if kill:
            worker.process.kill()
        else:
            try:
                worker.connection.send(None)
            except OSError:
                worker.process.kill()
        worker.process.join(timeout=5)
        if worker.process.is_alive():
            worker.process.kill()
            worker.process.join()
        worker.connection.close()

    def _step(self) -> None:
        """Hand out queued tasks, then wait for one answer or one deadline."""
        from multiprocessing.connection import wait

        self.start()
        for worker in self._pool:
            if worker.task is None and self._queue:
                task = self._queue.popleft()
                worker.task, worker.budget = task.number, task.budget
                worker.deadline = time.monotonic() + STARTUP_S + task.budget
                worker.connection.send((task.number, task.function, task.args, task.before))
        busy = [w for w in self._pool if w.task is not None]
        if not busy:
            raise RuntimeError("the guard waits for a result that was never submitted")
        timeout = max(0.0, min(w.deadline for w in busy) - time.monotonic())
        ready = wait([w.connection for w in busy], timeout=timeout)
        for worker in busy:
            if worker.connection in ready:
                self._receive(worker)
            elif time.monotonic() >= worker.deadline:
                self._replace(worker, Result(TIME_OUT, seconds=worker.budget))

    def _receive(self, worker: _Worker) -> None:
        try:
            reply = worker.connection.recv()
        except (EOFError, OSError):
            worker.process.join(REAP_S)
            code = worker.process.exitcode
            self._replace(worker, Result("error", None, "WorkerDied", f"exit code {code}"))
            return
        if reply[0] == _BEGUN:
            worker.deadline = time.monotonic() + worker.budget
            return
        number, value, error_class, message, caught, seconds = reply
        status = "error" if error_class else "ok"
        self._results[number] = Result(status, value, error_class, message, caught, seconds)
        worker.task = None

    def _replace(self, worker: _Worker, result: Result) -> None:
        """Record ``result`` for the worker's task, kill the worker and start another."""
        self._results[worker.task] = result
        self._stop(worker, kill=True)
        self._pool[self._pool.index(worker)] = self._start()
