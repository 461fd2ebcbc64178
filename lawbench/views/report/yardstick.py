"""The yardstick checked by an independent engine: the ground truth against a tuned engine.

A view of the studies declared with `lawbench.studies.declared.yardstick`: an engine law, tuned
as rigid and as faithful to e and mu as it allows, on every scene whose ground truth is a
converged model. One row per scene: the difference from the model in the kinetic metric (the
``yardstick`` check's value, `lawbench.checks.yardstick`) and as the largest velocity
difference over the largest pre-impact speed (the model error's measure), the verdict (within
`LEVEL`, or the engine's finding that states the physics the two model differently), and the
cost of each: the shortest of the cell's solves, the first of which may load the engine. The
studies are slow: the quick report says that the full report holds them.
"""

from __future__ import annotations

from typing import Any

import pandas as pd

from lawbench.checks.yardstick import LEVEL
from lawbench.core.verdicts import Verdict
from lawbench.studies.study import Study
from lawbench.views.report.page import Section, Table
from lawbench.views.report.runs import Context, parsed
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "yardstick", "The yardstick checked by an independent engine", ("yardstick",)


def build(ctx: Context) -> Section:
    """The section, from every yardstick study that ran."""
    blocks: list[Any] = [
        "The ground truth of the chains and of the frictional scenes is a model, compliant "
        "contact integrated in time. Here an engine that integrates the impact in time too, "
        "tuned as rigid and as faithful to e and mu as it allows, is run on every scene both "
        "treat, and its answer is compared with the model's on the same problem: difference = "
        "sqrt(dv^T M dv / v^T M v), dv the difference of the post-impact velocities and v the "
        "pre-impact one (the kinetic metric: no unit, rotations and translations weighed by "
        f"the inertia), within {LEVEL:g} where the two model the same physics. Beside it the "
        "largest velocity difference over the largest pre-impact speed (the model error's "
        "measure). Where they differ by more, the verdict names the engine's finding: the "
        "physics the two model differently, measured by matching it."
    ]
    tables = ctx.tables("yardstick")
    if not tables:
        left = [name for name in ctx.left_out if name.endswith("_yardstick")]
        where = (
            "The full report holds it (`lawbench report --full`): a tuned engine integrates "
            "each impact in time, 0.2 to 3 s a scene"
            if ctx.config.mode != "full"
            else "No yardstick study ran"
        )
        listed = f" (studies {', '.join(f'`{name}`' for name in left)})" if left else ""
        return Section(ANCHOR, TITLE, [*blocks, f"{where}{listed}."])
    for study, table in tables:
        blocks += _study(ctx, study, table)
    return Section(ANCHOR, TITLE, blocks)


def _study(ctx: Context, study: Study, table: pd.DataFrame) -> list[Any]:
    table = table.fillna({"error_class": ""})
    law = study.laws[0]
    rows, refused = [], {}
    for case, cells in table.groupby("case", sort=True):
        first = cells[cells["repeat"] == 0].iloc[0].to_dict()
        value = parsed(first.get("yardstick_value"))
        if value is None:
            why = failure(first) if first["error_class"] else first.get("yardstick_detail", "")
            refused.setdefault(str(why), []).append(str(case))
            continue
        truth = ctx.case(str(case)).ground_truth
        rows.append(
            {
                "scene": f"`{case}`",
                "difference": f"{value:.2g}",
                "max |dv| / max |v-|": _number(first.get("model_distance")),
                "verdict": str(first["yardstick_verdict"]),
                "why": _why(ctx, law, first),
                f"{law} [s]": _number(cells["wall_time_s"].min()),
                f"{truth.law} [s]": _number(cells["model_seconds"].min()),
            }
        )
    caption = (
        f"{study.title}: per scene the difference in the kinetic metric, its verdict and why, "
        "and the cost of each (the shortest of the cell's solves)."
    )
    blocks: list[Any] = [Table(study.name, caption, pd.DataFrame(rows))] if rows else []
    blocks += [
        f"Not compared on {', '.join(f'`{c}`' for c in cases)}: {why}."
        for why, cases in refused.items()
    ]
    return blocks


def _why(ctx: Context, law: str, row: dict[str, Any]) -> str:
    """A row's verdict in words: within the level, or the finding that explains it."""
    verdict = row["yardstick_verdict"]
    if verdict == str(Verdict.HOLDS):
        return f"within {LEVEL:g}"
    finding = int(row.get("yardstick_finding", -1))
    if verdict == str(Verdict.LAW_PROPERTY) and finding >= 0:
        return ctx.law(law).findings[finding].describe()
    return str(row.get("yardstick_detail", ""))


def _number(value: Any) -> str:
    value = parsed(value)
    return "" if value is None else f"{float(value):.2g}"
