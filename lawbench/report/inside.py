"""Section 7, inside an impact: impulses, velocities and energies along the impact.

A view of the studies the laws declare with `lawbench.study_shapes.impact_path`: the laws that
resolve the impact along an impact variable return, with the option ``path``, what happens on
the way (`lawbench.outcome.Outcome.path`). Each quantity is drawn against the path's first entry
(the impact variable: time, normal impulse, or Jia's parameter), one panel per quantity and
unit, one line per component, labelled with its name and unit; phases a law reports at normal
impulses (stick, slip, end of compression) are marked when the impact variable is the normal
impulse.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd

from lawbench.case import Case
from lawbench.report import plots
from lawbench.report.page import Figure, Section
from lawbench.report.runs import Context, parsed
from lawbench.report.summary import failure

ANCHOR, TITLE, VIEWS = "inside", "Inside an impact", ("inside",)
MAX_COMPONENTS = 12
# What a path's entries are, and their units; 'v' takes the units of the scene's coordinates.
QUANTITIES = {
    "t": ("time", "s"),
    "tau": ("impulse-curve parameter", "N s"),
    "Pn": ("normal impulse", "N s"),
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
        if 1 < len(list(chosen)) <= 6:
            ax.legend(fontsize="xx-small")
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
            fontsize=6,
            va="top",
        )
