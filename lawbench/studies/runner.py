"""The executor: every study cell and every ``lawbench run`` row, one record each, one guard.

`compute` solves one cell (`lawbench.studies.study.Job`), runs its checks and measures, and returns
its `lawbench.studies.record.Record` row; it never raises: a failure is recorded with its error
class and message and the run goes on (nevergrad's runner does the same). An `Executor` runs cells
in this process (``serial``), in local worker processes (``processes``) or on a Dask cluster
(``dask``), every cell under the same per-job wall-clock guard (`lawbench.studies.guard`): a cell
stopped there is a *budget* cell naming the ``wall-clock guard`` and its seconds. Before any cell
starts, each of their laws does here, once, its one-time work of a process (`Law.prepare`:
compiling its kernels into numba's cache), and a worker does it again (a load from that cache)
before a cell's budget starts: no cell's budget pays for it.

`run` holds a lock on its output and writes a plan's records in checksummed chunks into
``OUT.parts/`` as they finish (`lawbench.studies.runfile.Store`), so a run that is interrupted
(Ctrl-C, a killed process) keeps every finished cell, and a resumed run computes only the cells that
are missing, and those of a damaged chunk. When every cell is done the chunks are gathered, sorted
by cell index, into ``OUT``'s tidy table (Parquet, CSV or Feather, from the extension). The table is
the same whichever executor ran it, up to the timing columns (``wall_time_s``, ``spent_s``).
"""

from __future__ import annotations

import functools
import multiprocessing
import os
import sys
import time
import warnings
from collections.abc import Iterator, Mapping, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
from tqdm import tqdm

from lawbench.checks import run_checks
from lawbench.core.errors import InvalidProblem, LawbenchError
from lawbench.core.guards import alarm, stopped
from lawbench.core.law import LAWS
from lawbench.files.paths import output_file
from lawbench.studies.guard import (
    BUDGET_S,
    EXECUTORS,
    TIME_OUT,
    WARNINGS_KEPT,
    Guard,
    Result,
)
from lawbench.studies.record import Record
from lawbench.studies.runfile import Store, file_format, metadata
from lawbench.studies.study import Job, Measure, Plan


class WorkerDied(Exception):
    """A worker process ended while it computed a cell (a crash in compiled code)."""


@dataclass(frozen=True)
class Task:
    """A cell with what to compute on it: the unit sent to a worker."""

    index: int
    job: Job
    study: str = ""
    checks: tuple[str, ...] = ()
    settings: Mapping[str, Any] = field(default_factory=dict)
    measures: Mapping[str, Measure] = field(default_factory=dict)


def _task(plan: Plan, index: int, job: Job) -> Task:
    """The task of ``plan``'s cell ``index``."""
    return Task(index, job, plan.name, plan.checks, plan.settings, plan.measures_of(job))


def compute(task: Task, alarm_s: float | None = None) -> dict[str, Any]:
    """The record row of one cell: outcome, checks, measures, cost, or the error that stopped it.

    ``alarm_s`` guards the cell in this process (`lawbench.core.law.alarm`).
    """
    start = time.perf_counter()
    heard: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            with alarm(alarm_s):
                trial = task.job.solve(task.settings)
                heard = list(trial.outcome.diagnostics.get("warnings", ()))
                checks = run_checks(trial, checks=list(task.checks)) if task.checks else {}
                measures = {name: measure(trial) for name, measure in task.measures.items()}
            record = Record.solved(task.index, task.study, task.job, trial, checks, measures)
        except Exception as exc:  # a cell records its failure and the run goes on
            spent = time.perf_counter() - start
            record = Record.failed(task.index, task.study, task.job, exc, spent)
    # The solve's own warnings are kept in its diagnostics; the checks' are caught here.
    seen = sorted({*heard, *(f"{w.category.__name__}: {w.message}" for w in caught)})
    record.warnings = "; ".join(seen[:WARNINGS_KEPT])
    return record.row()


def _row(result: Result, task: Task, budget_s: float) -> dict[str, Any]:
    """The row of a cell computed in a guarded worker."""
    if result.status == "ok":
        return result.value
    if result.status == TIME_OUT:
        error: Exception = stopped(budget_s)
    else:
        error = WorkerDied(f"{result.error_class}: {result.error_message}")
    return Record.failed(task.index, task.study, task.job, error, result.seconds).row()


# Seconds past its budget before the guard kills a worker whose cell ignored the alarm (a loop in
# compiled code): the alarm stops a cell inside its worker, which keeps its imports and its
# answers solved again, and a killed worker's replacement pays for them anew.
KILL_GRACE_S = 2.0


def _guarded(guard: Guard, task: Task, budget_s: float) -> int:
    """Submit ``task`` to ``guard``: its alarm rings at ``budget_s``, the kill comes after.

    Its worker prepares the cell's law first, outside the budget (`prepare`).
    """
    before = functools.partial(prepare, task.job.law)
    return guard.submit(compute, task, budget_s, budget=budget_s + KILL_GRACE_S, before=before)


def prepare(law: str) -> None:
    """The one-time work of this process that the law named ``law`` needs (`Law.prepare`)."""
    try:
        found = LAWS.get(law)
    except LawbenchError:  # a law that cannot load: each of its cells records why
        return
    found.prepare()


# The guard of a Dask worker process, started with its first chunk.
_WORKER_GUARD: Guard | None = None


def _dask_chunk(chunk: list[tuple[int, Task]], budget_s: float) -> list[tuple[int, dict]]:
    """``(position, row)`` of a chunk of cells, each run in this Dask worker's guard process."""
    global _WORKER_GUARD
    if _WORKER_GUARD is None:
        _WORKER_GUARD = Guard(1, budget_s)
    handles = {_guarded(_WORKER_GUARD, task, budget_s): k for k, task in chunk}
    tasks = dict(chunk)
    return [
        (handles[h], _row(r, tasks[handles[h]], budget_s))
        for h, r in _WORKER_GUARD.as_completed(handles)
    ]


def _daemonic() -> bool:
    return bool(multiprocessing.current_process().daemon)


class Executor:
    """Runs cells under the per-job wall-clock guard, in one of `EXECUTORS`.

    Parameters
    ----------
    kind : str
        'serial' (this process), 'processes' (local workers) or 'dask' (a local cluster, or the
        scheduler at ``address``).
    workers : int, optional
        Worker processes (default: one per core).
    budget_s : float
        Seconds a cell may run before the guard stops it.
    address : str, optional
        A Dask scheduler's address.
    chunk_size : int
        Cells per Dask task.

    Raises
    ------
    InvalidProblem
        For an unknown kind, an unreachable Dask scheduler, or Dask workers that cannot start
        the guard's process (daemonic workers).
    """

    def __init__(
        self,
        kind: str = "serial",
        workers: int | None = None,
        budget_s: float = BUDGET_S,
        address: str | None = None,
        chunk_size: int = 50,
    ) -> None:
        if kind not in EXECUTORS:
            raise InvalidProblem(f"executor {kind!r}: must be one of {', '.join(EXECUTORS)}")
        self.kind, self.budget_s, self.address = kind, budget_s, address
        self.workers = workers or os.cpu_count() or 1
        self.chunk_size = chunk_size
        self._guard: Guard | None = None
        self._client: Any = None
        self._cluster: Any = None

    def __enter__(self) -> Executor:
        if self.kind == "processes":
            self._guard = Guard(self.workers, self.budget_s)
        elif self.kind == "dask":
            self._connect()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._guard is not None:
            self._guard.close()
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()

    def run(self, tasks: Sequence[Task]) -> Iterator[tuple[int, dict[str, Any]]]:
        """``(position in tasks, row)`` of every task, in the order they finish.

        The tasks' laws are prepared here first (`Law.prepare`), before any cell's budget.
        """
        for name in sorted({task.job.law for task in tasks}):
            prepare(name)
        if self.kind == "serial":
            for position, task in enumerate(tasks):
                yield position, compute(task, self.budget_s)
        elif self.kind == "processes":
            assert self._guard is not None, "use the executor in a with block"
            handles = {
                _guarded(self._guard, task, self.budget_s): k for k, task in enumerate(tasks)
            }
            for handle, result in self._guard.as_completed(handles):
                position = handles[handle]
                yield position, _row(result, tasks[position], self.budget_s)
        else:
            yield from self._dask(tasks)

    def _dask(self, tasks: Sequence[Task]) -> Iterator[tuple[int, dict[str, Any]]]:
        from dask.distributed import as_completed

        numbered = list(enumerate(tasks))
        futures = [
            self._client.submit(
                _dask_chunk, numbered[start : start + self.chunk_size], self.budget_s, pure=False
            )
            for start in range(0, len(numbered), self.chunk_size)
        ]
        for future in as_completed(futures):
            yield from future.result()

    def _connect(self) -> None:
        try:
            import dask
            from dask.distributed import Client, LocalCluster
        except ImportError:  # an optional dependency: say how to get it
            raise InvalidProblem(
                "the dask executor needs Dask: pip install 'lawbench[dask]'"
            ) from None

        try:
            if self.address:
                self._client = Client(self.address, timeout="10s")
            else:
                # The guard starts a process inside each worker: the workers must not be
                # daemonic processes, which may not have children.
                with dask.config.set({"distributed.worker.daemon": False}):
                    self._cluster = LocalCluster(
                        n_workers=self.workers,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=None,
                    )
                self._client = Client(self._cluster)
        except OSError as exc:
            raise InvalidProblem(
                f"dask scheduler {self.address!r} cannot be reached ({exc})"
            ) from None
        if any(self._client.run(_daemonic).values()):
            raise InvalidProblem(
                "the dask workers are daemonic processes and cannot start the per-job guard: "
                "start them with the setting distributed.worker.daemon = False"
            )


def _progress(total: int, done: int, quiet: bool) -> tqdm:
    """A progress bar on a terminal's stderr; silent in a pipe and under ``quiet``."""
    return tqdm(
        total=total,
        initial=done,
        unit="cell",
        disable=quiet or not sys.stderr.isatty(),
        dynamic_ncols=True,
    )


def run_many(
    plans: Sequence[tuple[Plan, Path]],
    executor: Executor,
    resume: bool = False,
    chunk_size: int = 50,
    wait: bool = False,
    quiet: bool = False,
    seed: int | None = None,
) -> list[tuple[pd.DataFrame, int]]:
    """Run every plan into its file at once, one pool for all, each file locked meanwhile.

    Parameters
    ----------
    plans : sequence of (Plan, Path)
        The plans and their output files (format from the extension, `lawbench.studies.runfile`).
    executor : Executor
        The pool, entered (``with executor``).
    resume : bool
        Keep the rows already in the outputs and compute only the missing ones.
    chunk_size : int
        Rows per chunk file.
    wait : bool
        Wait for an output locked by another run instead of stopping.
    quiet : bool
        No progress bar.
    seed : int, optional
        The seed of the plans' random samples, recorded in the files' metadata.

    Returns
    -------
    list of (pandas.DataFrame, int)
        Per plan, its records (`lawbench.studies.record.Record` columns, cell order) and the number
        of cells computed now.

    Raises
    ------
    InvalidProblem
        Before any cell is computed: for an output with an unknown extension, one locked by
        another run (without ``wait``), one that holds results without ``resume`` or the cells
        of another grid (its fingerprint, a digest of the cells' keys, is kept beside the
        chunks and in the finished table's metadata), or a grid without a cell.
    """
    empty = [str(out) for plan, out in plans if not plan.jobs]
    if empty:
        raise InvalidProblem(f"{', '.join(empty)}: the grid has no cell, so nothing is written")
    stores = [Store(output_file(out, "run output")) for _, out in plans]
    grids = [_fingerprint(plan) for plan, _ in plans]
    with ExitStack() as locks:
        for store, (grid, described) in zip(stores, grids, strict=True):
            locks.enter_context(store.locked(wait))
            store.claim(grid, described)
        tasks, owner = _pending(plans, stores, resume)
        total = sum(_cells(plan) for plan, _ in plans)
        with _progress(total, total - len(tasks), quiet) as progress:
            _write(executor.run(tasks), owner, stores, chunk_size, progress)
        computed = [owner.count(number) for number in range(len(plans))]
        meta = metadata(seed)
        return [
            (
                store.finish(_cells(plan), {**meta, "grid": grid, "grid_described": described}),
                count,
            )
            for store, (plan, _), count, (grid, described) in zip(
                stores, plans, computed, grids, strict=True
            )
        ]


def _pending(
    plans: Sequence[tuple[Plan, Path]], stores: Sequence[Store], resume: bool
) -> tuple[list[Task], list[int]]:
    """The cells of ``plans`` not yet in their stores, and the number of the plan of each.

    Raises
    ------
    InvalidProblem
        For a store that holds results without ``resume``.
    """
    tasks, owner = [], []
    for number, ((plan, out), store) in enumerate(zip(plans, stores, strict=True)):
        finished = store.done()
        if len(finished) and not resume:
            raise InvalidProblem(f"{out} already holds results: give --resume or another --out")
        done = set(finished["key"]) if len(finished) else set()
        for index, job in enumerate(plan.jobs):
            if job.key not in done:
                done.add(job.key)  # a cell the grid names twice is computed once
                tasks.append(_task(plan, index, job))
                owner.append(number)
    return tasks, owner


def _cells(plan: Plan) -> int:
    """The number of distinct cells of ``plan``: a grid may name one twice (e = [0, 0])."""
    return len({job.key for job in plan.jobs})


def _write(
    rows: Iterator[tuple[int, dict[str, Any]]],
    owner: Sequence[int],
    stores: Sequence[Store],
    chunk_size: int,
    progress: tqdm,
) -> None:
    """Each row as it comes into the store of its plan, ``chunk_size`` rows a chunk file.

    The rows buffered when the run stops, finished or interrupted, are written too: a finished
    row is never lost.
    """
    buffers: list[list[dict]] = [[] for _ in stores]
    failed = 0
    try:
        for position, row in rows:
            buffer = buffers[owner[position]]
            buffer.append(row)
            failed += row["error_class"] != ""
            progress.set_postfix(failed=failed, refresh=False)
            progress.update()
            if len(buffer) >= chunk_size:
                stores[owner[position]].write_chunk(buffer)
                buffer.clear()
    finally:
        for store, buffer in zip(stores, buffers, strict=True):
            if buffer:
                store.write_chunk(buffer)


def _fingerprint(plan: Plan) -> tuple[str, str]:
    """A grid's identity (a digest of its cells' keys) and its description in messages."""
    import hashlib  # on first use: it loads OpenSSL

    digest = hashlib.sha256("\n".join([plan.name, *sorted(job.key for job in plan.jobs)]).encode())
    grid, cells = digest.hexdigest(), len(plan.jobs)
    named = f"{plan.name}: " if plan.name else ""
    return grid, f"{named}{cells} cell{'s' if cells != 1 else ''}, fingerprint {grid[:12]}"


def estimate_seconds(sample: Plan, cells: int, workers: int) -> float:
    """Wall time ``cells`` cells would take on ``workers`` processes, from ``sample`` timed here.

    ``sample`` holds a few cells spread over the grid (`lawbench.studies.grid.RunSpec.plan`); a grid
    whose cells differ much in cost (a sweep of an accuracy knob) makes this a rough figure.
    """
    if not sample.jobs:
        return 0.0
    start = time.perf_counter()
    for index, job in enumerate(sample.jobs):
        compute(_task(sample, index, job))
    per_cell = (time.perf_counter() - start) / len(sample.jobs)
    return per_cell * cells / max(1, workers)


def collect(plan: Plan, executor: Executor) -> pd.DataFrame:
    """Every record of ``plan``, in cell order, computed by ``executor`` (no file written)."""
    tasks = [_task(plan, index, job) for index, job in enumerate(plan.jobs)]
    rows = [row for _, row in executor.run(tasks)]
    return pd.DataFrame(sorted(rows, key=lambda row: row["index"]))


def run(
    plan: Plan,
    out: Path,
    executor: str = "serial",
    address: str | None = None,
    resume: bool = False,
    chunk_size: int = 50,
    workers: int | None = None,
    budget_s: float = BUDGET_S,
    wait: bool = False,
    quiet: bool = False,
    seed: int | None = None,
) -> tuple[pd.DataFrame, int]:
    """Run ``plan`` and write its table to ``out``; return its records and the cells computed.

    The options are those of `Executor` and `run_many`.

    Raises
    ------
    InvalidProblem
        For an unknown executor or extension, an output locked by another run (without
        ``wait``), an output that exists without ``resume``, or an unreachable Dask address:
        all before any cell is computed.
    """
    file_format(Path(out))
    pool = Executor(executor, workers, budget_s, address, chunk_size)
    with pool:
        return run_many([(plan, Path(out))], pool, resume, chunk_size, wait, quiet, seed)[0]
