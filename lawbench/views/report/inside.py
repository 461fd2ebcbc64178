"""Section 7, inside an impact: impulses, velocities and energies along the impact.

A view of the studies the laws declare with `lawbench.studies.declared.impact_path`: the laws that
resolve the impact along an impact variable return, with the option ``path``, what happens on the
way (`lawbench.core.outcome.Outcome.path`). Each quantity is drawn against the path's first entry
(the impact variable: time, normal impulse, or Jia's parameter), one panel per quantity and unit,
one line per component (named in the legend below the panels), labelled with its name and
unit (lzb's impact variable is the total normal impulse, Jia's the impulse-curve parameter, the
compliant model's the time); phases a law reports at normal impulses
(stick, slip, end of compression) are marked when the impact variable is the normal impulse.

A study that names path quantities after its grid parameter in ``axes``
(`lawbench.studies.declared.impact_paths`) is drawn as one figure: one panel per value of the
parameter and per quantity named, each quantity's components (one per contact) against the
impact variable, panels of one quantity on a shared vertical axis.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import Case
from lawbench.studies.study import Study
from lawbench.views.report import plots
from lawbench.views.report.page import Figure, Section
from lawbench.views.report.runs import Context, axis_value, parsed
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "inside", "Inside an impact", ("inside",)
MAX_COMPONENTS = 12
# The lowest value a log axis of `_along` shows, relative to the panel's peak.
SPREAD = 1e-6
# What a path's entries are, and their units; 'v' takes the units of the scene's coordinates.
QUANTITIES = {
    "t": ("time", "s"),
    "tau": ("impulse-curve parameter", "N s"),
    "Pn": ("normal impulse", "N s"),
    "Pn_sum": ("total normal impulse", "N s"),
    "Pt": ("tangential impulse", "N s"),
    "un": ("normal contact velocity", "m/s"),
    "ut": ("tangential contact velocity", "m/s"),
    "Wn": ("work of the normal impulse", "J"),
    "En": ("normal spring energy", "J"),
    "Et": ("tangential spring energy", "J"),
    "stored_energy": ("stored energy", "J"),
    "force": ("contact force", "N"),
    "primary": ("primary contact", "index"),
}


def build(ctx: Context) -> Section:
    """The section, from every path study that ran."""
    blocks: list[Any] = [
        "Quantities along the impact, as the laws that integrate it report them (option "
        "`path`), each with its unit."
    ]
    for study, table in ctx.tables("inside"):
        if len(study.axes) > 1:
            blocks.append(_along(ctx.case(study.case_names()[0]), study, table))
            continue
        row = table.fillna({"error_class": ""}).to_dict("records")[0]
        found = parsed(row.get("path"))
        if row["error_class"] or not found:
            why = failure(row) if row["error_class"] else "the law returned no path"
            blocks.append(f"`{row['law']}` on `{row['case']}` gave no path: {why}.")
            continue
        blocks.append(_figure(ctx.case(row["case"]), study.title, row, found))
    return Section(ANCHOR, TITLE, blocks)


def _panels(case: Case, params: dict, path: dict[str, Any]) -> list[tuple[str, str, Any]]:
    """``(label, key, columns)`` per panel: one per quantity, 'v' split by unit."""
    panels = []
    for key, values in list(path.items())[1:]:
        values = np.asarray(values, dtype=float)
        if not values.size:
            continue
        if key == "v":
            names = case.coordinates(params)
            for unit, indices in plots.by_unit(names).items():
                panels.append((f"velocity [{unit}]", key, indices))
            continue
        name, unit = QUANTITIES.get(key, (key, "unit not stated"))
        panels.append((f"{name} [{unit}]", key, None))
    return panels


def _figure(case: Case, what: str, row: dict[str, Any], found: dict[str, Any]) -> Figure:
    params = case.parameters(**json.loads(row["params"]))
    path = found["path"]
    x_key = next(iter(path))
    x_name, x_unit = QUANTITIES.get(x_key, (x_key, "unit not stated"))
    x = np.asarray(path[x_key], dtype=float).reshape(-1)
    panels = _panels(case, params, path)
    columns = min(len(panels), 3) or 1
    rows = -(-len(panels) // columns) or 1
    fig, axes = plots.figure(rows, columns, width=4.0, height=3.0)
    data = []
    names = case.coordinates(params)
    for ax, (title, key, indices) in zip(axes.flat, panels, strict=False):
        values = np.asarray(path[key], dtype=float).reshape(len(x), -1)
        chosen = indices if indices is not None else range(values.shape[1])
        for j in list(chosen)[:MAX_COMPONENTS]:
            part = names[j] if key == "v" else (f"{key}[{j}]" if values.shape[1] > 1 else key)
            quantity = title.rsplit(" [", 1)[0]
            ax.plot(x, values[:, j], label=part, linewidth=1.0)
            data.append(
                pd.DataFrame(
                    {x_name: x, "quantity": quantity, "component": part, "value": values[:, j]}
                )
            )
        if x_key == "Pn" and np.ndim(path["Pn"]) == 1:
            _mark_phases(ax, found["phases"], found["phase_impulses"])
        ax.set(title=title.rsplit(" [", 1)[0], xlabel=f"{x_name} [{x_unit}]", ylabel=title)
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 3))
    for ax in axes.flat[len(panels) :]:
        ax.set_axis_off()
    setting = row["params"].strip("{}").replace('"', "") or "defaults"
    fig.suptitle(f"{row['law']} on {case.name} ({setting})")
    return Figure(
        f"inside_{row['law']}_{case.name}",
        f"{what}: `{row['law']}` on `{case.name}` ({setting}), every quantity of its path "
        f"against the {x_name}; {row['formulation']}; dT / T- = "
        f"{row['dT'] / row['T_minus']:.3g}"
        + ("; dotted: the phases the law reports" if found["phases"] else "")
        + f". Reproduce: `{row['reproducer']}`.",
        fig,
        pd.concat(data, ignore_index=True) if data else pd.DataFrame(),
    )


def _along(case: Case, study: Study, table: pd.DataFrame) -> Figure:
    """The quantities ``study.axes[1:]`` of each cell's path, side by side.

    A column of panels per value of the study's parameter, a row per law and quantity.
    """
    axis, quantities = study.axes[0], list(study.axes[1:])
    rows = table.fillna({"error_class": ""}).to_dict("records")
    laws = list(dict.fromkeys(row["law"] for row in rows))
    values = sorted({axis_value(row, axis) for row in rows})
    unit = {spec.name: spec.unit for spec in case.params}.get(axis, "")
    fig, axes = plots.figure(len(laws) * len(quantities), len(values), width=3.6, height=2.8)
    data, notes = [], []
    for row in sorted(rows, key=lambda row: (laws.index(row["law"]), axis_value(row, axis))):
        value = axis_value(row, axis)
        col, law = values.index(value), row["law"]
        block = laws.index(law) * len(quantities)
        heading = f"{law}, {axis} = {value:g} {unit}".rstrip()
        found = None if row["error_class"] else parsed(row.get("path"))
        if not found:
            why = failure(row) if row["error_class"] else "the law returned no path"
            notes.append(f"{heading}: no path, {why}")
            for ax in axes[block : block + len(quantities), col]:
                ax.set_axis_off()
            continue
        measured = _measured(row, [name for name in study.measures if name != "path"])
        if measured:
            notes.append(f"{heading}: {measured}")
        path = found["path"]
        x_key = next(iter(path))
        x_name, x_unit = QUANTITIES.get(x_key, (x_key, "unit not stated"))
        x = np.asarray(path[x_key], dtype=float).reshape(-1)
        for line, key in enumerate(quantities):
            ax = axes[block + line, col]
            if col:
                ax.sharey(axes[block + line, 0])
            name, key_unit = QUANTITIES.get(key, (key, "unit not stated"))
            series = np.asarray(path.get(key, []), dtype=float).reshape(len(x), -1)
            for j in range(min(series.shape[1], MAX_COMPONENTS)):
                part = f"contact {j}" if series.shape[1] > 1 else key
                ax.plot(x, series[:, j], label=part, linewidth=1.0)
                data.append(
                    pd.DataFrame(
                        {"law": law, axis: value, x_name: x, "quantity": name}
                        | {"component": part, "value": series[:, j]}
                    )
                )
            ax.set(title=heading, xlabel=f"{x_name} [{x_unit}]", ylabel=f"{name} [{key_unit}]")
            ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 3))
            _spread(ax, series)
    fig.suptitle(f"{', '.join(laws)} on {case.name} along {axis}")
    reproduce = "; ".join(f"`{row['reproducer']}`" for row in rows)
    caption = f"{study.title}. Reproduce: {reproduce}."
    if notes:
        caption += " " + "; ".join(notes) + "."
    frame = pd.concat(data, ignore_index=True) if data else pd.DataFrame()
    return Figure(f"inside_{study.name}", caption, fig, frame)


def _measured(row: dict[str, Any], names: list[str]) -> str:
    """``name = value`` of a cell's other measures (numbers to three figures)."""
    shown = []
    for name in names:
        value = parsed(row.get(name))
        if isinstance(value, list) and all(isinstance(v, int | float) for v in value):
            shown.append(f"{name} = [{', '.join(f'{v:.3g}' for v in value)}]")
        elif isinstance(value, int | float) and not isinstance(value, bool):
            shown.append(f"{name} = {value:.3g}")
    return ", ".join(shown)


def _spread(ax: Any, values: np.ndarray) -> None:
    """A log axis down to `SPREAD` below the peak for widely spread non-negative components.

    When the components' peaks differ by more than three decades, a contact that stores
    little is still seen.
    """
    peaks = np.nanmax(np.abs(values), axis=0) if values.size else np.zeros(0)
    if values.size == 0 or (values < 0).any() or peaks.max() <= 0:
        return
    if peaks.min() < 1e-3 * peaks.max():
        plots.log_scale(ax, "y")
        ax.set_ylim(bottom=SPREAD * peaks.max())


def _mark_phases(ax: Any, phases: list[str], impulses: list[float]) -> None:
    """A dotted line at each normal impulse where phases start, labelled with them."""
    starts: dict[float, list[str]] = {}
    for phase, impulse in zip(phases, impulses, strict=False):
        starts.setdefault(impulse, []).append(phase)
    for impulse, names in starts.items():
        ax.axvline(impulse, color="0.5", linestyle=":", linewidth=0.8)
        ax.annotate(
            " / ".join(names),
            (impulse, 1.0),
            xycoords=("data", "axes fraction"),
            rotation=90,
            fontsize=7,
            va="top",
        )
