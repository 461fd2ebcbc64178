"""Assemble the report: start every section's runs, then build the sections and the pages.

Every section first submits its work (so both workers stay busy across sections), then builds
its tables and figures. A section that fails is kept in the report with its error.
"""

from __future__ import annotations

import platform
import time
import traceback
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import ModuleType

import matplotlib
import numpy as np
import scipy

import lawbench
from lawbench.guard import Guard
from lawbench.report import (
    dispersion,
    inside,
    outcomes,
    paradoxes,
    stability,
    summary,
    tradeoff,
)
from lawbench.report.config import Config
from lawbench.report.page import Figure, Section, save_figure, write_page
from lawbench.report.runs import Context

SECTIONS: tuple[ModuleType, ...] = (
    summary,
    outcomes,
    tradeoff,
    stability,
    paradoxes,
    dispersion,
    inside,
)
TITLE = "lawbench: impact laws compared"


def _failed(module: ModuleType, exc: Exception) -> Callable[[], Section]:
    where = traceback.extract_tb(exc.__traceback__)[-1]
    text = (
        f"This section failed: {type(exc).__name__}: {exc} "
        f"(at {Path(where.filename).name}:{where.lineno})."
    )
    return lambda: Section(module.ANCHOR, module.TITLE, [text])


def _finish(module: ModuleType, finish: Callable[[], Section]) -> Section:
    try:
        return finish()
    except Exception as exc:  # the other sections are still worth writing
        return _failed(module, exc)()


def build(out: Path, config: Config) -> Path:
    """Run every section with ``config`` and write the report into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    runs = out / "runs"
    if config.executor != "guard" and runs.is_dir():
        # Finished grids of an earlier report are recomputed; interrupted ones resume.
        for table in runs.glob("*.parquet"):
            table.unlink()
    start = time.perf_counter()
    with Guard(config.workers, config.budget_s) as guard:
        ctx = Context(config, out, guard)
        finishers = []
        for module in SECTIONS:
            try:
                finishers.append((module, module.start(ctx)))
            except Exception as exc:  # a section that cannot start is reported
                finishers.append((module, _failed(module, exc)))
        sections = [_finish(module, finish) for module, finish in finishers]
        seconds = time.perf_counter() - start
        preamble = _preamble(ctx, config, seconds)
        write_page(out, TITLE, preamble, sections, ctx.rerun, partial(_save, guard))
    return out


def _save(guard: Guard, figures: list[Figure], out: Path) -> None:
    """Render the figures in the workers, both at once."""
    handles = [guard.submit(save_figure, f.figure, f.name, f.data, out) for f in figures]
    for figure, handle in zip(figures, handles, strict=True):
        result = guard.result(handle)
        if result.status != "ok":
            reason = f"{result.error_class or result.status}: {result.error_message}"
            raise RuntimeError(f"figure {figure.name} could not be written: {reason}")


def _preamble(ctx: Context, config: Config, seconds: float) -> list[str]:
    return [
        f"Mode `{config.mode}`: computed in {seconds:.0f} s (before drawing the figures) "
        f"with {config.workers} worker processes (budget {config.budget_s:g} s per solve), "
        f"executor `{config.executor}`. "
        f"Rerun: `{ctx.rerun}`.",
        f"Laws: {', '.join(f'`{law.name}`' for law in ctx.laws) or 'none'}. "
        f"Scenes: {', '.join(f'`{case.name}`' for case in ctx.cases) or 'none'}.",
        f"lawbench {lawbench.__version__}, Python {platform.python_version()}, numpy "
        f"{np.__version__}, scipy {scipy.__version__}, matplotlib {matplotlib.__version__}.",
        *(f"Note: {note}." for note in ctx.notes),
    ]
