"""Section 4, stability at the extremes: a grid of verdicts per law.

The cells and their verdicts are defined in `lawbench.report.extremes`. Cells on a scene's
own parameters run as jobs (guarded workers in the quick mode, the runner in the full mode,
where a solve over the budget counts as a time-out); grazing and duplicated-contact problems
run in the guarded workers, killed at the budget. NaN, time-out and unexpected-error cells are
listed with a command that reproduces them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.colors import to_rgb
from matplotlib.patches import Patch

from lawbench.report import plots, tasks
from lawbench.report.extremes import CATEGORIES, TOLERANCE, UNACCEPTABLE, Cell, plan, verdict
from lawbench.report.page import Figure, Section, Table
from lawbench.report.runs import Context, Job, from_result

ANCHOR, TITLE = "stability", "Stability at the extremes"
COLOURS = {
    "ok": "#66bb6a",
    "check failed": "#fff176",
    "conservation broken": "#ffa726",
    "clear error": "#b0bec5",
    "NaN": "#e53935",
    "time-out": "#8e24aa",
    "unexpected error": "#4e342e",
}


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's runs; the returned function builds it."""
    cells, notes = plan(ctx)
    batch = ctx.batch("stability", [c.job for c in cells if c.job], checks=["energy_gain"])
    handles = {
        k: ctx.guard.submit(tasks.solve_problem, c.law, c.problem, {})
        for k, c in enumerate(cells)
        if c.problem is not None
    }
    return lambda: _build(ctx, cells, notes, batch.records(), handles)


def _judge(ctx: Context, cell: Cell, record: dict[str, Any]) -> dict[str, Any]:
    case = ctx.case(cell.case)
    params = case.parameters(**cell.params)
    problem = cell.problem if cell.problem is not None else case.build(**params)
    judged = verdict(
        cell, record, problem, case.momentum_axes(params), ctx.law(cell.law), ctx.config.budget_s
    )
    return {
        "law": cell.law,
        "axis": cell.axis,
        "case": cell.case,
        "value": cell.value,
        "e": cell.e,
        **judged,
        "wall_time_s": record.get("wall_time_s"),
        "row": cell.row,
        "reproducer": cell.reproducer(),
    }


def _build(
    ctx: Context, cells: list[Cell], notes: list[str], records: list, handles: dict
) -> Section:
    jobs = iter(records)
    rows = []
    for k, cell in enumerate(cells):
        if cell.job is not None:
            record = next(jobs)
        else:
            result = ctx.guard.result(handles[k])
            record = from_result(result, Job(cell.law, cell.case, cell.params), ctx.config.budget_s)
        try:
            rows.append(_judge(ctx, cell, record))
        except Exception as exc:  # the scene's problem could not be rebuilt: keep the cell
            detail = f"the report could not judge it: {type(exc).__name__}: {exc}"
            row = {"law": cell.law, "axis": cell.axis, "case": cell.case, "value": cell.value}
            row.update(e=cell.e, verdict="unexpected error", detail=detail, row=cell.row)
            rows.append({**row, "reproducer": cell.reproducer()})
    frame = pd.DataFrame(rows)
    config = ctx.config
    blocks: list[Any] = [
        "Each law at the extremes: stiffness ratios "
        f"{_span(config.stiffness_ratios)} ({', '.join(config.stiffness_cases)}), the striking "
        f"ball's mass over the others' {_span(config.mass_ratios)}, grazing approach speeds "
        f"{_span(config.grazing_speeds)} m/s, chains of {_span(config.chain_lengths)} balls, "
        f"mu in {{{', '.join(f'{m:g}' for m in config.frictions)}}} on every frictional scene, "
        "and contact 0 given twice; each crossed with e in "
        f"{{{', '.join(f'{e:g}' for e in config.restitutions)}}}. Each solve has "
        f"{config.budget_s:g} s of wall time. Verdicts and errors are defined in "
        "`lawbench.report.extremes`: momentum error is the impulse-momentum residual and the "
        "change of conserved momentum over the largest momentum; energy error is |dT| / T- "
        "for elastic frictionless cells and the energy created otherwise."
        + "".join(f" Note: {n}." for n in notes)
    ]
    if frame.empty:
        return Section(ANCHOR, TITLE, [*blocks, "No cell: no law or scene selected."])
    blocks.append(_counts(frame))
    blocks += _unacceptable(frame)
    blocks.append(_errors_figure(frame))
    for law, part in frame.groupby("law", sort=False):
        blocks.append(_law_figure(law, part.reset_index(drop=True)))
    return Section(ANCHOR, TITLE, blocks)


def _span(values: tuple[float, ...]) -> str:
    return f"{min(values):g} to {max(values):g}" if len(values) > 1 else f"{values[0]:g}"


def _counts(frame: pd.DataFrame) -> Table:
    counts = pd.crosstab(frame["law"], frame["verdict"]).reindex(
        columns=list(CATEGORIES), fill_value=0
    )
    worst = frame.groupby("law")[["momentum_error", "energy_error"]].max()
    table = counts.join(worst).reset_index()
    shown = table.copy()
    for column in ("momentum_error", "energy_error"):
        shown[column] = [f"{x:.2g}" if x == x else "" for x in table[column]]
    return Table(
        "stability_summary",
        "Cells per verdict and the largest momentum and energy errors seen, per law; every "
        "cell with its verdict is in the CSV of the law's figure below.",
        shown,
        table,
    )


def _unacceptable(frame: pd.DataFrame) -> list[Any]:
    bad = frame[frame["verdict"].isin(UNACCEPTABLE)]
    if bad.empty:
        return ["No NaN, time-out or unexpected-error cell."]
    shown = bad[["law", "row", "value", "verdict", "detail", "reproducer"]]
    return [
        f"{len(bad)} cells gave NaN, ran out of time or raised an unexpected error:",
        Table(
            "stability_unacceptable",
            "Cells that must not happen, with a command that reproduces each.",
            shown,
        ),
    ]


def _errors_figure(frame: pd.DataFrame) -> Figure:
    fig, axes = plots.figure(1, 2, width=6.0, height=3.6)
    laws = list(dict.fromkeys(frame["law"]))
    answered = frame[frame["momentum_error"].notna()]
    for ax, column in zip(axes[0], ("momentum_error", "energy_error"), strict=True):
        for k, law in enumerate(laws):
            values = answered.loc[answered["law"] == law, column].to_numpy()
            spread = np.linspace(-0.25, 0.25, len(values)) if len(values) > 1 else [0.0]
            style = plots.law_style(law)
            ax.plot(
                k + np.asarray(spread),
                plots.floored(values),
                style["marker"],
                color=style["color"],
                alpha=0.6,
                linestyle="none",
            )
        ax.axhline(TOLERANCE, color="k", linestyle=":", linewidth=0.8)
        ax.set_xticks(range(len(laws)), laws, rotation=45, ha="right")
        ax.set(yscale="log", ylabel=column.replace("_", " ") + " (relative)")
    data = answered[["law", "row", "value", "momentum_error", "energy_error"]]
    return Figure(
        "stability_errors",
        "Momentum and energy errors of every answered cell of the stability grid, per law "
        f"(exact zeros drawn at {plots.FLOOR:g}; dotted line: the tolerance {TOLERANCE:g} of "
        "exact laws).",
        fig,
        data.reset_index(drop=True),
    )


def _law_figure(law: str, part: pd.DataFrame) -> Figure:
    labels = list(dict.fromkeys(part["row"]))
    width = max(int(part.groupby("row").size().max()), 1)
    image = np.ones((len(labels), width, 3))
    fig, axes = plots.figure(1, 1, width=1.0 * width + 4.5, height=0.32 * len(labels) + 1.2)
    ax = axes[0, 0]
    for r, label in enumerate(labels):
        for c, cell in enumerate(part[part["row"] == label].itertuples()):
            image[r, c] = to_rgb(COLOURS[cell.verdict])
            ax.text(c, r, f"{cell.value:g}", ha="center", va="center", fontsize=6.5)
    ax.imshow(image, aspect="auto", interpolation="nearest")
    ax.set_yticks(range(len(labels)), labels, fontsize=7)
    ax.set_xticks([])
    present = [v for v in CATEGORIES if v in set(part["verdict"])]
    ax.legend(
        handles=[Patch(color=COLOURS[v], label=v) for v in present],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize="x-small",
    )
    ax.set_title(f"{law}: verdict per cell (the number is the swept value)")
    return Figure(
        f"stability_{law}",
        f"Stability grid of `{law}`: one row per extreme and scene (with e), one cell per "
        "value swept; colour: the verdict.",
        fig,
        part.drop(columns=["row"]),
    )
