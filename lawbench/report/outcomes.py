"""Section 2, outcomes side by side: post-impact velocities and energy change per scene.

Per scene, at its default parameters (the runs of the summary matrix): each law's post-impact
velocities, kinetic energy change and relative change, beside the scene's references (case
``references``) whose condition holds there; a law's error against each reference that
describes it (``Reference.applies``) is given relative to the largest pre-impact velocity.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from lawbench.case import Case, Reference
from lawbench.mechanics import kinetic_energy
from lawbench.report import plots
from lawbench.report.page import Figure, Section, Table, number
from lawbench.report.runs import Context, array, error_text
from lawbench.report.summary import default_batch, default_example, default_records

ANCHOR, TITLE = "outcomes", "Outcomes side by side"
LINE_STYLES = ("-", "--", ":", "-.")


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's runs (shared with the summary); the returned function builds it."""
    default_batch(ctx)
    return lambda: _build(ctx)


def _build(ctx: Context) -> Section:
    records = default_records(ctx)
    blocks: list[Any] = [
        "Each scene at its default parameters (`lawbench describe CASE` lists them): the "
        "post-impact velocities of every law that can treat it, its kinetic energy change "
        "dT = T+ - T- (J) and dT / T-, beside the analytic or published references of the "
        "scene that hold at these parameters. 'error' is the largest difference from a "
        "reference that describes the law (same law and options), over the largest "
        "pre-impact velocity."
    ]
    for case in ctx.cases:
        try:
            blocks += _scene(ctx, case, records)
        except Exception as exc:  # a scene that cannot be built keeps its place, with why
            blocks.append(f"Scene `{case.name}`: not shown ({type(exc).__name__}: {exc}).")
    return Section(ANCHOR, TITLE, blocks)


def _holds(reference: Reference, params: dict[str, Any]) -> bool:
    return not any(params.get("gaps", ())) and reference.condition(params) is None


def _scene(ctx: Context, case: Case, records: dict) -> list[Any]:
    example, given = default_example(case)
    params = case.parameters(**given)
    problem = case.build(**params)
    coordinates = case.coordinates(params)
    scale = float(np.abs(problem.v).max())
    T_minus = kinetic_energy(problem.M, problem.v)
    references = [(r, np.asarray(r.v_plus(params), float)) for r in case.references]
    references = [(r, v) for r, v in references if _holds(r, params)]
    rows = [_row("before the impact (v-)", problem.v, 0.0, T_minus, scale, coordinates)]
    data = _tidy("before the impact", "v-", coordinates, problem.v)
    for law in ctx.laws:
        record = records.get((law.name, case.name))
        if record is None:
            continue
        v_plus = array(record, "v_plus")
        if v_plus is None:
            rows.append({"": law.name, "note": error_text(record)})
            continue
        options = law.option_values(json.loads(record["options"]))
        errors = [
            f"{ref.name}: {np.abs(v_plus - v).max() / scale:.2g}"
            for ref, v in references
            if ref.applies(law.name, options, params) is None
        ]
        dT = kinetic_energy(problem.M, v_plus) - T_minus
        row = _row(law.name, v_plus, dT, T_minus, scale, coordinates)
        rows.append({**row, "error": "; ".join(errors), "note": record.get("formulation", "")})
        data = pd.concat([data, _tidy(law.name, "law", coordinates, v_plus)])
    for ref, v in references:
        label = f"reference {ref.name} ({ref.law})"
        dT = kinetic_energy(problem.M, v) - T_minus
        rows.append({**_row(label, v, dT, T_minus, scale, coordinates), "note": ref.source})
        data = pd.concat([data, _tidy(label, "reference", coordinates, v)])
    frame = pd.DataFrame(rows).reindex(
        columns=["", *coordinates, "dT [J]", "dT / T-", "error", "note"]
    )
    name = f"outcomes_{case.name}"
    what = f"`{case.name}` at its default parameters (example '{example}')"
    return [
        f"`{case.name}`: {case.summary}.",
        Table(name, f"Post-impact velocities on {what}.", frame),
        Figure(
            f"{name}_figure",
            f"Post-impact velocities on {what}: bars per law, the references that hold there "
            "as black lines (one style each), the pre-impact velocities in grey.",
            _figure(data, coordinates, case.name),
            data.reset_index(drop=True),
        ),
    ]


def _row(label: str, v: np.ndarray, dT: float, T: float, scale: float, names: list) -> dict:
    row: dict[str, Any] = {"": label}
    row.update({name: number(x, scale) for name, x in zip(names, v, strict=True)})
    row["dT [J]"] = number(dT, T)
    row["dT / T-"] = number(dT / T if T > 0 else 0.0, 1.0)
    return row


def _tidy(source: str, kind: str, coordinates: list[str], values: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame(
        {"source": source, "kind": kind, "coordinate": coordinates, "value": values}
    )


def _figure(data: pd.DataFrame, coordinates: list[str], case: str) -> Any:
    fig, axes = plots.figure(1, 1, width=max(6.0, 1.1 * len(coordinates) + 3.0), height=3.6)
    ax = axes[0, 0]
    laws = list(dict.fromkeys(data.loc[data["kind"] == "law", "source"]))
    x = np.arange(len(coordinates))
    width = 0.8 / max(len(laws), 1)
    before = data[data["kind"] == "v-"]["value"].to_numpy()
    ax.bar(x, before, 0.9, color="0.85", label="v-", zorder=0)
    for k, law in enumerate(laws):
        values = data[data["source"] == law]["value"].to_numpy()
        style = plots.law_style(law)
        offset = (k - (len(laws) - 1) / 2) * width
        ax.bar(x + offset, values, width, color=style["color"], label=law)
    sources = dict.fromkeys(data.loc[data["kind"] == "reference", "source"])
    for k, source in enumerate(sources):
        style = LINE_STYLES[k % len(LINE_STYLES)]
        values = data[data["source"] == source]["value"].to_numpy()
        ax.hlines(values, x - 0.45, x + 0.45, colors="k", linewidth=1.5, linestyles=style)
        ax.plot([], [], color="k", linestyle=style, label=source)
    ax.axhline(0.0, color="0.5", linewidth=0.5)
    ax.set_xticks(x, coordinates, rotation=30 if len(coordinates) > 4 else 0)
    ax.set_title(case)
    ax.set_ylabel("velocity after the impact")
    ax.legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return fig
