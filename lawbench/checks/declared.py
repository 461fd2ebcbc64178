"""Studies as declared: the registry `STUDIES`, and the shapes laws and scenes declare theirs with.

A scene (or law) module calls these to register its studies: which scenes enter the speed and
accuracy comparison, which extremes its stability grid pushes, which two parameters its
energy-increase map spans, and so on. Each returns a plain `Study` whose ``view`` names the
report section that draws it. The engine's own study is ``summary``: every law on every scene
at its defaults, with every check.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from lawbench.checks import CHECKS, SINGLE_SOLVE, measures
from lawbench.checks.study import Measure, Study
from lawbench.core.case import CASES
from lawbench.core.law import LAWS
from lawbench.core.registry import Registry

# Accuracy knob values of the speed/accuracy sweep (quick; the full report sweeps every decade).
KNOBS = (1e-2, 1e-6, 1e-10)
# Perturbation sizes of the continuity sweep (quick and full).
JUMP_SIZES = (1e-2, 1e-4, 1e-6)
FULL_JUMP_SIZES = tuple(10.0**-k for k in range(1, 9))


def decades(start: int, stop: int, step: int = 1) -> list[float]:
    """Powers of ten ``10**start ... 10**stop`` (both included) every ``step`` decades."""
    return [float(10.0**k) for k in range(start, stop + int(np.sign(step)), step)]


def speed_accuracy(case: str, slow: bool = False) -> Study:
    """Every law on ``case`` at its defaults, its accuracy knob swept.

    Cost, model error and numerical error (`lawbench.checks.measures`), one solve per point (the
    median of five in the full report).
    """
    return Study(
        name=f"{case}_speed_accuracy",
        title=f"cost, model error and numerical error of every law on {case} at its defaults, "
        "each law's accuracy knob swept",
        cases=(case,),
        knobs=KNOBS,
        measures={
            "model_error": measures.model_error,
            "numerical_error": measures.numerical_error,
        },
        view="tradeoff",
        slow=slow,
        full={"knobs": decades(-1, -11, -1), "repeats": 5},
    )


def extremes(
    name: str,
    title: str,
    case: str,
    axis: str,
    grid: Mapping[str, Sequence[Any]] | None = None,
    params: Mapping[str, Any] | None = None,
    transform: str | None = None,
    values: Sequence[float] = (),
    laws: tuple[str, ...] | str = "covering",
    measures: Mapping[str, Measure] | None = None,
    full: Mapping[str, Any] | None = None,
    slow: bool = False,
) -> Study:
    """One axis of the stability grid: every law on ``case`` pushed along ``axis``.

    ``axis`` is a grid parameter, a measure, or ``transform``; every single-solve check
    decides the cells.
    """
    return Study(
        name=name,
        title=title,
        cases=(case,),
        laws=laws,
        grid=dict(grid or {}),
        params=dict(params or {}),
        transform=transform,
        transform_values=tuple(values),
        measures=dict(measures or {}),
        axes=(axis,),
        view="stability",
        full=dict(full or {}),
        slow=slow,
    )


def grazing(
    case: str,
    e: Sequence[Any],
    values: Sequence[float] = tuple(decades(-4, -12, -4)),
    slow: bool = False,
) -> Study:
    """Every law on ``case`` with its approach made grazing, for each restitution of ``e``.

    Fastest approach at each of ``values`` (m/s; every decade from 1 to 1e-12 in the full
    report), the motion the contacts do not see kept (`lawbench.core.transforms.grazing`).
    """
    return extremes(
        f"{case}_grazing",
        "grazing speed [m/s]",
        case,
        "transform",
        grid={"e": list(e)},
        transform="grazing",
        values=values,
        full={"transform_values": decades(0, -12, -1)},
        slow=slow,
    )


def duplicated_contact(case: str, e: Sequence[Any], slow: bool = False) -> Study:
    """Every law on ``case`` with its contact 0 given twice, for each restitution of ``e``."""
    return extremes(
        f"{case}_duplicated",
        "contact 0 given twice",
        case,
        "transform",
        grid={"e": list(e)},
        transform="duplicated",
        values=(0,),
        slow=slow,
    )


def large_friction(case: str) -> Study:
    """Every law on ``case`` at mu = 0 and mu = 1000, each with e = 0 and e = 1."""
    return extremes(
        f"{case}_friction",
        "friction coefficient mu",
        case,
        "mu",
        grid={"mu": [0.0, 1e3], "e": [0.0, 1.0]},
    )


def energy_map(
    case: str,
    x: tuple[str, float, float],
    y: tuple[str, float, float],
    params: Mapping[str, Any] | None = None,
    points: int = 4,
    full_points: int = 41,
) -> Study:
    """The energy change of every law on ``case`` over two parameters.

    Each axis is ``(name, first, last)``; the energy-gain check decides each cell.
    """

    def grid(count: int) -> dict[str, list[float]]:
        return {a[0]: np.linspace(a[1], a[2], count).tolist() for a in (y, x)}

    return Study(
        name=f"{case}_energy_map",
        title=f"energy change dT/T- of every law on {case} over {x[0]} and {y[0]}",
        cases=(case,),
        grid=grid(points),
        params=dict(params or {}),
        checks=("energy_gain",),
        axes=(x[0], y[0]),
        view="paradoxes",
        full={"grid": grid(full_points)},
    )


def energy_shares(
    case: str, ratios: Sequence[float], full_ratios: Sequence[float], name: str | None = None
) -> Study:
    """The energy shares per body of every law on ``case`` over its stiffness ratio.

    The dispersion check (against the scene's ground truth) decides each cell.
    """
    return Study(
        name=name or f"{case}_energy_shares",
        title=f"share of the post-impact kinetic energy per body on {case} over the stiffness "
        "ratio of its contacts",
        cases=(case,),
        grid={"stiffness_ratio": list(ratios)},
        measures={
            "energy_shares": measures.energy_shares,
            "dispersion_index": measures.dispersion_index,
        },
        checks=("energy_gain", "dispersion"),
        axes=("stiffness_ratio",),
        view="dispersion",
        full={"grid": {"stiffness_ratio": list(full_ratios)}},
    )


def continuity(case: str) -> Study:
    """Outcome jumps of every law on ``case`` under vanishing perturbations.

    Of the gaps and of the velocities; the continuity check decides each cell.
    """
    return Study(
        name=f"{case}_continuity",
        title=f"outcome jump of every law on {case} under vanishing perturbations of the gaps "
        "and velocities",
        cases=(case,),
        measures={"jumps": measures.continuity_jumps},
        checks=("continuity",),
        settings={"continuity_sizes": list(JUMP_SIZES)},
        view="continuity",
        full={"settings": {"continuity_sizes": list(FULL_JUMP_SIZES)}},
    )


def impact_path(law: str, case: str, title: str, params: Mapping[str, Any] | None = None) -> Study:
    """What happens inside one impact of ``law`` on ``case`` (the option ``path``)."""
    return Study(
        name=f"{law}_path",
        title=title,
        cases=(case,),
        laws=(law,),
        params=dict(params or {}),
        options={law: {"path": [True]}},
        measures={"path": measures.impact_path},
        view="inside",
    )


def impact_paths(
    name: str,
    title: str,
    laws: tuple[str, ...],
    case: str,
    axis: str,
    values: Sequence[Any],
    quantities: Sequence[str],
    extra: Mapping[str, Measure] | None = None,
) -> Study:
    """Each of ``laws`` on ``case`` at each of ``values`` of the parameter ``axis`` (``path``).

    The report draws the path's ``quantities`` (keys of `lawbench.core.outcome.Outcome.path`) of
    every cell side by side, one row of panels per law; ``extra`` measures join the table.
    """
    return Study(
        name=name,
        title=title,
        cases=(case,),
        laws=tuple(laws),
        grid={axis: list(values)},
        options={law: {"path": [True]} for law in laws},
        measures={"path": measures.impact_path, **dict(extra or {})},
        checks=("energy_gain",),
        axes=(axis, *quantities),
        view="inside",
    )


class _Studies(Registry[Study]):
    """Studies are declared in the law and case modules: loading them loads both packages.

    The engine's own study (``summary``) is declared below.
    """

    def _load(self) -> None:
        if self._loaded:
            return
        LAWS.names()
        CASES.names()
        self._loaded = True


STUDIES: _Studies = _Studies("study", "lawbench.cases", Study)


STUDIES.register(
    Study(
        name="summary",
        title="every law on every scene at its defaults, with every check",
        laws="every",
        checks=(*SINGLE_SOLVE, *(name for name in CHECKS if name not in SINGLE_SOLVE)),
        settings={"continuity_sizes": [1e-6]},
        measures={
            "model_error": measures.model_error,
            "truth_velocity": measures.truth_velocity,
        },
        view="summary",
        full={"settings": {"continuity_sizes": [1e-2, 1e-4, 1e-6]}},
    )
)
