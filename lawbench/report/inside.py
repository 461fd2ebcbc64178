"""Section 7, inside an impact: impulses, velocities and stored energies along the impact.

The laws that resolve the impact along an impact variable return, with the option ``path``,
what happens on the way (`lawbench.outcome.Outcome.path`). Each study below draws every
quantity of the path against the path's first entry (the impact variable: time, normal impulse
or Jia's parameter), one panel per quantity, one line per component; a law that reports phases
at normal impulses (stick, slip, end of compression) has them marked when the impact variable
is the normal impulse. A study whose law or scene is not registered is named as missing.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from lawbench.report import plots, tasks
from lawbench.report.page import Figure, Section
from lawbench.report.runs import Context

ANCHOR, TITLE = "inside", "Inside an impact"
# Law, what the study shows, and the scenes to try in order (with their parameters).
STUDIES = (
    ("jia", "Jia's impulse curve for two colliding balls", (("ball_chain", {"n": 2}),)),
    ("lzb", "energy exchanged between the contacts of the bead column", (("bead_column", {}),)),
    (
        "darboux_keller",
        "stick and slip phases along the impulse",
        (("lamina", {}), ("falling_rod", {})),
    ),
)
MAX_COMPONENTS = 12


def _plan(ctx: Context) -> tuple[list[tuple], list[str]]:
    studies, notes = [], []
    for law, what, candidates in STUDIES:
        if ctx.law(law) is None:
            notes.append(f"law `{law}` is not registered: no {what}")
            continue
        found = next(((c, p) for c, p in candidates if ctx.case(c) is not None), None)
        missing = [c for c, _ in candidates if ctx.case(c) is None]
        if missing:
            notes.append(f"scene `{missing[0]}` is not registered (wanted for `{law}`)")
        if found is None:
            continue
        studies.append((law, what, *found))
    return studies, notes


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's solves; the returned function builds it."""
    studies, notes = _plan(ctx)
    handles = [ctx.guard.submit(tasks.impact_path, s[0], s[2], s[3]) for s in studies]
    return lambda: _build(ctx, studies, notes, handles)


def _build(ctx: Context, studies: list, notes: list[str], handles: list) -> Section:
    blocks: list[Any] = [
        "Quantities along the impact, as the laws that integrate it report them (option "
        "`path`)." + "".join(f" Note: {n}." for n in notes)
    ]
    for (law, what, case, params), handle in zip(studies, handles, strict=True):
        result = ctx.guard.result(handle)
        if result.status != "ok":
            reason = result.error_class or result.status
            blocks.append(f"`{law}` on `{case}` gave no path: {reason}: {result.error_message}.")
            continue
        blocks.append(_figure(law, what, case, params, result.value))
    return Section(ANCHOR, TITLE, blocks)


def _figure(law: str, what: str, case: str, params: dict, found: dict[str, Any]) -> Figure:
    path = found["path"]
    x_name = next(iter(path))
    x = np.asarray(path[x_name], dtype=float).reshape(-1)
    shown = [k for k in path if k != x_name and np.asarray(path[k]).size]
    columns = min(len(shown), 3) or 1
    rows = -(-len(shown) // columns) or 1
    fig, axes = plots.figure(rows, columns, width=4.0, height=3.0)
    data = []
    for ax, key in zip(axes.flat, shown, strict=False):
        values = np.asarray(path[key], dtype=float).reshape(len(x), -1)
        for j in range(min(values.shape[1], MAX_COMPONENTS)):
            label = f"{key}[{j}]" if values.shape[1] > 1 else key
            ax.plot(x, values[:, j], label=label, linewidth=1.0)
            data.append(
                pd.DataFrame({x_name: x, "quantity": key, "component": j, "value": values[:, j]})
            )
        if x_name == "Pn" and np.ndim(path["Pn"]) == 1:
            _mark_phases(ax, found["phases"], found["phase_impulses"])
        ax.set(title=key, xlabel=x_name)
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 3))
        if 1 < values.shape[1] <= 6:
            ax.legend(fontsize="xx-small")
    for ax in axes.flat[len(shown) :]:
        ax.set_axis_off()
    setting = ", ".join(f"{k}={v}" for k, v in params.items()) or "defaults"
    fig.suptitle(f"{law} on {case} ({setting})")
    return Figure(
        f"inside_{law}_{case}",
        f"{what}: `{law}` on `{case}` ({setting}), every quantity of its path against "
        f"`{x_name}`; {found['formulation']}; dT / T- = "
        f"{found['dT'] / found['T_minus']:.3g}"
        + ("; dotted: the phases the law reports" if found["phases"] else "")
        + ".",
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
