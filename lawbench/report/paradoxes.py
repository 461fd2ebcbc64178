"""Section 5, energy-increase paradoxes: maps of the energy change of the frictional laws.

Over two parameters of a scene (rod angle and mu on ``falling_rod``; e and mu on
``double_pendulum``), every frictional law that can treat the scene is solved on a grid and its
relative energy change ``dT / T-`` is mapped, the points where it creates energy (above the
checks' tolerance) marked. The other parameters are those of the scene's example named for
the energy gain when it has one, else its defaults. A table gives, per law, where it gains
energy, and the points where no law does (every law answered and none gains).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.colors import TwoSlopeNorm

from lawbench.case import Case
from lawbench.checks.base import TOLERANCE
from lawbench.errors import LawbenchError
from lawbench.report import plots
from lawbench.report.page import Figure, Section, Table
from lawbench.report.runs import Context, Job, error_text

ANCHOR, TITLE = "paradoxes", "Energy-increase paradoxes"
# Scene, then each axis as (parameter, first value, last value).
MAPS = (
    ("falling_rod", ("angle", 5.0, 85.0), ("mu", 0.0, 1.5)),
    ("double_pendulum", ("e", 0.0, 1.0), ("mu", 0.0, 1.5)),
)


def base_example(case: Case) -> tuple[str, dict[str, Any]]:
    """The example named for the energy gain, else the first (the defaults)."""
    name = next((n for n in case.examples if "gain" in n), next(iter(case.examples)))
    return name, dict(case.examples[name])


def _grid(axis: tuple[str, float, float], points: int) -> np.ndarray:
    return np.linspace(axis[1], axis[2], points)


def _plan(ctx: Context) -> tuple[list[tuple], list[Job], list[str]]:
    maps, jobs, notes = [], [], []
    for name, x_axis, y_axis in MAPS:
        case = ctx.case(name)
        if case is None:
            notes.append(f"scene `{name}` is not registered: its map is left out")
            continue
        laws = [law for law in ctx.laws if law.tags.friction and law.tags.covers(case.requires)]
        if not laws:
            notes.append(f"no frictional law can treat `{name}`: its map is left out")
            continue
        example, base = base_example(case)
        xs, ys = _grid(x_axis, ctx.config.map_points), _grid(y_axis, ctx.config.map_points)
        try:
            case.parameters(**{**base, x_axis[0]: float(xs[0]), y_axis[0]: float(ys[0])})
        except LawbenchError as exc:
            notes.append(f"`{name}` cannot be mapped over {x_axis[0]} and {y_axis[0]}: {exc}")
            continue
        first = len(jobs)
        for law in laws:
            for y in ys:
                for x in xs:
                    params = {**base, x_axis[0]: float(x), y_axis[0]: float(y)}
                    jobs.append(Job(law.name, name, params))
        maps.append((case, example, x_axis, y_axis, xs, ys, [law.name for law in laws], first))
    return maps, jobs, notes


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's runs; the returned function builds it."""
    maps, jobs, notes = _plan(ctx)
    batch = ctx.batch("paradoxes", jobs)
    return lambda: _build(ctx, maps, notes, batch.records())


def _build(ctx: Context, maps: list, notes: list[str], records: list) -> Section:
    blocks: list[Any] = [
        "Relative kinetic energy change dT / T- of each frictional law over two parameters "
        f"(a {ctx.config.map_points} x {ctx.config.map_points} grid); '+' marks the points "
        f"where the law creates energy (dT / T- > {TOLERANCE:g}), 'x' where it raised an error."
        + "".join(f" Note: {n}." for n in notes)
    ]
    summary = []
    for case, example, x_axis, y_axis, xs, ys, laws, first in maps:
        size = len(xs) * len(ys)
        rows = []
        for k, law in enumerate(laws):
            for j, record in enumerate(records[first + k * size : first + (k + 1) * size]):
                failed = bool(record.get("error_class"))
                relative = np.nan if failed else record["dT"] / record["T_minus"]
                rows.append(
                    {
                        "law": law,
                        x_axis[0]: xs[j % len(xs)],
                        y_axis[0]: ys[j // len(xs)],
                        "dT_over_T": relative,
                        "gain": bool(relative > TOLERANCE),
                        "error": error_text(record),
                    }
                )
        data = pd.DataFrame(rows)
        summary += _regions(case.name, data, laws, x_axis[0], y_axis[0])
        blocks.append(_figure(case, example, data, laws, x_axis[0], y_axis[0]))
    if summary:
        blocks.append(
            Table(
                "paradoxes_regions",
                "Where each law creates energy on each map: the count of points, of points "
                "where it gains, of failures, the largest gain and where it occurs, and the "
                "ranges the gaining points span; the row 'no law gains' counts, under "
                "'gaining', the points where every law answered and none gains.",
                pd.DataFrame(
                    summary,
                    columns=[
                        "case",
                        "law",
                        "points",
                        "gaining",
                        "failed",
                        "largest gain",
                        "gaining region",
                    ],
                ),
            )
        )
    return Section(ANCHOR, TITLE, blocks)


def _regions(case: str, data: pd.DataFrame, laws: list[str], x: str, y: str) -> list[dict]:
    rows = []
    for law in laws:
        part = data[data["law"] == law]
        gain = part[part["gain"]]
        row = {"case": case, "law": law, "points": len(part), "gaining": len(gain)}
        row["failed"] = int((part["error"] != "").sum())
        if len(gain):
            best = gain.loc[gain["dT_over_T"].idxmax()]
            row["largest gain"] = (
                f"dT/T- = {best['dT_over_T']:.3g} at {x} = {best[x]:.3g}, {y} = {best[y]:.3g}"
            )
            row["gaining region"] = (
                f"{x} {gain[x].min():.3g} to {gain[x].max():.3g}, "
                f"{y} {gain[y].min():.3g} to {gain[y].max():.3g}"
            )
        rows.append(row)
    wide = data.pivot_table(index=[x, y], columns="law", values="dT_over_T", aggfunc="first")
    answered = wide.notna().all(axis=1)
    none = answered & (wide <= TOLERANCE).all(axis=1)
    rows.append(
        {"case": case, "law": "no law gains", "points": int(answered.sum())}
        | {"gaining": int(none.sum()), "failed": int((~answered).sum())}
    )
    return rows


def _figure(case: Case, example: str, data: pd.DataFrame, laws: list, x: str, y: str) -> Figure:
    columns = min(len(laws) + 1, 4)
    rows = -(-(len(laws) + 1) // columns)
    fig, axes = plots.figure(rows, columns, width=3.6, height=3.0)
    values = data["dT_over_T"].to_numpy(dtype=float)
    low = min(float(np.nanmin(values)) if np.isfinite(values).any() else -1.0, -1e-12)
    high = max(float(np.nanmax(values)) if np.isfinite(values).any() else 1.0, 1e-12)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=low, vmax=high)
    for k, law in enumerate(laws):
        ax = axes.flat[k]
        part = data[data["law"] == law]
        grid = part.pivot_table(index=y, columns=x, values="dT_over_T", aggfunc="first")
        mesh = ax.pcolormesh(grid.columns, grid.index, grid.to_numpy(), norm=norm, cmap="RdBu_r")
        gain, failed = part[part["gain"]], part[part["error"] != ""]
        ax.plot(gain[x], gain[y], "k+", markersize=5)
        ax.plot(failed[x], failed[y], "x", color="0.4", markersize=5)
        ax.set(title=law, xlabel=x, ylabel=y)
    fig.colorbar(mesh, ax=axes.flat[len(laws) - 1], label="dT / T-")
    counts = data.groupby([y, x])["gain"].sum().unstack(x)
    ax = axes.flat[len(laws)]
    shown = ax.pcolormesh(
        counts.columns,
        counts.index,
        counts.to_numpy(),
        cmap="Greys",
        vmin=0,
        vmax=max(len(laws), 1),
    )
    fig.colorbar(shown, ax=ax, label="laws gaining energy")
    ax.set(title="laws gaining energy", xlabel=x, ylabel=y)
    for ax in axes.flat[len(laws) + 1 :]:
        ax.set_axis_off()
    return Figure(
        f"paradoxes_{case.name}",
        f"Energy change dT / T- of every frictional law on `{case.name}` over {x} and {y}, "
        f"the other parameters from its example '{example}'; '+' energy created, 'x' error; "
        "last panel: how many laws create energy at each point (white: none).",
        fig,
        data,
    )
