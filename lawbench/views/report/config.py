"""What a report runs: the mode, the workers, the guard, and what to restrict it to.

The report knows no scene or law by name: it runs every registered study that a section draws,
the section chosen here from what the study is (its shape, `Study.shape`: `VIEWS`), sized for
the mode: ``quick`` (the default: each study as declared with its
``quick`` replacements, where the engines and the laws that integrate the impact in time take
the first value of each swept axis of the speed/accuracy and stability studies, their accuracy
knob at its default; slow ones left
out; a few minutes on two cores) or ``full`` (each study's ``full`` sizes, slow ones in,
resumable from ``OUT/runs``, on local processes or a Dask cluster). A test may shrink a preset
with `dataclasses.replace`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

from lawbench.core.errors import InvalidProblem

if TYPE_CHECKING:
    from lawbench.studies.study import Study

MODES = ("quick", "full")
# Which view of a section draws a study, by the study's shape (`lawbench.studies.declared.SHAPES`;
# the stability grid's grazing, duplicated-contact and friction axes are ``extremes``).
VIEWS = {
    "summary": "summary",
    "speed_accuracy": "tradeoff",
    "extremes": "stability",
    "energy_map": "paradoxes",
    "energy_shares": "dispersion",
    "continuity": "continuity",
    "impact_path": "inside",
    "impact_paths": "inside",
    "sweep": "sweep",
    "table_path": "table_path",
    "yardstick": "yardstick",
}


def view(study: Study) -> str | None:
    """The view that draws ``study`` (a name a section asks `Context.tables` for); None for none."""
    return VIEWS.get(study.shape or "")


@dataclass(frozen=True)
class Config:
    """Settings of one report.

    Attributes
    ----------
    mode : str
        'quick' or 'full' (named in the captions' rerun commands).
    workers : int
        Worker processes.
    budget_s : float
        Wall-clock guard of one cell (a solve with its checks and measures), in seconds.
    executor : str
        'serial', 'processes' or 'dask' (`lawbench.studies.runner.Executor`).
    address : str or None
        Dask scheduler address (executor 'dask'); None starts a local cluster.
    laws, cases : tuple of str or None
        Restrict every study to these laws and scenes; None for every registered one.
    studies : tuple of str or None
        Run only these studies; None for every study a section draws.
    measurements : tuple of str or None
        Judge the laws on these measurement sets only; None for every registered one.
    """

    mode: str
    workers: int
    budget_s: float
    executor: str = "processes"
    address: str | None = None
    laws: tuple[str, ...] | None = None
    cases: tuple[str, ...] | None = None
    studies: tuple[str, ...] | None = None
    measurements: tuple[str, ...] | None = None

    def rerun(self, out: str) -> str:
        """The command that writes this report again."""
        return f"lawbench report --{self.mode} --out {out}"


# Quick: five seconds a cell, twice the longest cell the quick studies answer on two cores, so
# that a cell the laws cannot answer fast does not hold the page.
QUICK = Config(mode="quick", workers=2, budget_s=5.0)
FULL = Config(mode="full", workers=os.cpu_count() or 2, budget_s=600.0)


def preset(mode: str) -> Config:
    """The configuration of ``mode`` ('quick' or 'full')."""
    if mode not in MODES:
        raise InvalidProblem(f"report mode {mode!r}: must be one of {', '.join(MODES)}")
    return QUICK if mode == "quick" else FULL
