"""Section 3, speed versus accuracy: two errors against cost, never mixed in one column.

A view of the studies declared with `lawbench.studies.declared.speed_accuracy`: per scene, at its
default parameters, every law that can treat it solved at each value of its accuracy knob
(``Tags.accuracy_knob``), a few times. Cost is the median of the law's own wall time over the
repeats. Two measures, drawn on two panels:

- *model error*: distance from the scene's ground truth (``Case.ground_truth``, named in every
  caption and header), ``max |v+ - v_truth| / max |v-|``;
- *numerical error*: distance, the same way, from the law's own answer at its tightest knob
  (0 for an exact law; none for a knob that chooses an ordering, not an accuracy).

The ground truth's own model is the reference and never a candidate. Over the laws under test
whose cells hold (verdict holds or law property) the Pareto front (no point both cheaper and
closer to the ground truth) is marked. Which law to use at what cost is the page's first table
(`lawbench.views.report.answer`), read off the same points.
"""

from __future__ import annotations

import json
import weakref
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import Case
from lawbench.views.report import plots
from lawbench.views.report.answer import candidates
from lawbench.views.report.page import Figure, Section
from lawbench.views.report.runs import Context, parsed
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "tradeoff", "Speed versus accuracy", ("tradeoff",)
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
        row = {
            "law": law,
            "knob": knob or "",
            "value": value,
            "verdict": first["verdict"],
            "options": options,
            "params": first["params"],
            "reproducer": first["reproducer"],
        }
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
            }
        )
    columns = ["law", "knob", "value", "wall_time_s", "steps", *MEASURES, "verdict", "failure"]
    return pd.DataFrame(rows).reindex(columns=[*columns, "options", "params", "reproducer"])


_SCENES: weakref.WeakKeyDictionary[Context, list[tuple[Case, pd.DataFrame, int]]] = (
    weakref.WeakKeyDictionary()
)


def scenes(ctx: Context) -> list[tuple[Case, pd.DataFrame, int]]:
    """Per speed/accuracy study that ran: its scene, its points and its repeats.

    The points have a ``candidate`` column: False for the ground truth's own model.
    """
    if ctx not in _SCENES:
        found = []
        for study, table in ctx.tables("tradeoff"):
            case = ctx.case(study.cases[0])
            data = points(ctx, table)
            truth = case.ground_truth
            data["candidate"] = data["law"] != (truth.law if truth else None)
            found.append((case, data, study.repeats))
        _SCENES[ctx] = found
    return _SCENES[ctx]


def build(ctx: Context) -> Section:
    """The section, from every speed/accuracy study that ran."""
    blocks: list[Any] = [
        "Cost and the two errors of every law on each scene, sweeping its accuracy knob "
        "(named in `lawbench describe LAW`): model error is the distance from the scene's "
        "ground truth, numerical error the distance from the law's own answer at its tightest "
        "knob. Both are max |v+ - v_ref| / max |v-|, dimensionless."
    ]
    for case, data, repeats in scenes(ctx):
        blocks += _scene_blocks(case, data, repeats)
    return Section(ANCHOR, TITLE, blocks)


def _scene_blocks(case: Case, data: pd.DataFrame, repeats: int) -> list[Any]:
    data = data.copy()
    measured = data[data["failure"] == ""]
    fig, axes = plots.figure(1, 2, width=5.0, height=3.8)
    for ax, (measure, label) in zip(axes[0], MEASURES.items(), strict=True):
        # The ground truth's model is drawn against its own tightest answer only.
        shown = measured if measure == "numerical_error" else measured[measured["candidate"]]
        known = shown[shown[measure].notna()]
        for law, group in known.groupby("law", sort=False):
            floored = plots.floored(group[measure].astype(float))
            ax.plot(group["wall_time_s"], floored, linestyle="-", **plots.law_style(law))
        plots.log_scale(ax, "xy")
        ax.set(xlabel="median wall time [s]", ylabel=label)
        ax.set_ylim(bottom=plots.FLOOR / 10)
    data["pareto"] = False
    known = candidates(data)
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
    fig.suptitle(case.name)
    truth = case.ground_truth
    named = f"{truth.describe()}: {truth.why}" if truth else "none declared"
    cost = "one solve" if repeats == 1 else f"median of {repeats} solves"
    caption = (
        f"`{case.name}` at its default parameters, each law's accuracy knob swept. Left: model "
        f"error against the ground truth, {named}. Right: numerical error against the law's "
        f"own answer at its tightest knob. The ground truth's model is drawn on the right "
        f"only: it is the reference, never a candidate. Cost: {cost}; an "
        f"error of 0 (an exact law against itself) drawn at {plots.FLOOR:g}; black circles: "
        "the Pareto front of model error and cost over the cells of the laws under test that hold."
    )
    failed = data[data["failure"] != ""]
    notes = dict.fromkeys(
        f"`{r.law}`{_setting(r.knob, r.value)} gave no answer on `{case.name}`: {r.failure}."
        for r in failed.itertuples()
    )
    return [Figure(f"tradeoff_{case.name}", caption, fig, data), *notes]


def _setting(knob: str, value: object) -> str:
    """`` (tol=1e-06)`` for a law's accuracy knob at a value; nothing for a law without one."""
    return f" ({knob}={value})" if knob and not pd.isna(value) else ""
