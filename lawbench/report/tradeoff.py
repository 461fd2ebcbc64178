"""Section 3, speed versus accuracy: error against a high-fidelity reference versus cost.

Per scene, at its default parameters, every law that can treat it is solved at each value of
its accuracy knob (``capabilities.accuracy_knob``): a numeric knob over the configured values
its spec accepts, a choice over its choices; an exact law is one point. Cost is the median of
the law's own wall time (``diagnostics['wall_time_s']``) over the repeats, and its steps or
iterations as the runner records them. Error is the largest velocity difference from the
reference over the largest pre-impact velocity. The reference is the compliant model at its
tightest tolerance when it can treat the scene (one reference for every law); otherwise each
law's own answer at its tightest knob (an exact law then has error 0, drawn at the floor).
The Pareto front (no point both cheaper and more accurate) is marked, and a table gives the
cheapest law that reaches each error threshold.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from lawbench.case import Case
from lawbench.errors import InvalidProblem
from lawbench.law import Law
from lawbench.report import plots
from lawbench.report.page import Figure, Section, Table
from lawbench.report.runs import Context, Job, array, error_text
from lawbench.report.summary import default_example

ANCHOR, TITLE = "tradeoff", "Speed versus accuracy"
THRESHOLDS = (1e-2, 1e-4, 1e-6)
REFERENCE_LAW = "compliant"
INT_KNOBS = (10, 100, 1_000, 10_000, 100_000)


def _accepts(spec: Any, value: Any) -> bool:
    try:
        spec.coerce(value)
    except InvalidProblem:
        return False
    return True


def knob_values(law: Law, values: tuple[float, ...]) -> tuple[str | None, list[Any]]:
    """The knob's name and the values swept (``[None]``: one point at the defaults)."""
    knob = law.tags.accuracy_knob
    spec = next((s for s in law.options if s.name == knob), None)
    if spec is None:
        return None, [None]
    if spec.choices:
        return knob, list(spec.choices)
    if spec.kind == "bool":
        return knob, [False, True]
    candidates = INT_KNOBS if spec.kind == "int" else values
    return knob, [v for v in candidates if _accepts(spec, v)] or [spec.default]


def tightest(law: Law, reference: float) -> dict[str, Any]:
    """Options at the law's tightest knob: ``reference`` or the nearest value accepted."""
    knob, _ = knob_values(law, ())
    spec = next((s for s in law.options if s.name == knob), None)
    if spec is None or spec.choices or spec.kind == "bool":
        return {}
    if spec.kind == "int":
        return {knob: max(v for v in (*INT_KNOBS, spec.default) if _accepts(spec, v))}
    accepted = [reference * 10.0**k for k in range(12) if _accepts(spec, reference * 10.0**k)]
    return {knob: accepted[0]} if accepted else {}


def _scenes(ctx: Context) -> tuple[list[Case], list[str]]:
    wanted = ctx.config.tradeoff_cases
    if wanted is None:
        return list(ctx.cases), []
    found = [ctx.case(name) for name in wanted]
    missing = [
        f"scene `{n}` is not registered" for n, c in zip(wanted, found, strict=True) if not c
    ]
    return [c for c in found if c], missing


def _plan(ctx: Context) -> tuple[list[Job], list[Job], list[dict[str, Any]]]:
    """Reference jobs, sweep jobs, and what each sweep job stands for."""
    references, sweep, points = [], [], []
    compliant = ctx.law(REFERENCE_LAW)
    for case in _scenes(ctx)[0]:
        params = default_example(case)[1]
        tight = ctx.config.reference_knob
        shared = compliant is not None and compliant.tags.covers(case.requires)
        if shared:
            references.append(Job(REFERENCE_LAW, case.name, params, tightest(compliant, tight)))
        for law in ctx.laws:
            if not law.tags.covers(case.requires):
                continue
            if not shared:
                references.append(Job(law.name, case.name, params, tightest(law, tight)))
            knob, values = knob_values(law, ctx.config.knob_values)
            for value in values:
                options = {} if value is None else {knob: value}
                sweep.append(Job(law.name, case.name, params, options))
                points.append({"case": case.name, "law": law.name, "knob": knob, "value": value})
    return references, sweep, points


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's runs; the returned function builds it."""
    references, sweep, points = _plan(ctx)
    reference_batch = ctx.batch("tradeoff-reference", references)
    sweep_batch = ctx.batch("tradeoff", sweep, repeats=ctx.config.repeats)
    return lambda: _build(ctx, reference_batch.records(), sweep_batch.records(), points)


def _build(ctx: Context, references: list, sweep: list, points: list) -> Section:
    scenes, missing = _scenes(ctx)
    repeats = ctx.config.repeats
    reference_by = {(r["law"], r["case"]): r for r in references}
    rows = []
    for k, point in enumerate(points):
        records = sweep[k * repeats : (k + 1) * repeats]
        try:
            rows.append({**point, **_measure(ctx, point, records, reference_by)})
        except Exception as exc:  # a point the report cannot measure keeps its row
            rows.append({**point, "failure": f"{type(exc).__name__}: {exc}"})
    table = pd.DataFrame(
        rows,
        columns=[
            "case",
            "law",
            "knob",
            "value",
            "reference",
            "error",
            "wall_time_s",
            "steps",
            "failure",
        ],
    )
    blocks: list[Any] = [
        "Cost and error of every law on each scene, sweeping its accuracy knob (named in "
        "`lawbench describe LAW`). " + " ".join(f"Note: {m}." for m in missing)
    ]
    cheapest = []
    for case in scenes:
        part = table[table["case"] == case.name]
        if part.empty:
            blocks.append(f"`{case.name}`: no law can treat it.")
            continue
        blocks += _scene_blocks(ctx, case, part, repeats)
        cheapest.append(_cheapest(case.name, part))
    blocks.append(
        Table(
            "tradeoff_cheapest",
            "The cheapest law (by median wall time) whose error reaches each threshold, per "
            "scene; 'none' when no point of the sweep reaches it.",
            pd.DataFrame(cheapest),
        )
    )
    return Section(ANCHOR, TITLE, blocks)


def _measure(ctx: Context, point: dict, records: list, reference_by: dict) -> dict[str, Any]:
    answers = [r for r in records if not r.get("error_class")]
    if not answers:
        return {"failure": error_text(records[0])}
    case = ctx.case(point["case"])
    v_minus = case.build(**default_example(case)[1]).v
    shared = reference_by.get((REFERENCE_LAW, point["case"]))
    if shared is not None:
        reference, label = shared, f"compliant at {_options(shared)}"
    else:
        reference = reference_by.get((point["law"], point["case"]))
        knob = _options(reference)
        label = f"own answer at {knob}" if knob else "own answer (exact law: itself)"
    v_reference = None if reference is None else array(reference, "v_plus")
    if v_reference is None:
        why = error_text(reference) if reference else "no reference job"
        label, error = f"none ({why})", np.nan
    else:
        v_plus = array(answers[0], "v_plus")
        error = float(np.abs(v_plus - v_reference).max() / np.abs(v_minus).max())
    return {
        "reference": label,
        "error": error,
        "wall_time_s": float(np.median([r["wall_time_s"] for r in answers])),
        "steps": int(answers[0].get("steps") or 0),
        "failure": "",
    }


def _options(record: dict | None) -> str:
    if record is None:
        return ""
    return record["options"].strip("{}").replace('"', "").replace(": ", "=")


def pareto(cost: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Mask of the points no other point beats in both cost and error."""
    front = np.zeros(len(cost), dtype=bool)
    for i in range(len(cost)):
        better = (cost <= cost[i]) & (error <= error[i]) & ((cost < cost[i]) | (error < error[i]))
        front[i] = not better.any()
    return front


def _scene_blocks(ctx: Context, case: Case, part: pd.DataFrame, repeats: int) -> list[Any]:
    data = part.copy()
    data["error_floored"] = plots.floored(data["error"])
    data["pareto"] = False
    measured = data[(data["failure"] == "") & data["error"].notna()]
    if len(measured):
        front = pareto(measured["wall_time_s"].to_numpy(), measured["error_floored"].to_numpy())
        data.loc[measured.index, "pareto"] = front
    fig, axes = plots.figure(1, 2, width=5.0, height=3.8)
    for ax, cost, label in (
        (axes[0, 0], "wall_time_s", "median wall time [s]"),
        (axes[0, 1], "steps", "steps or iterations (0 drawn at 1)"),
    ):
        for law, group in data.loc[measured.index].groupby("law", sort=False):
            x = group[cost].to_numpy(dtype=float)
            x = np.maximum(x, 1.0) if cost == "steps" else x
            ax.plot(x, group["error_floored"], linestyle="-", **plots.law_style(law))
        ax.set(xscale="log", yscale="log", xlabel=label, ylabel="error (relative)")
    front = data[data["pareto"]].sort_values("wall_time_s")
    if len(front):
        ax = axes[0, 0]
        ax.step(front["wall_time_s"], front["error_floored"], "k--", where="post", linewidth=0.8)
        ax.plot(
            front["wall_time_s"],
            front["error_floored"],
            "ko",
            fillstyle="none",
            markersize=11,
            label="Pareto front",
        )
    axes[0, 0].legend(fontsize="x-small")
    fig.suptitle(case.name)
    shared = next((r for r in measured["reference"] if r.startswith("compliant")), None)
    reference = (
        f"{shared}, for every law"
        if shared
        else "each law's own answer at its tightest knob (the compliant model cannot treat "
        "the scene), so the error is the law's convergence, not agreement between laws"
    )
    caption = (
        f"Error versus cost on `{case.name}` at its default parameters, each law's accuracy "
        f"knob swept; reference: {reference}; cost: median of "
        f"{repeats} solves; error 0 (the reference itself, or an exact law against itself) "
        f"drawn at {plots.FLOOR:g}; black circles: the Pareto front."
    )
    failures = data[data["failure"] != ""]
    notes = [f"`{r.law}` failed on `{case.name}`: {r.failure}." for r in failures.itertuples()]
    return [Figure(f"tradeoff_{case.name}", caption, fig, data), *notes]


def _cheapest(case: str, part: pd.DataFrame) -> dict[str, str]:
    row = {"case": case}
    ok = part[(part["failure"] == "") & part["error"].notna()]
    for threshold in THRESHOLDS:
        reached = ok[ok["error"] <= threshold].sort_values("wall_time_s")
        if reached.empty:
            row[f"error <= {threshold:g}"] = "none"
            continue
        best = reached.iloc[0]
        knob = "" if best["value"] is None else f" ({best['knob']}={best['value']})"
        row[f"error <= {threshold:g}"] = f"{best['law']}{knob}, {best['wall_time_s']:.2g} s"
    return row
