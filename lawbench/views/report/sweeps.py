"""Section 8, sweeps of the sources' systems: what each law gives as one parameter varies.

A view of the studies declared with the shape ``sweep``: the study's first axis (a grid parameter)
is the abscissa, and each of the measures its other axes name (every measure when it names
none) is drawn against it, one line per law and value of the other grid parameters, one panel per
measure (a vector measure gives one panel per component); the table lists every cell with its
verdict. An abscissa over two decades or more (a stiffness ratio) is drawn on a log scale.
The abscissa takes the unit of the scene's parameter, each panel the unit the study
declares for its measure (``Study.units``): one panel holds one quantity, so quantities of
different units (m/s, rad/s) never share an axis; a cell without a value (a path that does not
curve) is a gap in its line, never a zero. The laws' legend is below the panels. A study
declared with the shape ``table_path`` draws each law's path of a ball on the table (its
``table_path`` measure, x and y in m) in one panel per value of its parameter.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from lawbench.views.report import plots
from lawbench.views.report.page import Figure, Section, Table, number
from lawbench.views.report.plots import unit_label
from lawbench.views.report.runs import Context, axis_value, parsed

ANCHOR, TITLE, VIEWS = "sweeps", "Sweeps of the sources' systems", ("sweep", "table_path")
PANELS_PER_ROW = 3
DASHES = ("-", "--", ":", "-.")
# A measure's component below this fraction of its largest component is drawn as zero.
NOISE = 1e-12


def build(ctx: Context) -> Section:
    """The section, from every sweep study that ran."""
    blocks: list[Any] = [
        "Each system of the sources swept along one parameter: every law that treats it, one "
        "line per law, each measure on its own panel (the units are in the study's title)."
    ]
    for study, table in ctx.tables("sweep"):
        lines = [name for name in study.grid if name != study.axes[0]]
        frame = _tidy(table, study.axes[0], list(study.axes[1:]) or list(study.measures), lines)
        if frame.empty:
            blocks.append(f"Study `{study.name}`: no law answered.")
            continue
        units = _units(ctx, study.case_names()[0], study.axes[0], study.units)
        blocks.append(_figure(study.name, study.title, frame, study.axes[0], units))
        shown = frame.copy()
        for column in shown.columns.drop(["law", "verdict"]):
            shown[column] = shown[column].map(number)
        blocks.append(Table(f"sweep_{study.name}", study.title, shown, data=frame))
    for study, table in ctx.tables("table_path"):
        blocks.append(_paths(study.name, study.title, table, study.axes[0]))
    return Section(ANCHOR, TITLE, blocks)


def _paths(name: str, title: str, table: pd.DataFrame, axis: str) -> Figure:
    """One panel per value of ``axis``: every law's ``table_path`` (x, y in m), equal scales.

    Where a law's ball lands from its hop (a cross) and starts rolling (a dot) is marked.
    """
    rows = [r for r in table.fillna({"error_class": ""}).to_dict("records") if not r["error_class"]]
    values = sorted({axis_value(row, axis) for row in rows})
    fig, axes = plots.figure(1, max(len(values), 1), width=4.0, height=4.0)
    data, missing = [], []
    for row in rows:
        path = parsed(row.get("table_path"))
        value = axis_value(row, axis)
        if not isinstance(path, dict):
            missing.append(f"{row['law']} at {axis} = {value:g}")
            continue
        ax = axes[0, values.index(value)]
        x, y = np.asarray(path["x"]), np.asarray(path["y"])
        style = plots.law_style(row["law"])
        ax.plot(x, y, color=style["color"], label=row["law"], linewidth=1.2)
        for key, marker in (("t_land", "x"), ("t_roll", "o")):
            k = int(np.searchsorted(path["t"], path[key]))
            if 0 < k < len(x):
                ax.plot(x[k], y[k], marker, color=style["color"], markersize=4)
        data.append(pd.DataFrame({"law": row["law"], axis: value, "x": x, "y": y}))
    for ax, value in zip(axes[0], values, strict=False):
        ax.set(title=f"{axis} = {value:g}", xlabel="x [m]", ylabel="y [m]")
        ax.set_aspect("equal", adjustable="datalim")
    caption = (
        f"{title}. Each law's post-impact velocity and spin give the path in closed form: a "
        "hop (landing marked by a cross), sliding on a parabola, rolling from the dot on."
    )
    if missing:
        caption += " No path (the ball does not move on the table): " + ", ".join(missing) + "."
    frame = pd.concat(data, ignore_index=True) if data else pd.DataFrame()
    return Figure(f"sweep_{name}", caption, fig, frame)


def _tidy(table: pd.DataFrame, axis: str, measures: list[str], lines: list[str]) -> pd.DataFrame:
    """One row per answered cell: law, the axis, each numeric measure (vectors expanded).

    The other grid parameters ``lines`` join the law's name, so each of their values is a line
    of its own (``lzb (mu=1)``).
    """
    rows = []
    for row in table.fillna({"error_class": ""}).to_dict("records"):
        if row["error_class"]:
            continue
        values = ", ".join(f"{name}={axis_value(row, name):g}" for name in lines)
        law = f"{row['law']} ({values})" if values else row["law"]
        tidy: dict[str, Any] = {"law": law, axis: axis_value(row, axis)}
        for name in measures:
            value = parsed(row.get(name))
            if isinstance(value, dict):
                tidy |= {f"{name}[{k}]": v for k, v in value.items() if _number(v)}
            elif isinstance(value, list):
                tidy |= {f"{name}[{k}]": v for k, v in enumerate(value) if _number(v)}
            elif _number(value):
                tidy[name] = value
        tidy["verdict"] = row["verdict"]
        rows.append(tidy)
    return pd.DataFrame(rows)


def _units(ctx: Context, case: str, axis: str, declared: Mapping[str, str]) -> dict[str, str]:
    """Unit per column: the axis's from its scene's parameter, the measures' as declared."""
    specs = {spec.name: spec for spec in ctx.case(case).params}
    units = dict(declared)
    if axis in specs:
        units[axis] = specs[axis].unit
    return units


def _largest(frame: pd.DataFrame, column: str) -> float:
    """The largest magnitude among the components of ``column``'s measure, every law."""
    base = column.split("[", 1)[0]
    parts = [c for c in frame.columns if c == base or c.startswith(f"{base}[")]
    return float(np.nanmax(np.abs(frame[parts].to_numpy(dtype=float))))


def coinciding(frame: pd.DataFrame, axis: str, columns: list[str]) -> dict[str, list[str]]:
    """The lines to draw, each with the names of every law whose answers it shows.

    One line ``moreau = newton`` instead of one hidden under another. Answers coincide when
    every value along the axis agrees to 1e-9 of the largest value.
    """
    scale = max(float(np.nanmax(np.abs(frame[columns].to_numpy(dtype=float)))), 1e-300)
    drawn: dict[str, list[str]] = {}
    series = {
        law: group.sort_values(axis)[[axis, *columns]].to_numpy(dtype=float)
        for law, group in frame.groupby("law", sort=True)
    }
    for law, values in series.items():
        first = next(
            (
                other
                for other in drawn
                if series[other].shape == values.shape
                and np.allclose(series[other], values, rtol=0, atol=1e-9 * scale, equal_nan=True)
            ),
            None,
        )
        if first is None:
            drawn[str(law)] = [str(law)]
        else:
            drawn[first].append(str(law))
    return drawn


def _decades(values: pd.Series) -> float:
    """Decades a positive abscissa spans (0 when it reaches zero or below): a log axis from 2."""
    low, high = float(values.min()), float(values.max())
    return float(np.log10(high / low)) if low > 0 else 0.0


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _figure(
    name: str,
    title: str,
    frame: pd.DataFrame,
    axis: str,
    units: Mapping[str, str] | None = None,
) -> Figure:
    columns = [c for c in frame.columns if c not in ("law", axis, "verdict")]
    rows = -(-len(columns) // PANELS_PER_ROW)
    fig, axes = plots.figure(rows, min(len(columns), PANELS_PER_ROW))
    units = units or {}
    # A line named "law (mu=1)" takes its law's colour and a dash pattern of its own values.
    variants = sorted({str(name).partition(" (")[2] for name in frame["law"]})
    same = coinciding(frame, axis, columns)
    floors = {c: NOISE * _largest(frame, c) for c in columns}
    for ax, column in zip(axes.flat, columns, strict=False):
        for law, group in frame.groupby("law", sort=True):
            if law not in same:
                continue
            ordered = group.sort_values(axis)
            # Rounding noise of a quantity that is zero (1e-15 beside a component of 4) is 0;
            # a cell without the measure (NaN) stays NaN, a gap in its line.
            shown = ordered[column].mask(ordered[column].abs() <= floors[column], 0.0)
            base, _, values = str(law).partition(" (")
            style = {**plots.law_style(base), "label": " = ".join(same[law])}
            style["linestyle"] = DASHES[variants.index(values) % len(DASHES)]
            ax.plot(ordered[axis], shown, **style)
        if _decades(frame[axis]) >= 2:
            plots.log_scale(ax, "x")
        ax.set_xlabel(unit_label(axis, units))
        ax.set_ylabel(unit_label(column, units))
        ax.set_title(column)
    for ax in list(axes.flat)[len(columns) :]:
        ax.set_visible(False)
    data = frame.replace({np.nan: None})
    return Figure(f"sweep_{name}", title, fig, data)
