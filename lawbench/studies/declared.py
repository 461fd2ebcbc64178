"""Studies as declared: the shapes laws and scenes declare theirs with, and the registry `STUDIES`.

A scene (or a law) declares its studies as plain data, in its class attribute ``studies``: one
mapping per study, its ``shape`` (a key of `SHAPES`) and the shape's arguments, such as
``{"shape": "speed_accuracy"}`` (every law on the scene, its accuracy knob swept),
``{"shape": "extremes", "name": "stiffness", "title": ..., "axis": ..., "grid": ...}`` (one
axis of the stability grid), or a study written out field by field, ``{"shape": "sweep",
"name": ..., "title": ..., "grid": ..., "measures": {"omega_ratio": omega_ratio}}`` whose
measures are module-level functions of the scene. The scene's name (the law's, in a law's
declaration) is filled in where a shape needs it: a scene never repeats it. `STUDIES` builds
every `Study` from its declaration the first time studies are listed, looked up or run, so
importing a scene or a law, or solving one, builds none. The engine's own study is
``summary``: every law on every scene at its defaults, with every check.

A study keeps the name of its shape (`Study.shape`): the report's configuration chooses the
section that draws it from that (`lawbench.views.report.config`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from functools import partial
from typing import Any

import numpy as np

from lawbench.checks import CHECKS, ON_REQUEST, SINGLE_SOLVE, measures
from lawbench.checks.knobs import decades
from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.core.registry import Registry
from lawbench.studies.study import Measure, Study

# Accuracy knob values of the speed/accuracy sweep (quick; the full report sweeps every decade).
KNOBS = (1e-2, 1e-6, 1e-10)
# Values of each swept axis a law that follows the impact through time (an engine, or a law that
# integrates the compliant impact: `lawbench.studies.study.costly`) is given in the quick report's
# speed/accuracy and stability studies (`lawbench.studies.study.evenly`: one is an axis's first
# value), with its accuracy knob at its default; the full report gives it every value. Two would
# keep each axis's last value, the extreme where such a law runs until the quick report's
# wall-clock guard stops it (a step of 1e-10 s, a grazing speed of 1e-12 m/s, mu = 1000): a third
# or more of the quick report's time for cells whose answer is that they are out of budget.
QUICK_COSTLY_POINTS = 1
QUICK_COSTLY = {"costly_points": QUICK_COSTLY_POINTS}
# Perturbation sizes of the continuity sweep (quick and full). The verdict reads the smallest;
# the quick report shows one larger size beside it, each size costing every law on the scene
# m + 3 solves again (a third of the laws' work in the quick continuity studies per size).
JUMP_SIZES = (1e-2, 1e-6)
FULL_JUMP_SIZES = tuple(10.0**-k for k in range(1, 9))


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
        shape="speed_accuracy",
        slow=slow,
        full={"knobs": decades(-1, -11, -1), "repeats": 5},
        # The numerical error of a law thinned to its default knob needs its tightest setting,
        # the costliest solve of its sweep: measured in the full report, but for the ground
        # truth's model, whose convergence the figure shows.
        quick={**QUICK_COSTLY, "costly_measures": ("model_error",)},
    )


def extremes(
    case: str,
    name: str,
    title: str,
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

    The study is called after the scene and ``name`` (``three_ball_chain_stiffness``).
    ``axis`` is a grid parameter, a measure, or ``transform``; every single-solve check decides
    the cells.
    """
    return Study(
        name=f"{case}_{name}",
        title=title,
        cases=(case,),
        laws=laws,
        grid=dict(grid or {}),
        params=dict(params or {}),
        transform=transform,
        transform_values=tuple(values),
        measures=dict(measures or {}),
        axes=(axis,),
        shape="extremes",
        full=dict(full or {}),
        quick=QUICK_COSTLY,
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
        case,
        "grazing",
        "grazing speed [m/s]",
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
        case,
        "duplicated",
        "contact 0 given twice",
        "transform",
        grid={"e": list(e)},
        transform="duplicated",
        values=(0,),
        slow=slow,
    )


def large_friction(case: str) -> Study:
    """Every law on ``case`` at mu = 0 and mu = 1000, each with e = 0 and e = 1."""
    return extremes(
        case,
        "friction",
        "friction coefficient mu",
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
        shape="energy_map",
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
        shape="energy_shares",
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
        shape="continuity",
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
        shape="impact_path",
    )


def impact_paths(
    case: str,
    name: str,
    title: str,
    laws: tuple[str, ...],
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
        shape="impact_paths",
    )


def custom(shape: str, case: str, name: str, title: str, **fields: Any) -> Study:
    """A study on ``case`` written out field by field (the other fields of `Study`).

    ``shape`` says what it is for the report: ``sweep`` (measures against one grid parameter)
    or ``table_path`` (a ball's path on the table per value of its parameter).
    """
    return Study(name=name, title=title, cases=(case,), shape=shape, **fields)


def yardstick(law: str, options: Mapping[str, Any], repeats: int = 2) -> Study:
    """``law`` with ``options`` on every scene, against the scene's ground-truth model.

    The ``yardstick`` check decides each cell (`lawbench.checks.yardstick`); the model's own
    distance and wall time are measured beside it. Each cell is solved ``repeats`` times, so
    that a cost can be read after a warm-up (an engine's first solve in a process loads it).
    A slow study: an engine that integrates every impact in time takes seconds per scene.
    """
    return Study(
        name=f"{law}_yardstick",
        title=f"{law} ({', '.join(f'{k}={v}' for k, v in options.items())}) against each "
        "scene's ground-truth model: the yardstick checked by an independent engine",
        laws=(law,),
        options={law: {name: [value] for name, value in options.items()}},
        checks=("yardstick",),
        measures={
            "model_distance": measures.model_distance,
            "model_seconds": measures.model_seconds,
        },
        repeats=repeats,
        shape="yardstick",
        slow=True,
    )


def summary() -> Study:
    """The engine's own study: every law on every scene at its defaults, with every check.

    Every check but those that run on request (`lawbench.checks.ON_REQUEST`).
    """
    return Study(
        name="summary",
        title="every law on every scene at its defaults, with every check",
        laws="every",
        checks=(
            *SINGLE_SOLVE,
            *(name for name in CHECKS if name not in SINGLE_SOLVE and name not in ON_REQUEST),
        ),
        settings={"continuity_sizes": [1e-6]},
        measures={
            "model_error": measures.model_error,
            "truth_velocity": measures.truth_velocity,
        },
        shape="summary",
        full={"settings": {"continuity_sizes": [1e-2, 1e-4, 1e-6]}},
        # The quick report probes continuity in the continuity studies of the two chains, every
        # law on each: on every scene here it solved each law m + 3 times again, a sixth of the
        # quick report's work (the laws that follow the impact through time, most of it).
        quick={"checks": (*SINGLE_SOLVE, "dispersion")},
    )


# What declares studies, as messages call it, by the keyword its name fills in.
_OWNERS = {"case": "scene", "law": "law"}
# Shape name -> what builds its study; a scene's declaration gets its name as ``case``, a law's
# its name as ``law``.
SHAPES: dict[str, Callable[..., Study]] = {
    "speed_accuracy": speed_accuracy,
    "extremes": extremes,
    "grazing": grazing,
    "duplicated_contact": duplicated_contact,
    "large_friction": large_friction,
    "energy_map": energy_map,
    "energy_shares": energy_shares,
    "continuity": continuity,
    "impact_path": impact_path,
    "impact_paths": impact_paths,
    "sweep": partial(custom, "sweep"),
    "table_path": partial(custom, "table_path"),
    "yardstick": yardstick,
}


def build(declaration: Mapping[str, Any], kind: str, owner: str) -> Study:
    """The study a scene (``kind`` 'case') or a law (``kind`` 'law') called ``owner`` declares.

    Raises
    ------
    InvalidProblem
        For an unknown shape or arguments the shape does not take, naming the scene or law
        and the study.
    """
    arguments = dict(declaration)
    shape = arguments.pop("shape", None)
    where = f"{_OWNERS[kind]} {owner}, study {arguments.get('name', shape)!r}"
    if shape not in SHAPES:
        raise InvalidProblem(f"{where}: shape {shape!r} is not one of {', '.join(SHAPES)}")
    try:
        return SHAPES[shape](**{kind: owner}, **arguments)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{where} ({shape}): {exc}") from None


class _Studies(Registry[Study]):
    """The engine's own study and those the scenes and laws declare, built on first use.

    Listing, looking up or running any study loads every scene and law and builds every
    study at once: a study's name says nothing of the module that declares it.
    """

    def _load(self) -> None:
        if self._loaded:
            return
        built = {"summary": summary()}
        for kind, registry in (("case", CASES), ("law", LAWS)):
            for owner in registry.values():
                for declaration in owner.studies:
                    study = build(declaration, kind, owner.name)
                    if study.name in built or study.name in self._entries:
                        raise InvalidProblem(
                            f"{_OWNERS[kind]} {owner.name}: study {study.name!r} is declared twice"
                        )
                    built[study.name] = study
        self._entries.update(built)
        self._loaded = True

    def _load_one(self, name: str) -> None:
        self._load()


STUDIES: _Studies = _Studies("study", "lawbench.cases", Study)
