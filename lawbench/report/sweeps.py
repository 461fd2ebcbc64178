"""Section 8, sweeps of the sources' systems: what each law gives as one parameter varies.

A view of the studies declared with ``view="sweep"``: the study's first axis (a grid parameter)
is the abscissa, and each of the measures its other axes name (every measure when it names
none) is drawn against it, one line per law, one panel per
measure (a vector measure gives one panel per component); the table lists every cell with its
verdict. Measures name their units in the study's title, so quantities of different units
never share a panel.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from lawbench.report import plots
from lawbench.report.page import Figure, Section, Table, number
from lawbench.report.runs import Context, axis_value, parsed

ANCHOR, TITLE, VIEWS = "sweeps", "Sweeps of the sources' systems", ("sweep",)
PANELS_PER_ROW = 3


def build(ctx: Context) -> Section:
    """The section, from every sweep study that ran."""
    blocks: list[Any] = [
        "Each system of the sources swept along one parameter: every law that treats it, one "
        "line per law, each measure on its own panel (the units are in the study's title)."
    ]
    for study, table in ctx.tables("sweep"):
        frame = _tidy(table, study.axes[0], list(study.axes[1:]) or list(study.measures))
        if frame.empty:
            blocks.append(f"Study `{study.name}`: no law answered.")
            continue
        blocks.append(_figure(study.name, study.title, frame, study.axes[0]))
        shown = frame.copy()
        for column in shown.columns.drop(["law", "verdict"]):
            shown[column] = shown[column].map(number)
        blocks.append(Table(f"sweep_{study.name}", study.title, shown, data=frame))
    return Section(ANCHOR, TITLE, blocks)


def _tidy(table: pd.DataFrame, axis: str, measures: list[str]) -> pd.DataFrame:
    """One row per answered cell: law, the axis, each numeric measure (vectors expanded)."""
    rows = []
    for row in table.fillna({"error_class": ""}).to_dict("records"):
        if row["error_class"]:
            continue
        tidy: dict[str, Any] = {"law": row["law"], axis: axis_value(row, axis)}
        for name in measures:
            value = parsed(row.get(name))
            if isinstance(value, list):
                tidy |= {f"{name}[{k}]": v for k, v in enumerate(value) if _number(v)}
            elif _number(value):
                tidy[name] = value
        tidy["verdict"] = row["verdict"]
        rows.append(tidy)
    return pd.DataFrame(rows)


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _figure(name: str, title: str, frame: pd.DataFrame, axis: str) -> Figure:
    columns = [c for c in frame.columns if c not in ("law", axis, "verdict")]
    rows = -(-len(columns) // PANELS_PER_ROW)
    fig, axes = plots.figure(rows, min(len(columns), PANELS_PER_ROW))
    for ax, column in zip(axes.flat, columns, strict=False):
        for law, group in frame.groupby("law", sort=True):
            ordered = group.sort_values(axis)
            ax.plot(ordered[axis], ordered[column], **plots.law_style(str(law)))
        ax.set_xlabel(axis)
        ax.set_title(column)
        ax.legend(fontsize="small")
    for ax in list(axes.flat)[len(columns) :]:
        ax.set_visible(False)
    data = frame.replace({np.nan: None})
    return Figure(f"sweep_{name}", title, fig, data)
