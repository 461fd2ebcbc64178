"""What a report runs: the grids of each section, in a quick and a full preset.

``quick`` (the default) runs small grids in guarded worker processes and finishes in a few
minutes on two cores; ``full`` runs the large grids through `lawbench.runner.run` (resumable,
on local processes or a Dask cluster). A test may shrink a preset with `dataclasses.replace`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from lawbench.errors import InvalidProblem

MODES = ("quick", "full")


def _decades(start: int, stop: int, step: int = 1) -> tuple[float, ...]:
    """Powers of ten ``10**start ... 10**stop`` (both included) every ``step`` decades."""
    return tuple(float(10.0**k) for k in range(start, stop + np.sign(step), step))


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
        Wall-clock budget of one task (a solve with its checks), in seconds.
    executor : str
        'guard' runs the grids in the guarded workers; 'serial', 'processes' or 'dask' runs
        them through `lawbench.runner.run`, resumable from ``OUT/runs``.
    address : str or None
        Dask scheduler address (executor 'dask'); None starts a local cluster.
    laws, cases : tuple of str or None
        Restrict the report to these laws and scenes; None for every registered one.
    summary_continuity_sizes : tuple of float
        Perturbation sizes of the continuity check in the summary matrix.
    tradeoff_cases : tuple of str or None
        Scenes of the speed/accuracy study; None for every scene.
    knob_values : tuple of float
        Values a numeric accuracy knob is swept over (those its spec accepts).
    reference_knob : float
        The tightest value of a numeric knob: the compliant reference's tol, and a law's own
        reference when the compliant model cannot treat the scene.
    repeats : int
        Solves per point of the speed/accuracy study (the median wall time is kept).
    stiffness_ratios, mass_ratios, grazing_speeds : tuple of float
        Extremes of the stability grid.
    chain_lengths : tuple of int
        Ball counts of the long chains.
    restitutions, frictions : tuple of float
        Values of e and mu crossed with the extremes.
    stiffness_cases, grazing_cases, redundant_cases : tuple of str
        Scenes of the stiffness sweep, the grazing approaches and the duplicated contacts.
    map_points : int
        Points per axis of the energy-increase maps.
    share_ratios : tuple of float
        Stiffness ratios of the energy-share sweep.
    jump_sizes : tuple of float
        Perturbation sizes of the continuity study.
    """

    mode: str
    workers: int
    budget_s: float
    executor: str
    address: str | None = None
    laws: tuple[str, ...] | None = None
    cases: tuple[str, ...] | None = None
    summary_continuity_sizes: tuple[float, ...] = (1e-6,)
    tradeoff_cases: tuple[str, ...] | None = None
    knob_values: tuple[float, ...] = _decades(-2, -10, -2)
    reference_knob: float = 1e-12
    repeats: int = 3
    stiffness_ratios: tuple[float, ...] = _decades(-8, 8, 4)
    mass_ratios: tuple[float, ...] = _decades(-6, 6, 3)
    grazing_speeds: tuple[float, ...] = _decades(-4, -12, -4)
    chain_lengths: tuple[int, ...] = (100,)
    restitutions: tuple[float, ...] = (0.0, 1.0)
    frictions: tuple[float, ...] = (0.0, 1e3)
    stiffness_cases: tuple[str, ...] = ("three_ball_chain",)
    grazing_cases: tuple[str, ...] = ("three_ball_chain", "falling_rod")
    redundant_cases: tuple[str, ...] = ("three_ball_chain", "falling_rod")
    map_points: int = 7
    share_ratios: tuple[float, ...] = _decades(-3, 3)
    jump_sizes: tuple[float, ...] = _decades(-2, -6, -1)

    def rerun(self, out: str) -> str:
        """The command that writes this report again."""
        return f"lawbench report --{self.mode} --out {out}"


QUICK = Config(
    mode="quick",
    workers=2,
    budget_s=60.0,
    executor="guard",
    tradeoff_cases=("three_ball_chain", "lamina", "bead_column", "falling_rod"),
)

FULL = Config(
    mode="full",
    workers=os.cpu_count() or 2,
    budget_s=600.0,
    executor="processes",
    summary_continuity_sizes=(1e-2, 1e-4, 1e-6),
    knob_values=_decades(-1, -11),
    repeats=5,
    stiffness_ratios=_decades(-8, 8),
    mass_ratios=_decades(-6, 6),
    grazing_speeds=_decades(0, -12, -1),
    chain_lengths=(10, 100, 1000),
    stiffness_cases=("three_ball_chain", "two_balls_wall"),
    grazing_cases=("three_ball_chain", "two_balls_wall", "falling_rod", "sphere_wall", "lamina"),
    redundant_cases=("three_ball_chain", "two_balls_wall", "falling_rod", "lamina"),
    map_points=41,
    share_ratios=tuple(np.logspace(-3, 3, 25).tolist()),
    jump_sizes=_decades(-1, -8, -1),
)


def preset(mode: str) -> Config:
    """The configuration of ``mode`` ('quick' or 'full')."""
    if mode not in MODES:
        raise InvalidProblem(f"report mode {mode!r}: must be one of {', '.join(MODES)}")
    return QUICK if mode == "quick" else FULL
