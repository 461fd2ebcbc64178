"""Where the report's work runs, and what it reads back.

A section asks for a batch of jobs (a law with options on a case with parameters) and gets
one record per job, the record of `lawbench.runner.compute`: outcome as JSON, cost, the
verdict of each check, or the error class and message. In the quick mode the jobs run in the
guarded workers (`lawbench.report.guard`), each under the wall-clock budget; a job that runs
out of time gets the error class ``TimeOut``. In the full mode they run through
`lawbench.runner.run` into ``OUT/runs/NAME.parquet`` (one file per repeat), so an interrupted
report resumes where it stopped and the grids can run on a Dask cluster. Other work (custom
problems, continuity jumps, impact paths) runs in the guarded workers in both modes.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.case import CASES, Case
from lawbench.grid import RunSpec
from lawbench.guard import TIME_OUT, Guard, Result
from lawbench.law import LAWS, Law
from lawbench.registry import Registry
from lawbench.report.config import Config
from lawbench.runner import Task, compute, run
from lawbench.study import Job as Cell

TIME_OUT_CLASS = "TimeOut"


@dataclass(frozen=True)
class Job:
    """A law with options on a case with parameters."""

    law: str
    case: str
    params: dict[str, Any] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)

    def row(self, index: int = 0) -> Cell:
        """The runner's cell of this job."""
        return Cell(self.law, self.case, dict(self.params), dict(self.options))


def failed_record(job: Job, error_class: str, message: str) -> dict[str, Any]:
    """The record of a job that gave no answer."""
    return {
        "law": job.law,
        "case": job.case,
        "params": json.dumps(job.params, sort_keys=True),
        "options": json.dumps(job.options, sort_keys=True),
        "status": "error",
        "error_class": error_class,
        "error_message": message,
    }


def from_result(result: Result, job: Job, budget: float) -> dict[str, Any]:
    """The record of a job run in a guarded worker."""
    if result.status == TIME_OUT:
        return failed_record(job, TIME_OUT_CLASS, f"no answer within {budget:g} s (stopped)")
    if result.status != "ok":
        return failed_record(job, result.error_class, result.error_message)
    return {**result.value, "warnings": "; ".join(result.warnings)}


def array(record: dict[str, Any], key: str) -> np.ndarray | None:
    """A vector of a record (stored as JSON text), or None when the job failed."""
    value = record.get(key)
    if record.get("error_class") or value is None or (isinstance(value, float) and value != value):
        return None
    return np.asarray(json.loads(value) if isinstance(value, str) else value, dtype=float)


def error_text(record: dict[str, Any]) -> str:
    """``Class: message`` of a failed record, '' for an answer."""
    if not record.get("error_class"):
        return ""
    return f"{record['error_class']}: {record.get('error_message', '')}"


class Batch:
    """Records of a batch of jobs, gathered when first asked for."""

    def __init__(self, gather: Callable[[], list]) -> None:
        self._gather = gather
        self._records: list[dict[str, Any]] | None = None

    def records(self) -> list[dict[str, Any]]:
        """One record per job and repeat, jobs in order, repeats inside (``repeat`` key)."""
        if self._records is None:
            self._records = self._gather()
        return self._records


def registered(registry: Registry, wanted: Sequence[str] | None) -> tuple[list[Any], list[str]]:
    """The entries of ``registry`` (those in ``wanted`` when given) and notes on the others."""
    notes = []
    try:
        names = registry.names()
    except Exception as exc:  # a module failing to import keeps the ones loaded before it
        notes.append(f"loading the {registry.kind}s stopped: {type(exc).__name__}: {exc}")
        names = registry.names()
    notes += [f"{registry.kind} module `{m}` skipped: {r}" for m, r in registry.unavailable.items()]
    if wanted is not None:
        notes += [f"{registry.kind} `{w}` is not registered" for w in wanted if w not in names]
        names = [name for name in names if name in wanted]
    return [registry.get(name) for name in names], notes


class Context:
    """What the sections share: the configuration, the output folder and the workers."""

    def __init__(self, config: Config, out: Path, guard: Guard) -> None:
        self.config, self.out, self.guard = config, out, guard
        self.laws, law_notes = registered(LAWS, config.laws)
        self.cases, case_notes = registered(CASES, config.cases)
        self.notes = law_notes + case_notes
        self._batches: dict[str, Batch] = {}

    @property
    def rerun(self) -> str:
        """The command that writes this report again."""
        return self.config.rerun(str(self.out))

    def case(self, name: str) -> Case | None:
        """The scene called ``name`` when it is registered (and selected), else None."""
        return next((case for case in self.cases if case.name == name), None)

    def law(self, name: str) -> Law | None:
        """The law called ``name`` when it is registered (and selected), else None."""
        return next((law for law in self.laws if law.name == name), None)

    def batch(
        self,
        name: str,
        jobs: Sequence[Job],
        checks: Sequence[str] = ("energy_gain",),
        settings: dict[str, Any] | None = None,
        repeats: int = 1,
    ) -> Batch:
        """Start the jobs (once per ``name``: a second call returns the first batch)."""
        if name in self._batches:
            return self._batches[name]
        settings = dict(settings or {})
        if self.config.executor == "guard":
            gather = self._guarded(jobs, list(checks), settings, repeats)
        else:
            gather = self._run(name, jobs, list(checks), settings, repeats)
        self._batches[name] = Batch(gather)
        return self._batches[name]

    def _guarded(self, jobs: Sequence[Job], checks: list, settings: dict, repeats: int) -> Callable:
        budget = self.config.budget_s
        handles = [
            [
                self.guard.submit(compute, Task(0, job.row(), "", tuple(checks), settings))
                for _ in range(repeats)
            ]
            for job in jobs
        ]

        def gather() -> list[dict[str, Any]]:
            return [
                {**from_result(self.guard.result(handle), job, budget), "repeat": repeat}
                for job, row in zip(jobs, handles, strict=True)
                for repeat, handle in enumerate(row)
            ]

        return gather

    def _run(
        self, name: str, jobs: Sequence[Job], checks: list, settings: dict, repeats: int
    ) -> Callable:
        unique = list({job.row().key: job for job in jobs}.values())
        grids = [
            {
                "laws": [job.law],
                "cases": [job.case],
                "params": {k: [v] for k, v in job.params.items()},
                "options": {job.law: {k: [v] for k, v in job.options.items()}},
            }
            for job in unique
        ]
        extra = {}
        if "continuity_sizes" in settings:
            extra["continuity_sizes"] = tuple(settings["continuity_sizes"])
        tables = []
        for repeat in range(repeats):
            if not grids:
                tables.append({})
                continue
            spec = RunSpec(grids, checks=checks, **extra)
            table, _ = run(
                spec.plan(),
                self.out / "runs" / f"{name}-r{repeat}.parquet",
                executor=self.config.executor,
                address=self.config.address,
                resume=True,
                workers=self.config.workers,
            )
            tables.append(_by_key(table))

        def gather() -> list[dict[str, Any]]:
            return [
                {**tables[repeat][job.row().key], "repeat": repeat, "warnings": ""}
                for job in jobs
                for repeat in range(repeats)
            ]

        return gather


def _by_key(table: pd.DataFrame) -> dict[str, dict[str, Any]]:
    records = table.to_dict("records")
    for record in records:
        if not isinstance(record.get("error_class"), str):
            record["error_class"] = ""
    return {record["key"]: record for record in records}
