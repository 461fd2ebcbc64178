"""Section 5, energy-increase paradoxes: maps of the energy change of the frictional laws.

A view of the studies declared with `lawbench.studies.declared.energy_map`: each frictional scene
names the two parameters its map spans (and the example it starts from). Every law that can
treat the scene is solved on the grid; its relative energy change ``dT / T-`` is mapped, and
beside it the verdict of each cell (the energy-gain check: a gain the law's findings predict is
a *law property*, any other gain is not). A table gives, per law, where it gains energy.

Two laws a row (each law's map and its verdicts side by side) keep a figure as wide as the page,
its labels readable; the colour scale is the scene's own, symmetric and logarithmic beyond
``LINEAR``, so that one law's gain of 8 does not wash out another's change of 1e-2.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.colors import ListedColormap, SymLogNorm

from lawbench.checks.outcome_checks import TOLERANCE
from lawbench.core.case import Case
from lawbench.core.verdicts import Verdict
from lawbench.studies.study import Study
from lawbench.views.report import plots
from lawbench.views.report.marks import COLOURS
from lawbench.views.report.page import Figure, Legend, Section, Table
from lawbench.views.report.runs import Context, label
from lawbench.views.report.summary import failure

ANCHOR, TITLE, VIEWS = "paradoxes", "Energy-increase paradoxes", ("paradoxes",)
CLASSES = list(Verdict)
# Two laws per row of panels (each law's map and its verdicts): the figure fits the page.
LAWS_PER_ROW = 2
# |dT / T-| below this is drawn on a linear colour scale, above on a logarithmic one.
LINEAR = 1e-3


def axis_label(case: Case, name: str) -> str:
    """A parameter's name with its unit (from the scene's spec)."""
    spec = next(s for s in case.params if s.name == name)
    return f"{name} [{spec.unit}]" if spec.unit else f"{name} (dimensionless)"


def cells(study: Study, table: pd.DataFrame) -> pd.DataFrame:
    """One row per cell: law, both parameters, dT / T-, verdict, why."""
    x, y = study.axes
    rows = []
    for row in table.fillna({"error_class": ""}).to_dict("records"):
        params = json.loads(row["params"])
        failed = bool(row["error_class"])
        rows.append(
            {
                "law": row["law"],
                x: params[x],
                y: params[y],
                "dT_over_T": np.nan if failed else row["dT"] / row["T_minus"],
                "verdict": row["verdict"],
                "detail": failure(row) if failed else row["energy_gain_detail"],
                "reproducer": row["reproducer"],
            }
        )
    return pd.DataFrame(rows)


def build(ctx: Context) -> Section:
    """The section, from every energy map that ran."""
    blocks: list[Any] = [
        "Relative kinetic energy change dT / T- of every law that can treat each frictional "
        "scene, over the two parameters the scene names; beside each map, the verdict of "
        f"every cell (energy created when dT / T- > {TOLERANCE:g}: a law property where the "
        "law's findings predict it).",
        Legend(),
    ]
    summary = []
    for study, table in ctx.tables("paradoxes"):
        case = ctx.case(study.cases[0])
        data = cells(study, table)
        x, y = study.axes
        summary += _regions(case.name, data, x, y)
        blocks.append(_figure(case, study, data))
        blocks.append(_nobody_gains(case.name, data, x, y))
    if summary:
        blocks.append(
            Table(
                "paradoxes_regions",
                "Per map and law, one row each: the points, how many create energy, their "
                "verdicts, the largest gain and where, and the ranges the gaining points span.",
                pd.DataFrame(summary),
            )
        )
    return Section(ANCHOR, TITLE, blocks)


def _nobody_gains(case: str, data: pd.DataFrame, x: str, y: str) -> str:
    """How many points of the map every law answered, and at how many none gains energy."""
    wide = data.pivot_table(index=[x, y], columns="law", values="dT_over_T", aggfunc="first")
    answered = wide.notna().all(axis=1)
    none = answered & (wide <= TOLERANCE).all(axis=1)
    return (
        f"On `{case}`, every law answered at {int(answered.sum())} of the {len(wide)} points; "
        f"at {int(none.sum())} of them no law creates energy."
    )


def _regions(case: str, data: pd.DataFrame, x: str, y: str) -> list[dict]:
    rows = []
    for law, part in data.groupby("law", sort=False):
        gain = part[part["dT_over_T"] > TOLERANCE]
        verdicts = part["verdict"].value_counts()
        row = {"case": case, "law": law, "points": len(part), "gaining": len(gain)}
        row["verdicts"] = ", ".join(f"{n} {v}" for v, n in verdicts.items())
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
    return rows


def _norm(values: np.ndarray) -> SymLogNorm:
    """A colour scale symmetric about 0 and logarithmic beyond `LINEAR` of ``dT / T-``.

    A gain of 8 and a loss of 0.01 on one map both stay visible; the scale is the map's own.
    """
    finite = np.abs(values[np.isfinite(values)])
    bound = max(float(finite.max()) if finite.size else 1.0, 10 * LINEAR)
    return SymLogNorm(linthresh=LINEAR, vmin=-bound, vmax=bound, base=10)


def _figure(case: Case, study: Study, data: pd.DataFrame) -> Figure:
    x, y = study.axes
    laws = list(dict.fromkeys(data["law"]))
    rows = -(-len(laws) // LAWS_PER_ROW)
    fig, axes = plots.figure(rows, 2 * min(len(laws), LAWS_PER_ROW), width=2.9, height=2.7)
    norm = _norm(data["dT_over_T"].to_numpy(dtype=float))
    classes = ListedColormap([COLOURS[v] for v in CLASSES])
    for k, law in enumerate(laws):
        part = data[data["law"] == law]
        grid = part.pivot_table(index=y, columns=x, values="dT_over_T", aggfunc="first")
        row, col = divmod(k, LAWS_PER_ROW)
        change, verdict = axes[row, 2 * col], axes[row, 2 * col + 1]
        mesh = change.pcolormesh(
            grid.columns, grid.index, grid.to_numpy(), norm=norm, cmap="RdBu_r"
        )
        fig.colorbar(mesh, ax=change, label="dT / T- [-]")
        codes = part.assign(code=[CLASSES.index(Verdict(v)) for v in part["verdict"]])
        kinds = codes.pivot_table(index=y, columns=x, values="code", aggfunc="first")
        verdict.pcolormesh(
            kinds.columns, kinds.index, kinds.to_numpy(), cmap=classes, vmin=-0.5, vmax=5.5
        )
        change.set(title=f"{law}: dT / T-")
        verdict.set(title=f"{law}: verdict")
        for ax in (change, verdict):
            ax.set(xlabel=axis_label(case, x), ylabel=axis_label(case, y))
    for ax in axes.flat[2 * len(laws) :]:
        ax.set_axis_off()
    fixed = label(dict(study.params), skip=())
    return Figure(
        f"paradoxes_{case.name}",
        f"Energy change dT / T- (red: energy created; a colour scale of this scene's own, "
        f"linear within {LINEAR:g} of zero and logarithmic beyond, so small and large changes "
        f"both show) and verdict (colours of the legend) of every law on `{case.name}` over "
        f"{x} and {y}"
        + (f", with {fixed}" if fixed else "")
        + "; a blank cell: the law gave no answer there. The other parameters at their "
        "defaults.",
        fig,
        data,
    )
