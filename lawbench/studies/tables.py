"""Study tables as a reader sees them: what ``lawbench study NAME`` prints and writes.

A study's table (`lawbench.studies.runner.collect`) has one row per cell with every record column
(`lawbench.studies.record.Record`). The printed view keeps what the study varies and measures: the
law (and scene, when it has several), each swept parameter as a typed column, the transform's value,
the options swept, the measured columns (a mapping measure spread over one column per key) and the
verdict, for every cell that gave an answer; the cells that did not are notes, one per law and
reason, each with the count of its cells. ``--out`` writes the full records in the tidy format of a
run (`lawbench.studies.runfile.save_run`), which `lawbench.load_run` reads.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import pandas as pd

from lawbench.core.errors import InvalidProblem
from lawbench.core.transforms import parse
from lawbench.studies.declared import STUDIES
from lawbench.studies.guard import BUDGET_S
from lawbench.studies.record import budget_text
from lawbench.studies.runner import Executor, collect
from lawbench.studies.study import Study


@dataclass
class Table:
    """A study and its table: the full records (``data``) and the view of them."""

    study: Study
    data: pd.DataFrame

    @property
    def frame(self) -> pd.DataFrame:
        """The answered cells: what varies, what is measured, and the verdict."""
        data = self.data
        if data.empty or "error_class" not in data:
            return pd.DataFrame()
        answered = data[data["error_class"].fillna("") == ""]
        if answered.empty:  # every cell failed: no measure was written, the notes say why
            return pd.DataFrame()
        columns: dict[str, Any] = {"law": answered["law"]}
        if len(set(data["case"])) > 1:
            columns["case"] = answered["case"]
        for name in self.study.grid:
            columns[name] = [_plain(json.loads(p).get(name)) for p in answered["params"]]
        if self.study.transform:
            columns[self.study.transform] = [parse(t)[1] for t in answered["transform"]]
        for name in _varied_options(answered["options"]):
            columns[name] = [json.loads(o).get(name) for o in answered["options"]]
        for name in self.study.measures:
            columns.update(_spread(name, answered[name]))
        columns["verdict"] = answered["verdict"]
        return pd.DataFrame(columns).reset_index(drop=True)

    @property
    def notes(self) -> list[str]:
        """One line per law and reason for the cells that gave no answer, with their count."""
        data = self.data
        if data.empty or "error_class" not in data:
            return []
        failed = data[data["error_class"].fillna("") != ""]
        notes = []
        for (law, verdict, message), group in failed.groupby(
            ["law", "verdict", "error_message"], sort=False
        ):
            total = int((data["law"] == law).sum())
            first = group.iloc[0]
            budget = budget_text(first.to_dict())
            where = f"{len(group)} of {total} cells, first: `{first['reproducer']}`"
            notes.append(
                f"{law}: {verdict} on {where}: {first['error_class']}: {message}"
                + (f" ({budget})" if budget else "")
            )
        return notes

    def text(self) -> str:
        """The view as aligned text, the study's title first and its notes last."""
        frame = self.frame
        body = frame.to_string(index=False, float_format=lambda x: f"{x:.6g}")
        lines = [f"{self.study.name}: {self.study.title}", ""]
        lines.append(body if len(frame) else "(no cell gave an answer)")
        return "\n".join([*lines, *(f"note: {note}" for note in self.notes)])


def _plain(value: Any) -> Any:
    """A parameter value for a table column: a list of one number as the number."""
    return value[0] if isinstance(value, list) and len(value) == 1 else value


def _varied_options(options: pd.Series) -> list[str]:
    parsed = [json.loads(o) for o in options]
    names = dict.fromkeys(name for o in parsed for name in o)
    return [n for n in names if len({json.dumps(o.get(n)) for o in parsed}) > 1]


def _spread(name: str, values: pd.Series) -> dict[str, list[Any]]:
    """A measure's column, or one column per key when the measure is a mapping."""
    parsed = [json.loads(v) if isinstance(v, str) else v for v in values]
    if parsed and all(isinstance(v, dict) for v in parsed):
        keys = dict.fromkeys(k for v in parsed for k in v)
        return {f"{name}[{k}]": [v.get(k) for v in parsed] for k in keys}
    return {name: parsed}


def study_table(
    name: str,
    given: dict[str, str] | None = None,
    executor: str = "serial",
    workers: int | None = None,
    budget_s: float = BUDGET_S,
) -> Table:
    """Run the study called ``name`` (with the parameters ``given`` fixed) and tabulate it.

    Raises
    ------
    InvalidProblem
        For an unknown study, a parameter none of its scenes has, or a bad value.
    """
    study = STUDIES.get(name)
    if given:
        study = study.with_params(_coerced(study, given))
    with Executor(executor, workers, budget_s) as pool:
        return Table(study, collect(study.plan(), pool))


def _coerced(study: Study, given: dict[str, str]) -> dict[str, Any]:
    """The values of ``given`` as the study's first scene that has each parameter reads them."""
    from lawbench.core.case import CASES

    values = {}
    for key, text in given.items():
        specs = [s for c in study.case_names() for s in CASES.get(c).params if s.name == key]
        if not specs:
            raise InvalidProblem(f"--set {key}: no scene of study {study.name!r} has it")
        values[key] = specs[0].coerce(text)
    return values
