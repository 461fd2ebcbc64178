"""Section 3, speed versus accuracy: two errors against cost, never mixed in one column.

A view of the studies declared with `lawbench.studies.declared.speed_accuracy`: per scene, at its
default parameters, every law that can treat it solved at each value of its accuracy knob
(``Tags.accuracy_knob``), a few times. Cost is the median of the law's own wall time over the
repeats. Two measures, drawn on two panels:

- *model error*: distance from the scene's ground truth (``Case.ground_truth``, named in every
  caption and header), ``max |v+ - v_truth| / max |v-|``;
- *numerical error*: distance, the same way, from the law's own answer at its tightest knob
  (0 for an exact law; none for a knob that chooses an ordering, not an accuracy).

The ground truth's own model is the reference and never a candidate. Over the laws under test the
Pareto front (no point both cheaper and closer to the ground truth) is marked, and a table gives,
one row per scene, the cheapest law whose model error reaches each level and a sentence that says
which law to use and at what cost.
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
    rows: list[dict[str, str]] = []
    for study, table in ctx.tables("tradeoff"):
        case = ctx.case(study.cases[0])
        data = points(ctx, table)
        truth = case.ground_truth
        data["candidate"] = data["law"] != (truth.law if truth else None)
        blocks += _scene_blocks(case, data, study.repeats)
        rows.append(
            {
                "scene": case.name,
                "ground truth": truth.describe() if truth else "none",
                **{f"within {level:g}": _cheapest(data, level) for level in LEVELS},
                "answer": sentence(case, data),
            }
        )
    if rows:
        frame = pd.DataFrame(rows)
        blocks.append(
            Table(
                "tradeoff_cheapest",
                "Which law, at what cost, one row per scene: the cheapest law under test (by "
                "median wall time) whose model error, the distance from the scene's ground "
                "truth, is within each level ('none' when no point of its sweep is), and the "
                "answer in one sentence. The ground truth's own model is the reference, never "
                "a candidate.",
                frame,
            )
        )
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
    known = measured[measured["model_error"].notna() & measured["candidate"]]
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
    cost = "one solve" if repeats == 1 else f"median of {repeats} solves"
    caption = (
        f"`{case.name}` at its default parameters, each law's accuracy knob swept. Left: model "
        f"error against the ground truth, {named}. Right: numerical error against the law's "
        f"own answer at its tightest knob. The ground truth's model is drawn on the right "
        f"only: it is the reference, never a candidate. Cost: {cost}; an "
        f"error of 0 (an exact law against itself) drawn at {plots.FLOOR:g}; black circles: "
        "the Pareto front of model error and cost over the laws under test."
    )
    failed = data[data["failure"] != ""]
    notes = dict.fromkeys(
        f"`{r.law}` ({r.knob}={r.value}) gave no answer on `{case.name}`: {r.failure}."
        for r in failed.itertuples()
    )
    return [Figure(f"tradeoff_{case.name}", caption, fig, data), *notes]


def _measured(data: pd.DataFrame) -> pd.DataFrame:
    """The candidates' points that have a model error."""
    return data[data["candidate"] & (data["failure"] == "") & data["model_error"].notna()]


def _within(data: pd.DataFrame, level: float) -> pd.Series | None:
    """The cheapest candidate point whose model error is at most ``level``, or None."""
    known = _measured(data)
    reached = known[known["model_error"].astype(float) <= level].sort_values("wall_time_s")
    return None if reached.empty else reached.iloc[0]


def _cheapest(data: pd.DataFrame, level: float) -> str:
    best = _within(data, level)
    if best is None:
        return "none"
    knob = f" ({best['knob']}={best['value']})" if best["knob"] else ""
    return f"{best['law']}{knob}, {best['wall_time_s']:.2g} s"


def _duration(seconds: float) -> str:
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds / 1e-9:.3g} ns"


def sentence(case: Case, data: pd.DataFrame) -> str:
    """Which law to use on the scene, at what cost, read off its speed/accuracy points."""
    known = _measured(data)
    if known.empty:
        return f"No law under test has a model error on {case.name}."
    errors = known["model_error"].astype(float)
    closest = known.loc[errors.idxmin()]
    words = [
        f"{closest['law']} comes closest, within {float(closest['model_error']):.2g} at "
        f"{_duration(float(closest['wall_time_s']))}"
    ]
    for level in LEVELS:
        best = _within(data, level)
        if best is None:
            words.append(f"no law under test is within {level:g}")
            break
        words.append(
            f"the cheapest within {level:g} is {best['law']} at "
            f"{_duration(float(best['wall_time_s']))}"
        )
    return "; ".join(words) + "."
