"""Section 2, outcomes side by side: post-impact velocities and energy change per scene.

A view of the ``summary`` study: per scene, at its default parameters, each law's post-impact
velocities, kinetic energy change and its *model error* (distance from the scene's ground
truth, `lawbench.checks.measures.model_error`), beside the ground truth itself (once: the row of
its own model at its defaults, when it gives the same, is the truth's) and the scene's
references (case ``references``) whose condition holds there; the error against a reference
that describes the law (``Reference.applies``) is given too. Velocities of different units are
drawn on different axes.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import Case, Reference
from lawbench.core.metric import kinetic_energy
from lawbench.views.report import plots
from lawbench.views.report.page import Figure, Section, Table, number
from lawbench.views.report.runs import Context, parsed, vector
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "outcomes", "Outcomes side by side", ("summary",)
LINE_STYLES = ("-", "--", ":", "-.")
# The ground truth's model at its default options is the truth when it agrees to this share of
# the largest pre-impact velocity (below the tables' four digits): it is shown once, as the truth.
SAME = 1e-5


def build(ctx: Context) -> Section:
    """The section, from the ``summary`` study's table."""
    tables = ctx.tables("summary")
    blocks: list[Any] = [
        "Each scene at its default parameters (`lawbench describe CASE` lists them): the "
        "post-impact velocities of every law that answers, its kinetic energy change "
        "dT = T+ - T- (J) and dT / T-, and its model error: the largest difference from the "
        "scene's ground truth over the largest pre-impact velocity. Beside them the ground "
        "truth and the analytic or published references of the scene that hold at these "
        "parameters; 'vs reference' is the same distance from a reference that describes the "
        "law (same law and options)."
    ]
    if not tables:
        return Section(ANCHOR, TITLE, [*blocks, "No summary study ran."])
    table = tables[0][1].fillna({"error_class": ""})
    for case in ctx.cases:
        rows = table[table["case"] == case.name].to_dict("records")
        try:
            blocks += _scene(case, rows)
        except Exception as exc:  # a scene that cannot be built keeps its place, with why
            blocks.append(f"Scene `{case.name}`: not shown ({type(exc).__name__}: {exc}).")
    return Section(ANCHOR, TITLE, blocks)


def _holds(reference: Reference, params: dict[str, Any]) -> bool:
    return not any(params.get("gaps", ())) and reference.condition(params) is None


def _scene(case: Case, records: list[dict[str, Any]]) -> list[Any]:
    params = case.parameters()
    problem = case.build(**params)
    coordinates = case.coordinates(params)
    scale = float(np.abs(problem.v).max())
    T_minus = kinetic_energy(problem.M, problem.v)
    references = [(r, np.asarray(r.v_plus(params), float)) for r in case.references]
    references = [(r, v) for r, v in references if _holds(r, params)]
    rows = [_row("before the impact (v-)", problem.v, T_minus, T_minus, scale, coordinates)]
    data = _tidy("before the impact", "v-", coordinates, problem.v)
    ground = case.ground_truth
    truths = (parsed(record.get("truth_velocity")) for record in records)
    truth = next((v for v in truths if v is not None), None) if ground is not None else None
    same: list[str] = []
    for record in records:
        law = record["law"]
        v_plus = vector(record["v_plus"])
        if v_plus is None:
            if record["verdict"] != "refused":
                rows.append({"": law, "note": failure(record)})
            continue
        if _is_truth(law, v_plus, ground, truth, scale):
            same.append(law)  # the ground truth's own model: its row is the truth's
            continue
        options = json.loads(record["options"])
        errors = [
            f"{ref.name}: {np.abs(v_plus - v).max() / scale:.2g}"
            for ref, v in references
            if ref.applies(law, options, params) is None
        ]
        row = _row(law, v_plus, kinetic_energy(problem.M, v_plus), T_minus, scale, coordinates)
        model = parsed(record.get("model_error"))
        row["model error"] = "" if model is None else f"{model:.2g}"
        rows.append({**row, "vs reference": "; ".join(errors), "note": record["formulation"]})
        data = pd.concat([data, _tidy(law, "law", coordinates, v_plus)])
    if truth is not None:
        label = f"ground truth: {ground.describe()}"
        v = np.asarray(truth, dtype=float)
        row = _row(label, v, kinetic_energy(problem.M, v), T_minus, scale, coordinates)
        at_defaults = f" (`{same[0]}` at its default options gives the same)" if same else ""
        rows.append({**row, "note": ground.why + at_defaults})
        data = pd.concat([data, _tidy(label, "reference", coordinates, v)])
    for ref, v in references:
        label = f"reference {ref.name} ({ref.law})"
        row = _row(label, v, kinetic_energy(problem.M, v), T_minus, scale, coordinates)
        rows.append({**row, "note": ref.source})
        data = pd.concat([data, _tidy(label, "reference", coordinates, v)])
    columns = ["", *coordinates, "dT [J]", "dT / T-", "model error", "vs reference", "note"]
    frame = pd.DataFrame(rows).reindex(columns=columns)
    name = f"outcomes_{case.name}"
    what = f"`{case.name}` at its default parameters"
    return [
        f"`{case.name}`: {case.summary}.",
        Table(name, f"Post-impact velocities on {what}.", frame),
        Figure(
            f"{name}_figure",
            f"Post-impact velocities on {what}, one panel per unit: bars per law, the ground "
            "truth and the references that hold there as black lines (one style each), the "
            "pre-impact velocities in grey.",
            _figure(data, coordinates, case.name),
            data.reset_index(drop=True),
        ),
    ]


def _is_truth(law: str, v_plus: np.ndarray, ground: Any, truth: Any, scale: float) -> bool:
    """Whether ``law``'s answer is the ground truth's: its model, the same to the table's digits."""
    if truth is None or law != ground.law:
        return False
    return bool(np.abs(v_plus - np.asarray(truth, dtype=float)).max() <= SAME * scale)


def _row(label: str, v: np.ndarray, T: float, T_minus: float, scale: float, names: list) -> dict:
    dT = T - T_minus
    row: dict[str, Any] = {"": label}
    row.update({name: number(x, scale) for name, x in zip(names, v, strict=True)})
    row["dT [J]"] = number(dT, T_minus)
    row["dT / T-"] = number(dT / T_minus if T_minus > 0 else 0.0, 1.0)
    return row


def _tidy(source: str, kind: str, coordinates: list[str], values: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame(
        {"source": source, "kind": kind, "coordinate": coordinates, "value": values}
    )


def _figure(data: pd.DataFrame, coordinates: list[str], case: str) -> Any:
    groups = plots.by_unit(coordinates)
    widths = [max(4.0, 1.2 * len(k) + 2.0) for k in groups.values()]
    fig, axes = plots.figure(1, len(groups), width=max(widths), height=3.6)
    laws = list(dict.fromkeys(data.loc[data["kind"] == "law", "source"]))
    sources = list(dict.fromkeys(data.loc[data["kind"] == "reference", "source"]))
    width = 0.8 / max(len(laws), 1)
    for ax, (unit, indices) in zip(axes[0], groups.items(), strict=True):
        names = [coordinates[k] for k in indices]
        x = np.arange(len(names))

        def values(source: str, names: list[str] = names) -> np.ndarray:
            part = data[data["source"] == source].set_index("coordinate")["value"]
            return part.reindex(names).to_numpy()

        ax.bar(x, values("before the impact"), 0.9, color="0.85", label="v-", zorder=0)
        for k, law in enumerate(laws):
            offset = (k - (len(laws) - 1) / 2) * width
            ax.bar(x + offset, values(law), width, color=plots.law_style(law)["color"], label=law)
        for k, source in enumerate(sources):
            style = LINE_STYLES[k % len(LINE_STYLES)]
            ax.hlines(values(source), x - 0.45, x + 0.45, colors="k", linestyles=style)
            ax.plot([], [], color="k", linestyle=style, label=source)
        ax.axhline(0.0, color="0.5", linewidth=0.5)
        ax.set_xticks(x, names, rotation=30 if len(names) > 3 else 0)
        ax.set_ylabel(f"velocity [{unit or 'as named'}]")
    axes[0, 0].set_title(case)
    return fig  # its legend, every law and reference, goes below the panels when drawn
