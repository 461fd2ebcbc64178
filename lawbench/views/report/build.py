"""Assemble the report: run every study the sections draw, then build the sections and pages.

The studies run once, together, through one executor (`lawbench.views.report.runs.Context.run`);
each section is then a view of their tables. The page opens on the answer
(`lawbench.views.report.answer`): per scene, the law closest to the ground truth and the cheapest
law at each accuracy level, and per measured set the law closest to measurement. Then each
scene, the laws, and the health of the run (`lawbench.views.report.layout`): the headline counts
the *unexplained* cells, numerical failures and budgets of every table and lists each with the
command that reproduces it. A section that fails is kept in the report with its error.
"""

from __future__ import annotations

import json
import platform
import threading
import time
import traceback
from collections.abc import Callable
from importlib.metadata import version
from pathlib import Path
from types import ModuleType
from typing import Any

import matplotlib
import numpy as np
import pandas as pd
import scipy

from lawbench.core.errors import SolverFailure
from lawbench.core.verdicts import Verdict
from lawbench.studies.guard import Guard
from lawbench.views.report import (
    answer,
    dispersion,
    inside,
    measured,
    outcomes,
    paradoxes,
    stability,
    summary,
    sweeps,
    tradeoff,
    yardstick,
)
from lawbench.views.report.config import Config
from lawbench.views.report.layout import arrange
from lawbench.views.report.page import (
    Block,
    Details,
    Figure,
    Section,
    Table,
    save_figure,
    write_page,
)
from lawbench.views.report.runs import Context, label

SECTIONS: tuple[ModuleType, ...] = (
    summary,
    measured,
    outcomes,
    tradeoff,
    stability,
    paradoxes,
    dispersion,
    inside,
    sweeps,
    yardstick,
)
TITLE = "lawbench: impact laws compared"
# Seconds to draw one figure in a worker.
DRAWING_S = 300.0


def _section(module: ModuleType, ctx: Context, failure: Exception | None = None) -> Section:
    """The section ``module`` builds, or the one that says how it failed (``failure``)."""
    try:
        if failure is not None:
            raise failure
        return module.build(ctx)
    except Exception as exc:  # the other sections are still worth writing
        where = traceback.extract_tb(exc.__traceback__)[-1]
        text = (
            f"This section failed: {type(exc).__name__}: {exc} "
            f"(at {Path(where.filename).name}:{where.lineno})."
        )
        return Section(module.ANCHOR, module.TITLE, [text])


def build(out: Path, config: Config) -> Path:
    """Run every study the sections draw with ``config`` and write the report into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    ctx = Context(config, out)
    ctx.run([view for module in SECTIONS for view in module.VIEWS])
    # The measured studies run in their own workers while this process builds the other
    # sections; the measured section is built once they are done.
    measuring = _beside(measured.results, ctx)
    with Guard(config.workers, DRAWING_S) as drawing:
        drawing.start()  # the drawing workers start up while the sections are built
        built = {m.ANCHOR: _section(m, ctx) for m in SECTIONS if m is not measured}
        built[measured.ANCHOR] = _section(measured, ctx, measuring())
        topics = {module.ANCHOR: built[module.ANCHOR] for module in SECTIONS}
        first = answer_blocks(ctx)
        seconds = time.perf_counter() - start
        counts, *lists = headline(ctx)
        health = [counts, *_preamble(ctx, config, seconds), *lists]
        sections = arrange(topics, [case.name for case in ctx.cases], health)
        write_page(out, TITLE, [*first, counts], sections, ctx.rerun, _save(drawing))
    return out


def _beside(function: Callable[..., Any], *args: Any) -> Callable[[], Exception | None]:
    """Start ``function(*args)`` in a thread; return what waits for it and gives its error.

    A daemon thread: a run interrupted meanwhile ends without waiting for it.
    """
    error: list[Exception] = []

    def run() -> None:
        try:
            function(*args)
        except Exception as exc:  # the section says so
            error.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()

    def wait() -> Exception | None:
        thread.join()
        return error[0] if error else None

    return wait


def _save(guard: Guard) -> Any:
    def save(figures: list[Figure], out: Path) -> None:
        """Draw the figures in the workers of ``guard``, all at once."""
        handles = [guard.submit(save_figure, f.figure, f.name, f.data, out) for f in figures]
        for figure, handle in zip(figures, handles, strict=True):
            result = guard.result(handle)
            if result.status != "ok":
                reason = f"{result.error_class or result.status}: {result.error_message}"
                raise SolverFailure(f"figure {figure.name} could not be written: {reason}")

    return save


# The verdicts the headline counts, each with the name of its list and what it asks of a reader.
COUNTED = {
    Verdict.UNEXPLAINED: (
        "unexplained",
        "unexplained",
        "each is a bug to fix or a finding to write",
    ),
    Verdict.NUMERICAL_FAILURE: (
        "numerical_failures",
        "numerical failures",
        "an answer that breaks what its law promises",
    ),
    Verdict.BUDGET: ("budgets", "budgets", "a cell stopped by a budget it names"),
}


def _why(row: dict[str, Any], checks: list[str], verdict: Verdict) -> str:
    if row["error_class"]:
        return f"{row['error_class']}: {row['error_message']}"
    return "; ".join(
        f"{c}: {row[f'{c}_detail']}" for c in checks if row[f"{c}_verdict"] == str(verdict)
    )


def headline(ctx: Context) -> list[Any]:
    """The counts of unexplained cells, numerical failures and budgets, each with its list.

    Every listed cell has the command that reruns it and the exit status that command gives.
    """
    lists: dict[Verdict, list[dict[str, Any]]] = {verdict: [] for verdict in COUNTED}
    for study, table in ctx.every_table():
        table = table.fillna({"error_class": ""})
        checks = study.check_names()
        for row in table[table["repeat"] == 0].to_dict("records"):
            verdict = next((v for v in COUNTED if row["verdict"] == str(v)), None)
            if verdict is None:
                continue
            lists[verdict].append(
                {
                    "study": study.name,
                    "law": row["law"],
                    "scene": row["case"],
                    "cell": label(json.loads(row["params"]), skip=()) or "defaults",
                    "why": _why(row, checks, verdict),
                    "reproducer": row["reproducer"],
                    "exit status": row["exit_status"],
                    "anchor": answer.cell_anchor(row["reproducer"]),
                }
            )
    cells = sum(len(t[t["repeat"] == 0]) for _, t in ctx.every_table())
    counts = ", ".join(
        f"[{len(lists[verdict])} {plural}](#{name})" if lists[verdict] else f"0 {plural}"
        for verdict, (name, plural, _) in COUNTED.items()
    )
    blocks: list[Any] = [
        f"Health of the run: among the {cells} cells of {len(ctx.studies)} studies, {counts}. "
        "Each listed cell "
        "comes with a command that reruns it and exits with the status shown (0 answered, "
        "3 refused, 4 budget or solver failure)."
    ]
    for verdict, (name, _, meaning) in COUNTED.items():
        if lists[verdict]:
            caption = f"Every cell of the report whose verdict is {verdict} ({meaning})."
            frame = pd.DataFrame(lists[verdict])
            table = Table(
                name, caption, frame, commands=("reproducer",), anchors="anchor", hidden=("anchor",)
            )
            blocks.append(table)
    return blocks


def _preamble(ctx: Context, config: Config, seconds: float) -> list[Block]:
    left_out = "; ".join(f"`{name}`: {why}" for name, why in ctx.left_out.items())
    listed = [
        f"Laws: {', '.join(f'`{law.name}`' for law in ctx.laws) or 'none'}. "
        f"Scenes: {', '.join(f'`{case.name}`' for case in ctx.cases) or 'none'}. "
        f"Studies: {', '.join(f'`{s.name}`' for s in ctx.studies) or 'none'} "
        "(`lawbench study NAME` runs one).",
        *([f"Declared studies left out of this page: {left_out}."] if left_out else []),
    ]
    return [
        f"Mode `{config.mode}`: computed in {seconds:.0f} s (before drawing the figures) "
        f"with {config.workers} worker processes (executor `{config.executor}`; wall-clock "
        f"guard {config.budget_s:g} s per cell). Rerun: `{ctx.rerun}`.",
        f"lawbench {version('lawbench')}, Python {platform.python_version()}, numpy "
        f"{np.__version__}, scipy {scipy.__version__}, matplotlib {matplotlib.__version__}.",
        *dict.fromkeys(f"Note: {note}." for note in ctx.notes),
        Details(
            f"The {len(ctx.laws)} laws, {len(ctx.cases)} scenes and {len(ctx.studies)} "
            "studies of this run, and the declared studies left out: show",
            listed,
        ),
    ]


def answer_blocks(ctx: Context) -> list[Block]:
    """The page's first screen: the answer table, one row per scene and per measured set."""
    rows, aside = [], 0
    for case, data, _ in tradeoff.scenes(ctx):
        costs = answer.retime(case, data)
        rows.append(answer.scene_row(case, data, costs, f"scene-{case.name}"))
        aside += len(answer.set_aside(data))
    for name, text in measured.closest_per_set(ctx).items():
        rows.append(
            {
                "scene": f"set [{name}](#{measured.ANCHOR})",
                "ground truth": "measured impacts (closest to measurement: held-out error)",
                "closest law, model error": text,
            }
        )
    if not rows:
        return ["No speed/accuracy study and no measurement set ran: no answer to give."]
    levels = ", ".join(f"{level:g}" for level in answer.LEVELS)
    return [
        f"Model error = {answer.ERROR}: the distance from the scene's ground truth relative to "
        f"the largest pre-impact speed; the accuracy levels are {levels}.",
        Table("answer", answer.caption(aside), pd.DataFrame(rows).fillna("")),
    ]
