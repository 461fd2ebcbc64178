"""The answer on the page's first screen: per scene, which law comes closest and which is cheapest.

A view of the speed/accuracy studies (`lawbench.views.report.tradeoff.points`). Per scene, the
ground truth it declares, the law closest to it with its *model error*
``max |v+ - v_truth| / max |v-|`` (relative, the speed/accuracy section's definition), and the
cheapest law whose model error is within each level of `LEVELS`, with its cost, and each engine's
model error at its default settings (`at_defaults`); per measured
set, the law closest to the measurements (`lawbench.views.report.measured.closest_law`).

Only a cell whose verdict is *holds* or *law property* is recommended: a cell whose verdict is a
numerical failure, a budget or unexplained is set aside, counted and linked to its line in the
health of the run. A cost is the shortest of `TIMINGS` timed solves after `WARM_UPS` warm-up
solve (`retime`): the load of a shared machine only ever adds time, so the shortest is the
steadiest estimate, and one wall-clock sample per cell made two runs choose differently.

The choice (`choose`) leans on the clock as little as it can. Of one law's settings of a
numeric accuracy knob (a tolerance, a time step: the larger, the looser) that reach a level,
only the loosest competes: a tighter setting does the same work and more, so only timing noise
could make it look cheaper. Between laws, costs within a factor `TIE` of the cheapest are a
tie, broken without the clock: the loosest setting first (a law without a knob counts as the
loosest), then the law's name.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from typing import Any

import pandas as pd

from lawbench.bench.timing import duration
from lawbench.core.case import Case
from lawbench.core.law import LAWS
from lawbench.core.trial import solve
from lawbench.core.verdicts import Verdict

LEVELS = (1e-2, 1e-4, 1e-6)
RECOMMENDABLE = frozenset({str(Verdict.HOLDS), str(Verdict.LAW_PROPERTY)})
SET_ASIDE = (Verdict.NUMERICAL_FAILURE, Verdict.BUDGET, Verdict.UNEXPLAINED)
WARM_UPS, TIMINGS = 1, 5
# Costs within this factor of the cheapest are one tie: the spread of repeated timings of one
# cell on a shared two-core machine.
TIE = 1.5
# A cell whose one study sample took longer than this is not timed again (its sample is its
# cost): it is far from the cheapest at every level the quick report reaches.
RETIME_S = 0.2
ERROR = "max |v+ - v_truth| / max |v-|"


def cell_anchor(reproducer: str) -> str:
    """The anchor of a cell's line in the health of the run, from the command that reruns it."""
    return "cell-" + hashlib.sha1(reproducer.encode()).hexdigest()[:12]


def candidates(data: pd.DataFrame) -> pd.DataFrame:
    """The points that may be recommended: laws under test, answered, holding, with an error."""
    known = data["candidate"] & (data["failure"] == "") & data["model_error"].notna()
    return data[known & data["verdict"].isin(RECOMMENDABLE)]


def set_aside(data: pd.DataFrame) -> pd.DataFrame:
    """The points of laws under test whose verdict keeps them from any recommendation."""
    return data[data["candidate"] & data["verdict"].isin([str(v) for v in SET_ASIDE])]


def retime(case: Case, data: pd.DataFrame) -> pd.Series:
    """The cost of each candidate point within the loosest level: shortest of repeated solves.

    `WARM_UPS` round of solves, then `TIMINGS` timed rounds, each point solved once a round (a
    burst of load on the machine slows every point alike), each time the law's own wall time
    (``diagnostics['wall_time_s']``). A point slower than `RETIME_S` in its study keeps its
    study cost. Indexed like ``data``; NaN for the points that are not candidates.
    """
    costs = pd.Series(float("nan"), index=data.index)
    chosen = candidates(data)
    chosen = chosen[chosen["model_error"].astype(float) <= max(LEVELS)]
    slow = chosen["wall_time_s"] > RETIME_S
    costs[chosen.index[slow]] = chosen.loc[slow, "wall_time_s"]
    cells = {
        index: (row["law"], json.loads(row["options"]), json.loads(row["params"]))
        for index, row in chosen[~slow].iterrows()
    }
    samples: dict[Any, list[float]] = {index: [] for index in cells}
    for repeat in range(WARM_UPS + TIMINGS):
        for index, (law, options, params) in cells.items():
            seconds = solve(law, case, options, **params).diagnostics["wall_time_s"]
            if repeat >= WARM_UPS:
                samples[index].append(seconds)
    for index, found in samples.items():
        costs[index] = min(found)
    return costs


def _looseness(row: pd.Series) -> tuple[float, str, str]:
    """The clock-free order of a tie: loosest tolerance first, then the law's name."""
    value = row["value"]
    return (-float(value) if _numeric(value) else -float("inf"), row["law"], str(value))


def _numeric(value: object) -> bool:
    """Whether a knob's value orders by looseness: a number, not a choice such as an ordering."""
    return isinstance(value, int | float) and not isinstance(value, bool) and value == value


def _loosest_per_law(found: pd.DataFrame) -> pd.DataFrame:
    """Of each law's points on a numeric knob, only the loosest; every other point as it is."""
    numeric = found["value"].map(_numeric)
    keep = found.loc[numeric, "value"].astype(float).groupby(found.loc[numeric, "law"]).idxmax()
    return found[~numeric | found.index.isin(keep)]


def choose(data: pd.DataFrame, costs: pd.Series, level: float) -> pd.Series | None:
    """The recommended point within ``level``: the loosest of those within `TIE` of the cheapest.

    Only each law's loosest numeric setting that reaches ``level`` competes. None when no
    candidate point reaches ``level``.
    """
    found = candidates(data)
    found = found[(found["model_error"].astype(float) <= level) & costs[found.index].notna()]
    if found.empty:
        return None
    found = _loosest_per_law(found)
    cost = costs[found.index]
    tied = found[cost <= TIE * cost.min()]
    order = sorted(tied.index, key=lambda i: _looseness(tied.loc[i]))
    return tied.loc[order[0]]


def closest(data: pd.DataFrame) -> pd.Series | None:
    """The candidate point with the smallest model error; a tie goes to the loosest, by name."""
    found = candidates(data)
    if found.empty:
        return None
    error = found["model_error"].astype(float)
    tied = found[error == error.min()]
    return tied.loc[sorted(tied.index, key=lambda i: _looseness(tied.loc[i]))[0]]


def point_text(row: pd.Series) -> str:
    """``law (knob=value)`` of a point."""
    if not row["knob"]:
        return str(row["law"])
    value = row["value"]
    shown = f"{value:g}" if isinstance(value, int | float) else str(value)
    return f"{row['law']} ({row['knob']}={shown})"


def choices(data: pd.DataFrame, costs: pd.Series) -> dict[str, str]:
    """Per column of the answer, the recommended point's ``law (knob=value)``, or 'none'."""
    found = {"closest": closest(data)}
    found |= {f"within {level:g}": choose(data, costs, level) for level in LEVELS}
    return {key: "none" if row is None else point_text(row) for key, row in found.items()}


def at_defaults(data: pd.DataFrame) -> str:
    """Each engine's model error at its default options, and the tightest level it is within.

    An engine (`Law.engine`) runs in the speed/accuracy study at its default settings, what a
    user gets; its point whose options are all the law's defaults is the one shown. On a scene
    that declares no geometry every engine refuses, and no engine answered.
    """
    shown = []
    for _, row in data[data["model_error"].notna()].iterrows():
        law = LAWS.get(row["law"]) if row["law"] in LAWS.names() else None
        if law is None or not law.engine:
            continue
        defaults = law.option_values()
        if any(defaults.get(k) != v for k, v in json.loads(row["options"]).items()):
            continue
        error = float(row["model_error"])
        within = [level for level in LEVELS if error <= level]
        reached = f"within {min(within):g}" if within else f"none within {max(LEVELS):g}"
        shown.append(f"{row['law']} {error:.2g} ({reached})")
    return ", ".join(shown) or "no engine answered"


def scene_row(case: Case, data: pd.DataFrame, costs: pd.Series, anchor: str) -> dict[str, Any]:
    """The answer's row of one scene: truth, closest law, cheapest per level, set-aside cells."""
    truth = case.ground_truth
    best = closest(data)
    near = "none" if best is None else f"{point_text(best)}, error {float(best['model_error']):.2g}"
    row: dict[str, Any] = {
        "scene": f"[{case.name}](#{anchor})",
        "ground truth": truth.describe() if truth else "none declared",
        "closest law, model error": near,
    }
    for level in LEVELS:
        chosen = choose(data, costs, level)
        row[f"cheapest with model error ≤ {level:g}"] = (
            "none" if chosen is None else f"{point_text(chosen)}, {duration(costs[chosen.name])}"
        )
    row["engines at their defaults, model error"] = at_defaults(data)
    aside = set_aside(data)
    row["set aside"] = ", ".join(
        f"[{point_text(r)}](#{cell_anchor(r['reproducer'])}): {r['verdict']}"
        for _, r in aside.iterrows()
    )
    return row


def caption(aside: int, levels: Sequence[float] = LEVELS) -> str:
    """The answer's caption: the levels, the cost, the tie rule, the cells set aside."""
    shown = " / ".join(f"{level:g}" for level in levels)
    return (
        f"Per scene, the law closest to its ground truth and the cheapest law whose model "
        f"error {ERROR} (relative to the largest pre-impact speed, as in the speed/accuracy "
        f"section) is within {shown}. Cost: the shortest of {TIMINGS} timed solves after "
        f"{WARM_UPS} warm-up solve, in rounds over the scene's cells (a cell slower than "
        f"{RETIME_S:g} s in its study: that one solve). Of one law's tolerances or time steps "
        "that reach a level, only the loosest competes. Costs within {TIE:g}x of the "
        "cheapest are a tie, broken by the loosest tolerance (a law without a knob first), "
        "then the law's name. An engine at its default settings (what a user gets) is shown "
        "with its model error and the tightest level it reaches. Only cells that hold "
        f"(verdict holds or law property) are recommended: {aside} cells were set aside "
        "(numerical failure, budget or unexplained), each linked to its line in the health "
        "of the run."
    )
