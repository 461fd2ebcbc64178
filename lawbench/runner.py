"""Execute a run: every row of a specification, one tidy record each, written as it finishes.

A row never raises: a failure is recorded with its error class and message and the run goes
on. Records are written in chunks (Parquet, or CSV on request) into ``OUT.parts/`` as they
finish, each chunk file written whole before it appears, so a run that is interrupted (Ctrl-C,
a killed process) keeps every finished chunk, and a resumed run computes only the rows that are
missing. When every row is done the chunks are gathered, sorted by row index, into ``OUT``.
The table is the same whichever executor ran it (serial, local processes, or a Dask cluster),
up to the ``wall_time_s`` column.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.api import evaluate
from lawbench.checks import run_checks
from lawbench.errors import InvalidProblem
from lawbench.grid import Row, RunSpec
from lawbench.verdicts import Verdict, of_error

EXECUTORS = ("serial", "processes", "dask")
STEP_KEYS = ("steps", "impacts", "iterations")


def compute(row: Row, checks: Sequence[str], settings: dict[str, Any]) -> dict[str, Any]:
    """The record of one row: outcome, checks, cost, or the error that stopped it."""
    record: dict[str, Any] = {
        "index": row.index,
        "key": row.key,
        "law": row.law,
        "case": row.case,
        "params": json.dumps(row.params, sort_keys=True),
        "options": json.dumps(row.options, sort_keys=True),
        "status": "error",
        "verdict": str(Verdict.HOLDS),
        "error_class": "",
        "error_message": "",
    }
    try:
        trial = evaluate(row.law, row.case, row.options, **row.params)
        trial.settings.update(settings)
        results = run_checks(trial, list(checks))
    except Exception as exc:  # a row records its failure and the run goes on
        record.update(
            verdict=str(of_error(exc)), error_class=type(exc).__name__, error_message=str(exc)
        )
        return record
    outcome = trial.outcome
    diagnostics = outcome.diagnostics
    record.update(
        status=outcome.status,
        v_plus=json.dumps(outcome.v_plus.tolist()),
        Pn=json.dumps(outcome.Pn.tolist()),
        Pt=json.dumps(outcome.Pt.tolist()),
        T_minus=outcome.T_minus,
        T_plus=outcome.T_plus,
        dT=outcome.dT,
        formulation=str(diagnostics.get("formulation", "")),
        steps=next((int(diagnostics[k]) for k in STEP_KEYS if k in diagnostics), 0),
        wall_time_s=diagnostics["wall_time_s"],
    )
    for name, result in results.items():
        record[f"{name}_value"] = np.nan if result.value is None else float(result.value)
        record[f"{name}_verdict"] = str(result.verdict)
        claims = trial.law.findings if result.verdict == Verdict.LAW_PROPERTY else ()
        record[f"{name}_finding"] = claims.index(result.claim) if result.claim in claims else -1
    return record


def compute_chunk(rows: Sequence[Row], checks: Sequence[str], settings: dict) -> list[dict]:
    """Records of a chunk of rows (the unit sent to a worker)."""
    return [compute(row, checks, settings) for row in rows]


class Store:
    """The chunk files of a run and the final table."""

    def __init__(self, out: Path, file_format: str) -> None:
        self.out = Path(out)
        self.parts = self.out.with_name(self.out.name + ".parts")
        self.format = file_format

    def done(self) -> pd.DataFrame:
        """Every record finished so far (final table and chunk files)."""
        frames = [self._read(self.out)] if self.out.exists() else []
        if self.parts.exists():
            frames += [self._read(path) for path in sorted(self.parts.glob("part-*"))]
        if not frames:
            return pd.DataFrame()
        return pd.concat(frames, ignore_index=True).drop_duplicates("key")

    def write_chunk(self, records: list[dict], number: int) -> None:
        """Write one chunk whole under a temporary name, then move it in place."""
        self.parts.mkdir(parents=True, exist_ok=True)
        path = self.parts / f"part-{number:06d}.{self.format}"
        temporary = path.with_suffix(".tmp")
        self._write(pd.DataFrame(records), temporary)
        os.replace(temporary, path)

    def finish(self, total: int) -> pd.DataFrame:
        """Gather the chunks by row index; when all ``total`` rows are done, write ``out``."""
        table = self.done().sort_values("index").reset_index(drop=True)
        if len(table) == total:
            self._write(table, self.out)
            for path in self.parts.glob("part-*"):
                path.unlink()
            self.parts.rmdir()
        return table

    def _read(self, path: Path) -> pd.DataFrame:
        return pd.read_parquet(path) if self.format == "parquet" else pd.read_csv(path)

    def _write(self, table: pd.DataFrame, path: Path) -> None:
        if self.format == "parquet":
            table.to_parquet(path, index=False)
        else:
            table.to_csv(path, index=False)


class Progress:
    """Rows done, failures and time left, on a terminal only."""

    def __init__(self, total: int, stream: Any = sys.stderr) -> None:
        self.total, self.stream = total, stream
        self.enabled = stream.isatty()
        self.start = time.monotonic()
        self.done = self.failed = 0

    def update(self, records: list[dict]) -> None:
        """Count a finished chunk and redraw the line."""
        self.done += len(records)
        self.failed += sum(r["error_class"] != "" for r in records)
        if not self.enabled:
            return
        elapsed = time.monotonic() - self.start
        left = elapsed / self.done * (self.total - self.done)
        self.stream.write(
            f"\r{self.done}/{self.total} rows, {self.failed} failed, "
            f"{elapsed:.0f} s elapsed, about {left:.0f} s left "
        )
        self.stream.flush()

    def close(self) -> None:
        """End the line."""
        if self.enabled:
            self.stream.write("\n")


def _chunks(rows: Sequence[Row], size: int) -> Iterator[list[Row]]:
    for start in range(0, len(rows), size):
        yield list(rows[start : start + size])


def run(
    spec: RunSpec,
    out: Path,
    executor: str = "serial",
    address: str | None = None,
    resume: bool = False,
    file_format: str = "parquet",
    chunk_size: int = 50,
    workers: int | None = None,
) -> tuple[pd.DataFrame, int]:
    """Run ``spec`` and write its table to ``out``; return the table and the rows computed.

    Raises
    ------
    InvalidProblem
        For a bad specification, an unknown executor, an output that exists without
        ``resume``, or an unreachable Dask address: all before any row is computed.
    """
    if executor not in EXECUTORS:
        raise InvalidProblem(f"executor {executor!r}: must be one of {', '.join(EXECUTORS)}")
    rows = spec.rows()
    store = Store(out, file_format)
    finished = store.done()
    if len(finished) and not resume:
        raise InvalidProblem(f"{out} already holds results: give --resume or another --out")
    done_keys = set(finished["key"]) if len(finished) else set()
    todo = [row for row in rows if row.key not in done_keys]
    settings = {"continuity_sizes": list(spec.continuity_sizes)}
    chunks = list(_chunks(todo, chunk_size))
    first = len(list(store.parts.glob("part-*"))) if store.parts.exists() else 0
    progress = Progress(len(rows))
    progress.done = len(rows) - len(todo)
    submit = _EXECUTE[executor]
    try:
        for number, records in enumerate(submit(chunks, spec.checks, settings, address, workers)):
            store.write_chunk(records, first + number)
            progress.update(records)
    finally:
        progress.close()
    return store.finish(len(rows)), len(todo)


Results = Iterable[list[dict]]


def _serial(
    chunks: list, checks: Sequence[str], settings: dict, address: Any, workers: Any
) -> Results:
    for chunk in chunks:
        yield compute_chunk(chunk, checks, settings)


def _processes(
    chunks: list, checks: Sequence[str], settings: dict, address: Any, workers: Any
) -> Results:
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
        futures = [pool.submit(compute_chunk, chunk, checks, settings) for chunk in chunks]
        try:
            for future in as_completed(futures):
                yield future.result()
        finally:
            for future in futures:
                future.cancel()


def _dask(
    chunks: list, checks: Sequence[str], settings: dict, address: Any, workers: Any
) -> Results:
    try:
        from dask.distributed import Client, LocalCluster
        from dask.distributed import as_completed as dask_completed
    except ImportError:  # an optional dependency: say how to get it
        raise InvalidProblem("the dask executor needs Dask: pip install 'lawbench[dask]'") from None

    cluster = None
    try:
        if address:
            client = Client(address, timeout="10s")
        else:
            cluster = LocalCluster(
                n_workers=workers or os.cpu_count(),
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
            )
            client = Client(cluster)
    except OSError as exc:
        raise InvalidProblem(f"dask scheduler {address!r} cannot be reached ({exc})") from None
    try:
        futures = [
            client.submit(compute_chunk, chunk, checks, settings, pure=False) for chunk in chunks
        ]
        for future in dask_completed(futures):
            yield future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


_EXECUTE: dict[str, Callable[..., Results]] = {
    "serial": _serial,
    "processes": _processes,
    "dask": _dask,
}
