"""Where the report's studies run, and how its sections read their tables.

Every study a section draws runs once, all of them through one executor
(`lawbench.studies.runner.run_many`) into ``OUT/runs/NAME.parquet``: the quick mode recomputes them,
the full mode resumes an interrupted report. A section is a view of study tables: it asks
`Context.tables` for its view and reads each row's columns (`lawbench.studies.record.Record`).
"""

from __future__ import annotations

import dataclasses
import json
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import CASES, Case
from lawbench.core.law import LAWS, Law
from lawbench.core.registry import Registry
from lawbench.core.transforms import parse
from lawbench.studies.declared import STUDIES
from lawbench.studies.runner import Executor, run_many
from lawbench.studies.study import Study
from lawbench.views.report.config import Config, view


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


def vector(value: Any) -> np.ndarray | None:
    """A vector column's value (JSON text) as an array; None for a cell without it."""
    if not isinstance(value, str) or not value:
        return None
    return np.asarray(json.loads(value), dtype=float)


def parsed(value: Any) -> Any:
    """A measure's value: JSON text parsed, a number as it is, None for a missing one."""
    if isinstance(value, str):
        return json.loads(value)
    return None if value is None or value != value else value


def axis_value(row: dict[str, Any], axis: str) -> Any:
    """What a cell shows along ``axis``: a parameter, the transform's value, or a measure.

    A vector parameter is shown by its first entry (the striker's mass of a chain whose other
    masses are 1 kg).
    """
    if axis == "transform":
        return parse(row["transform"])[1]
    params = json.loads(row["params"])
    if axis in params:
        value = params[axis]
        return value[0] if isinstance(value, list) else value
    return parsed(row.get(axis))


def label(params: dict[str, Any], skip: Sequence[str]) -> str:
    """``name=value`` of the parameters a row fixes, those in ``skip`` left out."""
    shown = []
    for name, value in params.items():
        if name in skip:
            continue
        if isinstance(value, list):
            value = value[0] if len(value) == 1 else ",".join(f"{v:g}" for v in value)
        shown.append(f"{name}={value:g}" if isinstance(value, float) else f"{name}={value}")
    return ", ".join(shown)


def _left_to_full(study: Study, cells: int, laws: list[str], cases: list[str]) -> int:
    """How many cells ``study``, planned with ``cells``, leaves to the full report."""
    if study.costly_points is None:
        return 0
    whole = dataclasses.replace(study, costly_points=None)
    return len(whole.plan(laws, cases).jobs) - cells


def _thinning(left: dict[str, tuple[int, int | None]]) -> list[str]:
    """Notes on the studies whose costly laws ran a subsample: study -> (cells left, points)."""
    by_points: dict[int | None, list[str]] = {}
    for name, (cells, points) in left.items():
        if cells:
            by_points.setdefault(points, []).append(name)
    return [
        "the engines and the laws that integrate the impact in time are given "
        f"{_values(points)} of each swept axis (parameter, option, transform) and their "
        "accuracy knob at its default in "
        f"{', '.join(f'`{name}`' for name in names)}: "
        f"{sum(left[name][0] for name in names)} cells are left to the full report "
        "(`lawbench report --full`)"
        for points, names in by_points.items()
    ]


def _engines_left(cases: Sequence[Case]) -> list[str]:
    """A note on the scenes whose engine cells the quick report leaves to the full one."""
    names = [f"`{case.name}`" for case in cases if not case.quick_engines]
    if not names:
        return []
    return [
        f"the engines step {', '.join(names)} in the full report only (`lawbench report "
        "--full`): in the quick one their cells on those scenes would add some ten seconds"
    ]


def _measured_less(studies: list[Study]) -> list[str]:
    """A note on the studies that measure the costly laws' cells for fewer quantities."""
    if not studies:
        return []
    kept = sorted({name for s in studies for name in s.costly_measures or ()})
    names = ", ".join(f"`{s.name}`" for s in studies)
    return [
        f"in {names} those laws' cells are measured for {', '.join(kept)} only, but the "
        "ground truth's own model's: their numerical error, against their tightest setting "
        "(the costliest solve of a sweep), is in the full report"
    ]


def _values(points: int | None) -> str:
    """Which values of an axis `lawbench.studies.study.evenly` keeps, in words."""
    if points == 1:
        return "the first value"
    return f"{points} evenly spaced values (the first and the last among them)"


class Context:
    """What the sections share: the configuration, the output folder, the study tables."""

    def __init__(self, config: Config, out: Path) -> None:
        self.config, self.out = config, out
        self.laws, law_notes = registered(LAWS, config.laws)
        self.cases, case_notes = registered(CASES, config.cases)
        self.notes = law_notes + case_notes
        self.studies: list[Study] = []
        # Declared studies this page does not run -> why.
        self.left_out: dict[str, str] = {}
        self._tables: dict[str, pd.DataFrame] = {}

    @property
    def rerun(self) -> str:
        """The command that writes this report again."""
        return self.config.rerun(str(self.out))

    def case(self, name: str) -> Case:
        """The scene called ``name``."""
        return CASES.get(name)

    def law(self, name: str) -> Law:
        """The law called ``name``."""
        return LAWS.get(name)

    def run(self, views: Sequence[str]) -> None:
        """Run every study the ``views`` draw, all through one executor."""
        config, full = self.config, self.config.mode == "full"
        laws = [law.name for law in self.laws]
        cases = [case.name for case in self.cases]
        plans, thinned = [], {}
        for study in STUDIES.values():
            if view(study) not in views:
                self.left_out[study.name] = f"no section draws it (`lawbench study {study.name}`)"
                continue
            if study.slow and not full:
                self.left_out[study.name] = (
                    "a slow study, in the full report (`lawbench report --full`)"
                )
                continue
            if config.studies is not None and study.name not in config.studies:
                self.left_out[study.name] = "not among the studies asked for"
                continue
            study = study.preset(config.mode)
            plan = study.plan(laws, cases)
            if plan.jobs:
                self.studies.append(study)
                plans.append((plan, self.out / "runs" / f"{study.name}.parquet"))
                left = _left_to_full(study, len(plan.jobs), laws, cases)
                thinned[study.name] = (left, study.costly_points)
            else:
                self.left_out[study.name] = "none of its laws and scenes is selected"
        self.notes += _thinning(thinned)
        if not full:
            self.notes += _engines_left(self.cases)
        self.notes += _measured_less([s for s in self.studies if s.costly_measures is not None])
        if not full:
            shutil.rmtree(self.out / "runs", ignore_errors=True)
        executor = Executor(
            config.executor, config.workers, config.budget_s, config.address, chunk_size=10
        )
        with executor:
            results = run_many(plans, executor, resume=True)
        for study, (table, _) in zip(self.studies, results, strict=True):
            self._tables[study.name] = table

    def tables(self, name: str) -> list[tuple[Study, pd.DataFrame]]:
        """The studies the view called ``name`` draws that ran, with their tables."""
        return [(s, self._tables[s.name]) for s in self.studies if view(s) == name]

    def every_table(self) -> list[tuple[Study, pd.DataFrame]]:
        """Every study that ran, with its table."""
        return [(s, self._tables[s.name]) for s in self.studies]
