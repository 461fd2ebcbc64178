"""Section 4, stability at the extremes: a grid of verdicts per law.

A view of the studies declared with `lawbench.studies.declared.extremes`: each scene names the axes
it is pushed along (stiffness and mass ratios over many decades, grazing approach speeds, long
chains, large friction, a contact given twice), crossed with the values of its other swept
parameters. Every cell's verdict is the worst of its checks' (`lawbench.checks`), or that of the
error that stopped it (`lawbench.core.verdicts.of_error`): a cell stopped by the wall-clock guard is
a
*budget* cell, naming the guard and its seconds. Cells that are not *holds*, *law property* or
*refused* are listed with the command that reproduces each.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.colors import to_rgb
from matplotlib.patches import Patch

from lawbench.core.verdicts import Verdict
from lawbench.studies.study import Study
from lawbench.views.report import plots
from lawbench.views.report.marks import COLOURS, Mark
from lawbench.views.report.page import Figure, Legend, Section, Table
from lawbench.views.report.runs import Context, axis_value, label
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "stability", "Stability at the extremes", ("stability",)
ATTENTION = (Verdict.UNEXPLAINED, Verdict.NUMERICAL_FAILURE, Verdict.BUDGET)


def cells(study: Study, table: pd.DataFrame) -> pd.DataFrame:
    """One row per cell: law, figure row, swept value, verdict, why, reproducer."""
    axis = study.axes[0]
    checks = study.check_names()
    rows = []
    for row in table.fillna({"error_class": ""}).to_dict("records"):
        params = json.loads(row["params"])
        others = label({k: params[k] for k in study.grid if k in params}, skip=(axis,))
        verdict = Verdict(row["verdict"])
        rows.append(
            {
                "law": row["law"],
                "row": f"{study.title} ({row['case']}{', ' + others if others else ''})",
                "value": axis_value(row, axis),
                "verdict": str(verdict),
                "detail": failure(row) if row["error_class"] else _why(row, verdict, checks),
                "momentum": row.get("momentum_value", np.nan),
                "energy": row.get("energy_gain_value", np.nan),
                "reproducer": row["reproducer"],
                "exit status": row["exit_status"],
            }
        )
    return pd.DataFrame(rows)


def _why(row: dict[str, Any], verdict: Verdict, checks: tuple[str, ...]) -> str:
    """The check that decided a solved cell's verdict, and its detail."""
    if verdict == Verdict.HOLDS:
        return ""
    check = next(c for c in checks if row[f"{c}_verdict"] == str(verdict))
    return f"{check}: {row[f'{check}_detail']}"


def build(ctx: Context) -> Section:
    """The section, from every stability study that ran."""
    tables = ctx.tables("stability")
    frame = pd.concat([cells(s, t) for s, t in tables], ignore_index=True) if tables else None
    blocks: list[Any] = [
        "Each law pushed to the extremes each scene declares: "
        + "; ".join(f"{s.title} on `{s.cases[0]}`" for s, _ in tables)
        + f". Each cell has {ctx.config.budget_s:g} s of wall time (the wall-clock guard); its "
        "verdict is the worst of its checks' verdicts (every single-solve check), or that of "
        "the error that stopped it.",
        Legend(),
    ]
    if frame is None or frame.empty:
        return Section(ANCHOR, TITLE, [*blocks, "No cell: no law or scene selected."])
    blocks.append(_counts(frame))
    blocks += _attention(frame)
    blocks.append(_errors_figure(frame))
    for law, part in frame.groupby("law", sort=False):
        blocks.append(_law_figure(law, part.reset_index(drop=True)))
    return Section(ANCHOR, TITLE, blocks)


def _counts(frame: pd.DataFrame) -> Table:
    counts = pd.crosstab(frame["law"], frame["verdict"]).reindex(
        columns=[str(v) for v in Verdict], fill_value=0
    )
    return Table(
        "stability_summary",
        "Cells per verdict, per law; every cell with its verdict, reason and reproducer is in "
        "the CSV of the law's figure below.",
        counts.reset_index(),
    )


def _attention(frame: pd.DataFrame) -> list[Any]:
    bad = frame[frame["verdict"].isin([str(v) for v in ATTENTION])]
    if bad.empty:
        return ["No cell is unexplained, a numerical failure or out of budget."]
    groups = []
    for (law, verdict, detail), group in bad.groupby(["law", "verdict", "detail"], sort=False):
        first = group.iloc[0]
        values = ", ".join(dict.fromkeys(f"{v:g}" for v in group["value"]))
        groups.append(
            {
                "law": law,
                "verdict": Mark("", Verdict(verdict), detail),
                "cells": len(group),
                "where": f"{first['row']} at {values}",
                "detail": detail,
                "reproducer": first["reproducer"],
                "exit status": first["exit status"],
            }
        )
    return [
        f"{len(bad)} cells are unexplained, numerical failures or out of budget; cells with "
        "the same reason are one line, with the command that reproduces the first:",
        Table(
            "stability_attention",
            "Cells to look at: the verdict, the reason, and a command that reruns the first "
            "cell and exits with the status shown (0 answered, 3 refused, 4 budget or solver "
            "failure).",
            pd.DataFrame(groups),
            bad.reset_index(drop=True),
            commands=("reproducer",),
        ),
    ]


def _errors_figure(frame: pd.DataFrame) -> Figure:
    fig, axes = plots.figure(1, 2, width=6.0, height=3.6)
    laws = list(dict.fromkeys(frame["law"]))
    panels = (
        ("momentum", "change of a conserved momentum (relative)"),
        ("energy", "energy created max(dT, 0) / T-"),
    )
    for ax, (column, name) in zip(axes[0], panels, strict=True):
        for k, law in enumerate(laws):
            values = frame.loc[frame["law"] == law, column].to_numpy(dtype=float)
            values = values[np.isfinite(values)]
            if column == "energy":
                values = np.maximum(values, 0.0)
            spread = np.linspace(-0.25, 0.25, len(values)) if len(values) > 1 else [0.0]
            style = plots.law_style(law)
            ax.plot(
                k + np.asarray(spread)[: len(values)],
                plots.floored(values),
                style["marker"],
                color=style["color"],
                alpha=0.6,
                linestyle="none",
            )
        ax.set_xticks(range(len(laws)), laws, rotation=45, ha="right")
        plots.log_scale(ax, "y")
        ax.set(ylabel=f"{name}, dimensionless")
        ax.set_ylim(bottom=plots.FLOOR / 10)
    data = frame[["law", "row", "value", "momentum", "energy", "verdict"]]
    return Figure(
        "stability_errors",
        "Momentum and energy checks' values of every answered cell of the stability grid, per "
        f"law (zeros, and energy kept or lost, drawn at {plots.FLOOR:g}); their verdicts are "
        "in the grids below.",
        fig,
        data.reset_index(drop=True),
    )


def _law_figure(law: str, part: pd.DataFrame) -> Figure:
    labels = list(dict.fromkeys(part["row"]))
    width = max(int(part.groupby("row").size().max()), 1)
    image = np.ones((len(labels), width, 3))
    fig, axes = plots.figure(1, 1, width=0.9 * width + 5.0, height=0.32 * len(labels) + 1.2)
    ax = axes[0, 0]
    for r, row_label in enumerate(labels):
        for c, cell in enumerate(part[part["row"] == row_label].itertuples()):
            image[r, c] = to_rgb(COLOURS[Verdict(cell.verdict)])
            ax.text(c, r, f"{cell.value:g}", ha="center", va="center", fontsize=6.5)
    ax.imshow(image, aspect="auto", interpolation="nearest")
    ax.set_yticks(range(len(labels)), labels, fontsize=7)
    ax.set_xticks([])
    present = [v for v in Verdict if str(v) in set(part["verdict"])]
    ax.legend(
        handles=[Patch(color=COLOURS[v], label=str(v)) for v in present],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize="x-small",
    )
    ax.set_title(f"{law}: verdict per cell (the number is the value swept, unit in the row)")
    return Figure(
        f"stability_{law}",
        f"Stability grid of `{law}`: one row per extreme and scene (with the other values "
        "swept), one cell per value; colour: the verdict.",
        fig,
        part.drop(columns=["row"]),
    )
