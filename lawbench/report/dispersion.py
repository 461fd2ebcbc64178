"""Section 6, dispersion and continuity.

Energy shares: on the three-ball chain and on two balls against a wall, every law that can
treat the scene is solved over the stiffness ratio of its two contacts; the share of the
post-impact kinetic energy each body carries (`lawbench.mechanics.energy_shares`) and the
dispersion index (`lawbench.checks.dispersion.dispersion_index`) are drawn for every law on
one figure per scene. Rigid laws that ignore stiffness draw flat lines.

Continuity: on the same scenes at their defaults, the outcome jump under vanishing gap and
velocity perturbations (`lawbench.checks.continuity.jumps`) against the perturbation size, and
the verdict at the smallest size, with the kinetic angles between the contacts (Paoli's
condition).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from lawbench.checks.continuity import CONTINUOUS
from lawbench.checks.dispersion import dispersion_index
from lawbench.mechanics import energy_shares, kinetic_angles
from lawbench.report import plots, tasks
from lawbench.report.page import Figure, Section, Table
from lawbench.report.runs import Context, Job, array, from_result
from lawbench.report.summary import default_example

ANCHOR, TITLE = "dispersion", "Dispersion and continuity"
SCENES = ("three_ball_chain", "two_balls_wall")


def _scenes(ctx: Context) -> tuple[list, list[str]]:
    scenes, notes = [], []
    for name in SCENES:
        case = ctx.case(name)
        if case is None:
            notes.append(f"scene `{name}` is not registered")
        elif not any(spec.name == "stiffness_ratio" for spec in case.params):
            notes.append(f"scene `{name}` has no parameter stiffness_ratio")
        else:
            scenes.append(case)
    return scenes, notes


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's runs; the returned function builds it."""
    scenes, notes = _scenes(ctx)
    pairs = [(c, law) for c in scenes for law in ctx.laws if law.tags.covers(c.requires)]
    jobs = [
        Job(law.name, case.name, {"stiffness_ratio": ratio})
        for case, law in pairs
        for ratio in ctx.config.share_ratios
    ]
    batch = ctx.batch("dispersion", jobs)
    sizes = list(ctx.config.jump_sizes)
    handles = [
        ctx.guard.submit(
            tasks.continuity_jumps, law.name, case.name, default_example(case)[1], sizes
        )
        for case, law in pairs
    ]
    return lambda: _build(ctx, scenes, notes, pairs, jobs, batch.records(), handles)


def _build(
    ctx: Context, scenes: list, notes: list, pairs: list, jobs: list, records: list, handles: list
) -> Section:
    blocks: list[Any] = [
        "How the kinetic energy spreads over the bodies as the stiffness ratio of the two "
        "contacts sweeps "
        f"{min(ctx.config.share_ratios):g} to {max(ctx.config.share_ratios):g}, and how the "
        "outcome moves under vanishing perturbations of the initial gaps and velocities."
        + "".join(f" Note: {n}." for n in notes)
    ]
    shares = _shares(ctx, jobs, records)
    jumps = _jumps(ctx, pairs, handles)
    verdicts = []
    for case in scenes:
        blocks.append(_share_figure(case, shares[shares["case"] == case.name]))
        part = jumps[jumps["case"] == case.name]
        blocks.append(_jump_figure(case, part, ctx.config.jump_sizes))
        verdicts += _verdicts(case, part)
    blocks.append(
        Table(
            "continuity_verdicts",
            f"Continuity at the smallest perturbation (continuous when the jump is at most "
            f"{CONTINUOUS:g} of the largest velocity), with the kinetic angles between the "
            "contacts at the defaults.",
            pd.DataFrame(verdicts),
        )
    )
    return Section(ANCHOR, TITLE, blocks)


def _shares(ctx: Context, jobs: list[Job], records: list) -> pd.DataFrame:
    rows = []
    for job, record in zip(jobs, records, strict=True):
        ratio = job.params["stiffness_ratio"]
        base = {"case": job.case, "law": job.law, "stiffness_ratio": ratio}
        v_plus = array(record, "v_plus")
        if v_plus is None:
            rows.append({**base, "body": "", "share": np.nan, "error": record["error_class"]})
            continue
        problem = ctx.case(job.case).build(stiffness_ratio=ratio)
        found = energy_shares(problem, v_plus)
        rows += [{**base, "body": b, "share": s, "error": ""} for b, s in found.items()]
        rows.append({**base, "body": "dispersion index", "share": dispersion_index(found)})
    return pd.DataFrame(rows, columns=["case", "law", "stiffness_ratio", "body", "share", "error"])


def _jumps(ctx: Context, pairs: list, handles: list) -> pd.DataFrame:
    rows = []
    for (case, law), handle in zip(pairs, handles, strict=True):
        params = default_example(case)[1]
        job = Job(law.name, case.name, params)
        record = from_result(ctx.guard.result(handle), job, ctx.config.budget_s)
        sizes = ctx.config.jump_sizes
        base = {"case": case.name, "law": law.name}
        if record.get("error_class"):
            message = f"{record['error_class']}: {record.get('error_message', '')}"
            rows.append(
                {**base, "perturbation": "", "size": np.nan, "jump": np.nan, "error": message}
            )
            continue
        for kind, values in record.items():
            if kind in ("gaps", "velocities"):
                rows += [
                    {**base, "perturbation": kind, "size": s, "jump": j, "error": ""}
                    for s, j in zip(sizes, values, strict=True)
                ]
    return pd.DataFrame(rows, columns=["case", "law", "perturbation", "size", "jump", "error"])


def _share_figure(case: Any, data: pd.DataFrame) -> Figure:
    bodies = [b for b in dict.fromkeys(data["body"]) if b]
    fig, axes = plots.figure(1, max(len(bodies), 1), width=3.4, height=3.0)
    for ax, body in zip(axes[0], bodies, strict=False):
        part = data[data["body"] == body]
        for law, group in part.groupby("law", sort=False):
            ax.plot(
                group["stiffness_ratio"],
                group["share"],
                linestyle="-",
                markersize=4,
                **plots.law_style(law),
            )
        ax.set(xscale="log", title=body, xlabel="stiffness ratio", ylim=(-0.03, 1.03))
    axes[0, 0].set_ylabel("share of the kinetic energy")
    axes[0, 0].legend(fontsize="x-small")
    return Figure(
        f"shares_{case.name}",
        f"Share of the post-impact kinetic energy per body, and the dispersion index, on "
        f"`{case.name}` (other parameters at their defaults) over the stiffness ratio of "
        "its contacts, every law that can treat it.",
        fig,
        data.reset_index(drop=True),
    )


def _jump_figure(case: Any, data: pd.DataFrame, sizes: tuple[float, ...]) -> Figure:
    fig, axes = plots.figure(1, 2, width=4.4, height=3.4)
    for ax, kind in zip(axes[0], ("gaps", "velocities"), strict=True):
        part = data[data["perturbation"] == kind]
        for law, group in part.groupby("law", sort=False):
            ax.plot(
                group["size"], plots.floored(group["jump"]), linestyle="-", **plots.law_style(law)
            )
        ax.axhline(CONTINUOUS, color="k", linestyle=":", linewidth=0.8)
        unit = "m" if kind == "gaps" else "of the largest velocity"
        ax.set(
            xscale="log",
            yscale="log",
            title=f"perturbed {kind}",
            xlabel=f"perturbation size ({unit})",
            ylabel="outcome jump (relative)",
        )
    axes[0, 0].legend(fontsize="x-small")
    return Figure(
        f"continuity_{case.name}",
        f"Outcome jump against the perturbation size on `{case.name}` at its defaults: small "
        "gaps letting each contact close first, and random velocity perturbations; dotted: "
        f"the verdict's threshold {CONTINUOUS:g}; zero jumps drawn at {plots.FLOOR:g}.",
        fig,
        data.reset_index(drop=True),
    )


def _verdicts(case: Any, data: pd.DataFrame) -> list[dict[str, Any]]:
    problem = case.build(**default_example(case)[1])
    angles = kinetic_angles(problem)
    text = ", ".join(
        f"{i}-{j}: {angles[i, j]:.1f} deg"
        for i in range(problem.m)
        for j in range(i + 1, problem.m)
    )
    rows = []
    for law, part in data.groupby("law", sort=False):
        if part["error"].iloc[0]:
            rows.append({"case": case.name, "law": law, "verdict": part["error"].iloc[0]})
            continue
        smallest = part[part["size"] == part["size"].min()]
        jump = float(smallest["jump"].max())
        verdict = "continuous" if jump <= CONTINUOUS else "discontinuous"
        rows.append(
            {
                "case": case.name,
                "law": law,
                "jump": f"{jump:.2g}",
                "verdict": verdict,
                "kinetic angles": text,
            }
        )
    return rows
