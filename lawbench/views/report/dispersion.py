"""Section 6, dispersion and continuity.

Energy shares: a view of the studies declared with `lawbench.studies.declared.energy_shares`. Each
scene sweeps the stiffness ratio of its contacts; the share of the post-impact kinetic energy
each body carries and the dispersion index are drawn for every law, and each cell's verdict is
that of the dispersion check (the shares against the scene's ground truth) and the energy check.

Continuity: a view of the studies declared with `lawbench.studies.declared.continuity`: the outcome
jump of every law under vanishing gap and velocity perturbations against the perturbation size,
and the verdict of the continuity check at the smallest size, whose detail gives the kinetic
angles between the contacts (Paoli's condition).
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd

from lawbench.checks.continuity import CONTINUOUS
from lawbench.core.case import Case
from lawbench.core.verdicts import Verdict
from lawbench.studies.study import Study
from lawbench.views.report import plots
from lawbench.views.report.marks import Mark
from lawbench.views.report.page import Figure, Legend, Section, Table
from lawbench.views.report.paradoxes import axis_label
from lawbench.views.report.runs import Context, axis_value, parsed
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "dispersion", "Dispersion and continuity", ("dispersion", "continuity")
JUMP_LABEL = "outcome jump max|v+ - v+(0)| / max|v-| (dimensionless)"


def _reason(row: dict[str, Any], checks: tuple[str, ...]) -> str:
    if row["error_class"]:
        return failure(row)
    return "; ".join(f"{c}: {row[f'{c}_detail']}" for c in checks)


def build(ctx: Context) -> Section:
    """The section, from every energy-share and continuity study that ran."""
    blocks: list[Any] = [
        "How the kinetic energy spreads over the bodies as the stiffness ratio of the contacts "
        "sweeps, and how the outcome moves under vanishing perturbations of the initial gaps "
        "and velocities. Every cell carries its verdict (legend).",
        Legend(),
    ]
    for study, table in ctx.tables("dispersion"):
        blocks += _shares(ctx.case(study.cases[0]), study, table)
    for study, table in ctx.tables("continuity"):
        blocks += _continuity(ctx.case(study.cases[0]), study, table)
    return Section(ANCHOR, TITLE, blocks)


def _shares(case: Case, study: Study, table: pd.DataFrame) -> list[Any]:
    axis = study.axes[0]
    checks = study.check_names()
    rows, marks = [], {}
    for row in table.fillna({"error_class": ""}).to_dict("records"):
        ratio = axis_value(row, axis)
        verdict = Verdict(row["verdict"])
        marks.setdefault(row["law"], {"law": row["law"]})[f"{ratio:g}"] = Mark(
            "", verdict, _reason(row, checks)
        )
        base = {"law": row["law"], axis: ratio, "verdict": str(verdict)}
        shares = parsed(row.get("energy_shares")) or {}
        rows += [{**base, "body": b, "share": s} for b, s in shares.items()]
        index = parsed(row.get("dispersion_index"))
        if index is not None:
            rows.append({**base, "body": "dispersion index", "share": index})
    data = pd.DataFrame(rows, columns=["law", axis, "body", "share", "verdict"])
    bodies = list(dict.fromkeys(data["body"]))
    fig, axes = plots.figure(1, max(len(bodies), 1), width=3.4, height=3.0)
    for ax, body in zip(axes[0], bodies, strict=False):
        for law, group in data[data["body"] == body].groupby("law", sort=False):
            style = plots.law_style(law)
            ax.plot(group[axis], group["share"], linestyle="-", markersize=4, **style)
        ylabel = "index (0: one body, 1: even)" if body == "dispersion index" else "energy share"
        plots.log_scale(ax, "x")
        ax.set(title=body, xlabel=axis_label(case, axis), ylabel=ylabel)
        ax.set_ylim(-0.03, 1.03)
    axes[0, 0].legend(fontsize="x-small")
    verdicts = pd.DataFrame(list(marks.values()))
    return [
        Figure(
            f"shares_{case.name}",
            f"Share of the post-impact kinetic energy per body (dimensionless), and the "
            f"dispersion index, on `{case.name}` (other parameters at their defaults) over "
            f"{axis}, every law that can treat it.",
            fig,
            data,
        ),
        Table(
            f"shares_verdicts_{case.name}",
            f"Verdict of every cell of the energy shares on `{case.name}`, per law (rows) and "
            f"{axis} (columns): the worst of {', '.join(checks)}; hover for the reasons.",
            verdicts,
        ),
    ]


def _continuity(case: Case, study: Study, table: pd.DataFrame) -> list[Any]:
    rows, summary = [], []
    for row in table.fillna({"error_class": ""}).to_dict("records"):
        verdict = Verdict(row["verdict"])
        reason = _reason(row, study.check_names())
        jumps = parsed(row.get("jumps"))
        smallest = np.nan
        if jumps:
            for kind in ("gaps", "velocities"):
                rows += [
                    {"law": row["law"], "perturbation": kind, "size": s, "jump": j}
                    for s, j in zip(jumps["sizes"], jumps[kind], strict=True)
                ]
            smallest = max(jumps["gaps"][-1], jumps["velocities"][-1])
        summary.append(
            {
                "law": row["law"],
                "jump at the smallest size": "" if smallest != smallest else f"{smallest:.2g}",
                "verdict": Mark("", verdict, reason),
                "reason": reason,
            }
        )
    data = pd.DataFrame(rows, columns=["law", "perturbation", "size", "jump"])
    fig, axes = plots.figure(1, 2, width=4.4, height=3.4)
    units = {"gaps": "initial gap [m]", "velocities": "velocity change / max |v-|"}
    for ax, kind in zip(axes[0], ("gaps", "velocities"), strict=True):
        for law, group in data[data["perturbation"] == kind].groupby("law", sort=False):
            ax.plot(
                group["size"], plots.floored(group["jump"]), linestyle="-", **plots.law_style(law)
            )
        ax.axhline(CONTINUOUS, color="k", linestyle=":", linewidth=0.8)
        plots.log_scale(ax, "xy")
        ax.set(title=f"perturbed {kind}", xlabel=units[kind])
        ax.set_ylim(bottom=plots.FLOOR / 10)
        ax.set_ylabel(JUMP_LABEL)
    axes[0, 0].legend(fontsize="x-small")
    sizes = json.dumps(list(study.settings.get("continuity_sizes", [])))
    return [
        Figure(
            f"continuity_{case.name}",
            f"Outcome jump against the perturbation size on `{case.name}` at its defaults: "
            "small gaps letting each contact close first, and random velocity perturbations "
            f"(sizes {sizes}); dotted: the continuity check's threshold {CONTINUOUS:g}; zero "
            f"jumps drawn at {plots.FLOOR:g}.",
            fig,
            data,
        ),
        Table(
            f"continuity_verdicts_{case.name}",
            f"The continuity check on `{case.name}` per law: the jump left at the smallest "
            "size and the verdict, with the kinetic angles between the contacts in the reason.",
            pd.DataFrame(summary),
        ),
    ]
