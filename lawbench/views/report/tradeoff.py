"""Section 3, speed versus accuracy: two errors against cost, never mixed in one column.

A view of the studies declared with `lawbench.checks.declared.speed_accuracy`: per scene, at its
default parameters, every law that can treat it solved at each value of its accuracy knob
(``Tags.accuracy_knob``), a few times. Cost is the median of the law's own wall time over the
repeats. Two measures, drawn on two panels:

- *model error*: distance from the scene's ground truth (``Case.ground_truth``, named in every
  caption and header), ``max |v+ - v_truth| / max |v-|``;
- *numerical error*: distance, the same way, from the law's own answer at its tightest knob
  (0 for an exact law; none for a knob that chooses an ordering, not an accuracy).

The Pareto front (no point both cheaper and closer to the ground truth) is marked, and a table
gives, per scene, the cheapest law whose model error reaches each level.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import Case
from lawbench.views.report import plots
from lawbench.views.report.page import Figure, Section, Table
from lawbench.views.report.runs import Context, parsed
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "tradeoff", "Speed versus accuracy", ("tradeoff",)
LEVELS = (1e-2, 1e-4, 1e-6)
MEASURES = {
    "model_error": "model error (vs the ground truth, relative)",
    "numerical_error": "numerical error (vs its tightest knob, relative)",
}


def pareto(cost: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Mask of the points no other point beats in both cost and error."""
    front = np.zeros(len(cost), dtype=bool)
    for i in range(len(cost)):
        better = (cost <= cost[i]) & (error <= error[i]) & ((cost < cost[i]) | (error < error[i]))
        front[i] = not better.any()
    return front


def points(ctx: Context, table: pd.DataFrame) -> pd.DataFrame:
    """One row per law and knob value: median cost over the repeats, both errors, verdict."""
    rows = []
    table = table.fillna({"error_class": ""})
    for (law, options), group in table.groupby(["law", "options"], sort=False):
        knob = ctx.law(law).tags.accuracy_knob
        value = json.loads(options).get(knob) if knob else None
        first = group.iloc[0].to_dict()
        answered = group[group["error_class"] == ""]
        row = {"law": law, "knob": knob or "", "value": value, "verdict": first["verdict"]}
        if answered.empty:
            rows.append({**row, "failure": failure(first)})
            continue
        rows.append(
            {
                **row,
                "wall_time_s": float(answered["wall_time_s"].median()),
                "steps": int(first["steps"]),
                **{m: parsed(first.get(m)) for m in MEASURES},
                "failure": "",
                "reproducer": first["reproducer"],
            }
        )
    columns = ["law", "knob", "value", "wall_time_s", "steps", *MEASURES, "verdict", "failure"]
    return pd.DataFrame(rows).reindex(columns=[*columns, "reproducer"])


def build(ctx: Context) -> Section:
    """The section, from every speed/accuracy study that ran."""
    blocks: list[Any] = [
        "Cost and the two errors of every law on each scene, sweeping its accuracy knob "
        "(named in `lawbench describe LAW`): model error is the distance from the scene's "
        "ground truth, numerical error the distance from the law's own answer at its tightest "
        "knob. Both are max |v+ - v_ref| / max |v-|, dimensionless."
    ]
    cheapest: dict[str, list[str]] = {}
    for study, table in ctx.tables("tradeoff"):
        case = ctx.case(study.cases[0])
        data = points(ctx, table)
        blocks += _scene_blocks(case, data, study.repeats)
        cheapest[_header(case)] = [_cheapest(data, level) for level in LEVELS]
    if cheapest:
        frame = pd.DataFrame(cheapest)
        frame.insert(0, "model error", [f"<= {level:g}" for level in LEVELS])
        blocks.append(
            Table(
                "tradeoff_cheapest",
                "The cheapest law (by median wall time) whose model error, the distance from "
                "the scene's ground truth named in the header, is at most each level; 'none' "
                "when no point of the sweep reaches it.",
                frame,
            )
        )
    return Section(ANCHOR, TITLE, blocks)


def _header(case: Case) -> str:
    truth = case.ground_truth
    return f"{case.name} (vs {truth.describe()})" if truth else f"{case.name} (no ground truth)"


def _scene_blocks(case: Case, data: pd.DataFrame, repeats: int) -> list[Any]:
    data = data.copy()
    measured = data[data["failure"] == ""]
    fig, axes = plots.figure(1, 2, width=5.0, height=3.8)
    for ax, (measure, label) in zip(axes[0], MEASURES.items(), strict=True):
        known = measured[measured[measure].notna()]
        for law, group in known.groupby("law", sort=False):
            floored = plots.floored(group[measure].astype(float))
            ax.plot(group["wall_time_s"], floored, linestyle="-", **plots.law_style(law))
        ax.set(xscale="log", yscale="log", xlabel="median wall time [s]", ylabel=label)
        ax.set_ylim(bottom=plots.FLOOR / 10)
    data["pareto"] = False
    known = measured[measured["model_error"].notna()]
    if len(known):
        errors = plots.floored(known["model_error"].astype(float))
        front = pareto(known["wall_time_s"].to_numpy(), errors)
        data.loc[known.index, "pareto"] = front
        shown = known[front].sort_values("wall_time_s")
        floored = plots.floored(shown["model_error"].astype(float))
        ax = axes[0, 0]
        ax.step(shown["wall_time_s"], floored, "k--", where="post", linewidth=0.8)
        ax.plot(shown["wall_time_s"], floored, "ko", fillstyle="none", markersize=11)
        ax.plot([], [], "ko", fillstyle="none", label="Pareto front")
    axes[0, 0].legend(fontsize="x-small")
    fig.suptitle(case.name)
    truth = case.ground_truth
    named = f"{truth.describe()}: {truth.why}" if truth else "none declared"
    caption = (
        f"`{case.name}` at its default parameters, each law's accuracy knob swept. Left: model "
        f"error against the ground truth, {named}. Right: numerical error against the law's "
        f"own answer at its tightest knob. Cost: median of {repeats} solves; an error of 0 "
        f"(the ground truth itself, an exact law against itself) drawn at {plots.FLOOR:g}; "
        "black circles: the Pareto front of model error and cost."
    )
    failed = data[data["failure"] != ""]
    notes = dict.fromkeys(
        f"`{r.law}` ({r.knob}={r.value}) gave no answer on `{case.name}`: {r.failure}."
        for r in failed.itertuples()
    )
    return [Figure(f"tradeoff_{case.name}", caption, fig, data), *notes]


def _cheapest(data: pd.DataFrame, level: float) -> str:
    known = data[(data["failure"] == "") & data["model_error"].notna()]
    reached = known[known["model_error"].astype(float) <= level].sort_values("wall_time_s")
    if reached.empty:
        return "none"
    best = reached.iloc[0]
    knob = f" ({best['knob']}={best['value']})" if best["knob"] else ""
    return f"{best['law']}{knob}, {best['wall_time_s']:.2g} s"
