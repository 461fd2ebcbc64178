"""The section "Against measurements": every law fitted on measured impacts and judged on others.

Per registered measurement set, the measured study (`lawbench.fitting.measured.measured_study`)
fits each law's contact coefficients on the set's training half and predicts its test half; the
table ranks the laws and the two baselines by held-out median error, with the bootstrap 95%
interval of the median, the coefficients, the cost of one prediction, what each row was fitted
and judged on, and every refusal with its reason (a law that fits no friction coefficient
refuses every impact measured with friction). Scatter plots put the predicted contact
velocities after the impact (normal and tangential) and the angular velocity against the
measured ones for three rows chosen by their tags, never by name: the best law, the best law
that reads no stiffness (rigid) and the best law that does (compliant). Kharaz's oblique
impacts (`lawbench.fitting.kharaz_curves`) draw every frictional law's tangential restitution,
rebound spin and rebound angles against incidence over the digitized points, with the RMS
error per range and whether the contact point reverses.

The studies run once per report, each set and Kharaz's curves as one task of a `Guard`'s worker
pool, so that the sets run side by side and a set whose study fails or runs out of time keeps
its error in the section while the others are shown. The quick report judges a fixed, evenly
spaced subsample of each set and Kharaz's digitized incidences only; the full report every
impact and the fine grid of incidences.
"""

from __future__ import annotations

import math
import time
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.law import LAWS
from lawbench.core.verdicts import Verdict
from lawbench.fitting import heldout, kharaz_curves, measured
from lawbench.fitting.measured import MeasuredStudy, measured_study
from lawbench.measurements import MEASUREMENTS, MeasurementSet
from lawbench.studies.guard import TIME_OUT, Guard, Result
from lawbench.studies.study import costly
from lawbench.views.report import plots
from lawbench.views.report.marks import Mark
from lawbench.views.report.page import Block, Figure, Section, Table, number
from lawbench.views.report.runs import Context, registered

ANCHOR, TITLE, VIEWS = "measured", "Against measurements", ()
# Wall-clock seconds one set's study (or Kharaz's curves) may take, per mode.
BUDGET_S = {"quick": 240.0, "full": 6.0 * 3600.0}
# The roles of the three rows drawn against the measurements, in the order of the legend.
ROLES = ("best law", "best rigid law", "best compliant law")
# Seconds the study of a law that follows the impact through time (an engine, or a law that
# reads stiffness) may take in the quick report: a fit solves each impact a hundred times or
# more, at 0.01 to 0.5 s a solve, so the quick page shows what
# such a law gives in that time (on `lawbench.fitting.measured.QUICK_COSTLY_FIT` and
# `QUICK_COSTLY_JUDGE` impacts of the quick subsample) and the full page the rest.
STIFF_QUICK_S = 30.0
QUANTITY_LABELS = {
    "tangential_restitution": "tangential restitution vx+/vx- [-]",
    "rebound_spin": "rebound spin -omega+ [rad/s]",
    "rebound_angle": "rebound angle of the centre [deg]",
    "contact_angle": "rebound angle of the contact point [deg]",
}


@dataclass
class Found:
    """What the section shows: each set's study (or its error) and Kharaz's curves."""

    quick: bool
    studies: dict[str, MeasuredStudy | str] = field(default_factory=dict)
    sets: dict[str, MeasurementSet] = field(default_factory=dict)
    kharaz: pd.DataFrame | str = "not run"
    seconds: float = 0.0
    workers: int = 1
    notes: list[str] = field(default_factory=list)


_FOUND: weakref.WeakKeyDictionary[Context, Found] = weakref.WeakKeyDictionary()


def _failure(result: Result) -> str:
    return f"{result.error_class or result.status}: {result.error_message}"


def results(ctx: Context) -> Found:
    """The measured studies of ``ctx``'s laws, run once per report in a worker pool.

    A set whose study fails or runs past `BUDGET_S` holds the error's text instead.
    """
    if ctx in _FOUND:
        return _FOUND[ctx]
    started = time.perf_counter()
    config = ctx.config
    quick = config.mode == "quick"
    names = [law.name for law in ctx.laws]
    found = Found(quick, workers=config.workers)
    sets, found.notes = registered(MEASUREMENTS, config.measurements)
    found.sets = {s.name: s for s in sets}
    frictional = [name for name in kharaz_curves.frictional_laws() if name in names]
    incidences = kharaz_curves.digitized_incidences() if quick else None
    with Guard(config.workers, BUDGET_S[config.mode]) as guard:
        curves = guard.submit(kharaz_curves.curves, frictional, incidences)
        handles = {
            name: [
                (group, guard.submit(measured_study, chosen_set, group, quick, budget=seconds))
                for chosen_set, group, seconds in tasks(s, names, quick)
            ]
            for name, s in found.sets.items()
        }
        note = " among the quick subsample, evenly spaced" if quick else ""
        for name, parts in handles.items():
            done = [(group, guard.result(handle)) for group, handle in parts]
            found.studies[name] = joined(done, note)
        result = guard.result(curves)
        found.kharaz = result.value if result.status == "ok" else _failure(result)
    found.seconds = time.perf_counter() - started
    _FOUND[ctx] = found
    return found


def tasks(
    measurement_set: MeasurementSet, names: Sequence[str], quick: bool
) -> list[tuple[str, list[str], float]]:
    """The studies of one set: the laws that read no stiffness together, then each other law.

    A law that follows the impact through time (an engine, or one that reads stiffness) is
    tens to hundreds of times slower than a closed form: it runs alone, so that the pool
    spreads the set's work, and in the quick report within `STIFF_QUICK_S`. The quick report
    leaves the engines to the full one: tuned, they step each fit's trial for up to tenths of a
    second. Each task is ``(set name, laws, seconds)``.
    """
    mode = "quick" if quick else "full"
    if quick:
        names = [name for name in names if not LAWS.get(name).engine]
    stiff = [name for name in names if costly(LAWS.get(name))]
    rigid = [name for name in names if name not in stiff]
    seconds = STIFF_QUICK_S if quick else BUDGET_S[mode]
    return [
        (measurement_set.name, rigid, BUDGET_S[mode]),
        *((measurement_set.name, [name], seconds) for name in stiff),
    ]


def joined(parts: Sequence[tuple[list[str], Result]], note: str = "") -> MeasuredStudy | str:
    """One set's study from its tasks' laws and results, ranked anew.

    The first task holds the baselines (every task fits the same ones, the others' are
    dropped); when it fails, the set's study is its failure's text. A law whose own task
    failed or ran out of time keeps a row with the failure as its reason. ``note`` is added
    to what the other tasks' rows were fitted and judged on.
    """
    (_, head), *others = parts
    if head.status != "ok":
        return _failure(head)
    first = head.value
    tables, predictions = [first.table], [first.predictions]
    for laws, result in others:
        if result.status != "ok":
            reason = _failure(result)
            if result.status == TIME_OUT:
                reason = f"wall-clock budget: no answer within {result.seconds:g} s"
            rows = [{"law": law, "coefficients": measured.FITTED, "reason": reason} for law in laws]
            tables.append(pd.DataFrame(rows).assign(refused=0, failed=1))
            continue
        study = result.value
        table = study.table[~study.table["law"].isin(heldout.BASELINES)].copy()
        for column in ("fitted_on", "judged_on"):
            table[column] = table[column] + note
        tables.append(table)
        judged = study.predictions
        predictions.append(
            judged[~judged["law"].isin(heldout.BASELINES)] if len(judged) else judged
        )
    judged = pd.concat(predictions, ignore_index=True)
    table, common = measured.ranked(pd.concat(tables, ignore_index=True), judged)
    return MeasuredStudy(first.set_name, table, judged, common)


def verdict(row: dict[str, Any]) -> Mark:
    """The mark of a row's answer: refused, a failure or budget, or holds, with its reason."""
    reason = str(row.get("reason") or "")
    answered = not _blank(row["median_error"])
    if not answered and row["refused"]:
        return Mark(number(row["median_error"]), Verdict.REFUSED, reason)
    if not answered or row["failed"]:
        return Mark(number(row["median_error"]), _failed(reason), reason or "no answer")
    return Mark(number(row["median_error"]), Verdict.HOLDS, reason or "every judged impact")


def _failed(reason: str) -> Verdict:
    """A failure's verdict: budget where its reason names a budget or the guard that stopped it."""
    budget = "budget" in reason.lower() or "stopped by" in reason
    return Verdict.BUDGET if budget else Verdict.NUMERICAL_FAILURE


def _blank(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _interval(row: dict[str, Any]) -> str:
    """The bootstrap 95% interval of the median error; empty without an answer."""
    if _blank(row["ci_low"]):
        return ""
    return f"{number(row['ci_low'])} – {number(row['ci_high'])}"


def _pair(row: dict[str, Any]) -> str:
    """The median errors of the normal and tangential parts; empty without an answer."""
    if _blank(row["normal_error"]):
        return ""
    return f"{number(row['normal_error'])} / {number(row['tangential_error'])}"


def _coefficients(row: dict[str, Any], fields: Sequence[str]) -> str:
    """The row's coefficients, each with its standard error where it was fitted."""
    shown = []
    for name in fields:
        value, error = row.get(name), row.get(f"{name}_se")
        if _blank(value):
            continue
        text = f"{name} = {value:.4g}"
        shown.append(text if _blank(error) else f"{text} ± {error:.2g}")
    return ", ".join(shown)


def _fields(study: MeasuredStudy) -> list[str]:
    """The fitted contact fields among the table's columns."""
    fixed = set(measured.COLUMNS)
    return [c for c in study.table.columns if c not in fixed and not c.endswith("_se")]


def ranking(study: MeasuredStudy) -> Table:
    """The set's table: laws and baselines by held-out median error, each answer's verdict."""
    fields = _fields(study)
    rows = []
    for rank, row in enumerate(study.table.to_dict("records"), 1):
        mark = verdict(row)
        rows.append(
            {
                "rank": rank,
                "law": row["law"],
                "coefficients": row["coefficients"],
                "median error": mark,
                "95% CI": _interval(row),
                f"on the {study.common_count} common": number(row["common_error"]),
                "normal / tangential": _pair(row),
                "values": _coefficients(row, fields),
                "cost [ms]": number(1e3 * row["cost_s"]),
                "fitted on": row["fitted_on"],
                "judged on": row["judged_on"],
                "refused": Mark(str(row["refused"]), Verdict.REFUSED, row["reason"])
                if row["refused"]
                else 0,
                "failed": row["failed"],
                "reason": row["reason"],
            }
        )
    caption = (
        f"Set `{study.set_name}`: every law and baseline, fitted on the training impacts and "
        "ranked by the median of its relative kinetic error on the test impacts every row "
        f"judged on all of them solved (column 'on the {study.common_count} common'; a row "
        "judged on a subsample follows, by its own median), with the median on its own "
        "judged impacts (its mark: holds, refused, numerical failure or budget; the reason on "
        "hover), the bootstrap 95% interval of that median, the medians of the normal and "
        "tangential parts, the coefficients (fitted ± standard error, or a published set), "
        "the wall time of one prediction, and each refusal and failure with its reason."
    )
    return Table(f"measured_{study.set_name}", caption, pd.DataFrame(rows), study.table)


def chosen(study: MeasuredStudy) -> dict[tuple[str, str], list[str]]:
    """The rows drawn against the measurements: ``(law, coefficients)`` -> their roles.

    The best law, the best law that reads no stiffness and the best that does, by rank,
    among the registered laws with an answer (an engine is none of these: its rows stand in
    the table); a row that is best in two roles is drawn once.
    """
    picks: dict[tuple[str, str], list[str]] = {}
    tests = {
        ROLES[0]: lambda stiff: True,
        ROLES[1]: lambda stiff: not stiff,
        ROLES[2]: lambda stiff: stiff,
    }
    answered = study.table[study.table["median_error"].notna()]
    registered = [
        r
        for r in answered.to_dict("records")
        if r["law"] in LAWS.names() and not LAWS.get(r["law"]).engine
    ]
    for role, test in tests.items():
        row = next((r for r in registered if test(LAWS.get(r["law"]).tags.stiffness)), None)
        if row is not None:
            picks.setdefault((row["law"], row["coefficients"]), []).append(role)
    return picks


def angular(n: int) -> list[int]:
    """The angular velocity's coordinates: a planar body's last, a spatial body's last three.

    The measured sets hold one body, ``(vx, vy, omega)`` in the plane or ``(v, omega)`` in
    space; another number of coordinates has none drawn.
    """
    return {3: [2], 6: [3, 4, 5]}.get(n, [])


def _parts(problem: Any, v: np.ndarray) -> dict[str, np.ndarray]:
    """The normal and tangential contact velocities and the angular velocity of ``v``."""
    parts = {"normal contact velocity": np.asarray(problem.Wn).T @ v}
    if problem.Wt is not None:
        parts["tangential contact velocity"] = np.asarray(problem.Wt).T @ v
    parts["angular velocity"] = v[angular(problem.n)]
    return parts


def scatter_data(study: MeasuredStudy, chosen_rows: dict, impacts: Sequence[Any]) -> pd.DataFrame:
    """One row per drawn row, judged impact, quantity and component: predicted and measured."""
    by_index = {impact.index: impact for impact in impacts}
    frames = []
    judged = study.predictions
    for (law, coefficients), roles in chosen_rows.items():
        rows = judged[
            (judged["law"] == law)
            & (judged["coefficients"] == coefficients)
            & (judged["status"] == "ok")
        ]
        for row in rows.to_dict("records"):
            problem = by_index[row["index"]].problem
            predicted = _parts(problem, np.asarray(row["predicted"]))
            measured_parts = _parts(problem, np.asarray(row["measured"]))
            for quantity, values in predicted.items():
                frames.append(
                    pd.DataFrame(
                        {
                            "law": law,
                            "coefficients": coefficients,
                            "role": ", ".join(roles),
                            "index": row["index"],
                            "quantity": quantity,
                            "component": np.arange(len(values)),
                            "predicted": values,
                            "measured": measured_parts[quantity],
                        }
                    )
                )
    columns = ["law", "coefficients", "role", "index", "quantity", "component"]
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=columns)


def scatter(study: MeasuredStudy, data: pd.DataFrame) -> Figure:
    """Predicted against measured, one panel per quantity, the chosen rows overlaid.

    Every row is named once in the legend the report figure gathers below the panels.
    """
    quantities = list(dict.fromkeys(data["quantity"]))
    fig, axes = plots.figure(1, max(len(quantities), 1), width=3.8, height=3.6)
    for ax, quantity in zip(axes[0], quantities, strict=False):
        part = data[data["quantity"] == quantity]
        for (law, coefficients, role), rows in part.groupby(
            ["law", "coefficients", "role"], sort=False
        ):
            style = plots.law_style(law)
            ax.scatter(
                rows["measured"],
                rows["predicted"],
                s=10,
                alpha=0.6,
                color=style["color"],
                marker=style["marker"],
                label=f"{law} ({coefficients}; {role})",
            )
        low = float(np.nanmin(part[["measured", "predicted"]].to_numpy()))
        high = float(np.nanmax(part[["measured", "predicted"]].to_numpy()))
        ax.plot([low, high], [low, high], color="0.5", linewidth=0.7)
        unit = "rad/s" if quantity == "angular velocity" else "m/s"
        ax.set_xlabel(f"measured {quantity} [{unit}]")
        ax.set_ylabel(f"predicted [{unit}]")
    axes[0, 0].set_title(study.set_name)
    caption = (
        f"Set `{study.set_name}`: predicted against measured velocities after each judged test "
        "impact, for the best law, the best rigid law (one that reads no stiffness) and the "
        "best compliant law (one that does), by the ranking above: the contact velocities "
        "along the normals and tangents, and the angular velocity (every component). The grey "
        "line is perfect agreement."
    )
    return Figure(f"measured_{study.set_name}_scatter", caption, fig, data)


def set_blocks(study: MeasuredStudy, measurement_set: MeasurementSet) -> list[Block]:
    """The blocks of one set: its summary line, ranking table and scatter plots."""
    blocks: list[Block] = [f"Set `{study.set_name}`: {measurement_set.summary}.", ranking(study)]
    picks = chosen(study)
    if picks:
        data = scatter_data(study, picks, measurement_set.impacts)
        blocks.append(scatter(study, data))
    return blocks


def closest(study: MeasuredStudy) -> str:
    """The registered law closest to the set's measurements, its error and interval."""
    table = study.table
    laws = table[table["law"].isin(LAWS.names()) & table["median_error"].notna()]
    if laws.empty:
        return "no law answered"
    best = laws.iloc[0]
    return (
        f"`{best['law']}` ({best['coefficients']} coefficients), held-out median error "
        f"{number(best['median_error'])} (95% CI {number(best['ci_low'])}"
        f"–{number(best['ci_high'])}; {best['judged_on']})"
    )


def closest_per_set(ctx: Context) -> dict[str, str]:
    """Per measurement set, the law closest to measurement (`closest`) or why there is none."""
    try:
        found = results(ctx)
    except Exception as exc:  # the page keeps its top; the section shows the same error
        return {"every set": f"the studies failed: {type(exc).__name__}: {exc}"}
    return {
        name: closest(study) if isinstance(study, MeasuredStudy) else "study failed"
        for name, study in found.studies.items()
    }


def kharaz_blocks(curves: pd.DataFrame, quick: bool) -> list[Block]:
    """Kharaz's curves over the digitized points, the RMS per range and the reversal.

    The laws and the points are named in the legend the report figure gathers below the panels.
    """
    fig, axes = plots.figure(2, 2, width=4.6, height=3.4)
    points = kharaz_curves.measured()
    engines = [name for name in curves["law"].unique() if LAWS.get(name).engine]
    for ax, quantity in zip(axes.flat, kharaz_curves.QUANTITIES, strict=True):
        for law, rows in curves.groupby("law", sort=False):
            color, dashed = plots.law_style(law)["color"], law in engines
            line = "--" if dashed else "-"
            ax.plot(rows["incidence"], rows[quantity], color=color, ls=line, label=law, lw=1)
        at, values = points[quantity]
        ax.scatter(at, values, color="k", s=14, zorder=3, label="Kharaz et al. 2001")
        ax.set_xlabel("incidence from the normal [deg]")
        ax.set_ylabel(QUANTITY_LABELS[quantity])
    where = (
        "at the digitized incidences only (quick)"
        if quick
        else f"on a grid of {len(kharaz_curves.GRID)} incidences and at the digitized ones"
    )
    stepped = (
        f" The engines ({', '.join(engines)}, dashed) step the sphere on the anvil at their "
        "default settings, what a user gets: each one's findings at settings = default (the "
        "laws section) say why its curve departs."
        if engines
        else ""
    )
    figure = Figure(
        "kharaz_curves",
        "Kharaz, Gorham and Salman's alumina sphere on glass at 3.9 m/s: every law that treats "
        f"one frictional planar contact, solved {where} with the benchmarks' e and mu (Hertz's "
        f"stiffness where a law reads one), over the measured points (black).{stepped}",
        fig,
        curves,
    )
    rms = kharaz_curves.rms(curves)
    failures = curves[curves["error"] != ""].groupby("law")["error"].first()
    rms_shown = rms.assign(
        rms=[_rms_mark(row, failures.get(row["law"], "")) for row in rms.to_dict("records")]
    )
    reversal = kharaz_curves.reversal(curves)
    reversal_shown = pd.DataFrame(
        {
            "law": reversal["law"],
            "reverses": [_reverses(value) for value in reversal["reverses"]],
            "lowest contact angle [deg]": [number(a, 90.0) for a in reversal["lowest_angle"]],
            "at incidence [deg]": [number(a) for a in reversal["at_incidence"]],
        }
    )
    return [
        figure,
        Table(
            "kharaz_rms",
            "RMS of predicted minus measured per law, quantity and range (sticking: nominal "
            f"incidence up to {kharaz_curves.STICKING:g} deg; sliding: from "
            f"{kharaz_curves.SLIDING:g} deg), over the points where the law answered.",
            rms_shown,
            rms,
        ),
        Table(
            "kharaz_reversal",
            "Whether each law's contact point leaves the anvil moving backwards (contact angle "
            f"below -{kharaz_curves.REVERSED:g} deg) somewhere in the sticking range, as "
            "measured (down to -8.5 deg at 20 deg): the lowest angle and its incidence. "
            "Finding (Maw, Barber and Fawcett, Wear 38, 1976; Kharaz, Gorham and Salman, "
            "Powder Technology 120, 2001): the contact's tangential compliance stores energy "
            "while it sticks and gives it back reversed, so the laws with tangential springs "
            "reverse and a rigid law with Coulomb friction, which ends a sticking impact at zero "
            "slip, leaves the contact point at rest.",
            reversal_shown,
            reversal,
        ),
    ]


def _reverses(value: Any) -> Mark:
    """The reversal cell: the law's answer, or no answer in the sticking range."""
    if value is None or _blank(value):
        return Mark("no answer", Verdict.NUMERICAL_FAILURE, "no solve of the sticking range")
    return Mark("yes" if value else "no", Verdict.HOLDS, "")


def _rms_mark(row: dict[str, Any], error: str) -> Mark:
    """The RMS cell: holds where every point answered, else the failure and its message."""
    if not row["failed"]:
        return Mark(number(row["rms"]), Verdict.HOLDS, f"{row['points']} points")
    return Mark(number(row["rms"]), _failed(error), f"{row['failed']} points failed: {error}")


def _mode_text(found: Found) -> str:
    if found.quick:
        sample = (
            f"the quick report fits and judges {measured.QUICK} evenly spaced impacts of each "
            "half of each set; a law that reads stiffness (it integrates each impact in time) "
            f"is fitted on {measured.QUICK_COSTLY_FIT} and judged on "
            f"{measured.QUICK_COSTLY_JUDGE} of them within "
            f"{STIFF_QUICK_S:g} s, a budget mark where that is too little; the engines are "
            "fitted in the full report only; Kharaz's curves are drawn at the digitized "
            "incidences only. `lawbench report --full` runs every impact, the engines and the "
            "fine grid"
        )
    else:
        sample = (
            f"every impact of each set (a law that reads stiffness is fitted on "
            f"{measured.COSTLY_FIT} evenly spaced training impacts and judged on every test "
            "impact) and Kharaz's curves on the fine grid"
        )
    return (
        f"Computed in {found.seconds:.0f} s with {found.workers} worker processes, one task "
        f"per set and per law that reads stiffness: {sample}. `lawbench measurements SET "
        "--study` prints one set's study."
    )


def build(ctx: Context) -> Section:
    """The section: each set's ranking and scatter plots, then Kharaz's curves."""
    found = results(ctx)
    blocks: list[Block] = [
        "Each law's contact coefficients fitted on a measured set's training impacts and "
        "judged on its test impacts; the error of an impact is the kinetic norm of the "
        "predicted minus the measured velocity after it, relative to the velocity before. "
        + _mode_text(found),
        *(f"Note: {note}." for note in found.notes),
    ]
    for name, study in found.studies.items():
        if isinstance(study, MeasuredStudy):
            blocks += set_blocks(study, found.sets[name])
        else:
            blocks.append(f"Set `{name}`: the study failed: {study}.")
    if isinstance(found.kharaz, pd.DataFrame):
        blocks += kharaz_blocks(found.kharaz, found.quick)
    else:
        blocks.append(f"Kharaz's curves failed: {found.kharaz}.")
    return Section(ANCHOR, TITLE, blocks)
