"""Studies as data: a grid of cells, what it measures and which checks decide its verdicts.

A study (laws x scenes x parameters x options x transforms) is declared, as plain data, where its
scene or law is (the class attribute ``studies`` of the case or the law); the registry `STUDIES`
(`lawbench.studies.declared`) builds each `Study` from its declaration the first time studies
are listed, looked up or run, and the engine knows none by name. Its grid expands
deterministically into `Job` cells (one law with options on one scene with parameters,
optionally a named transform of the built problem, `lawbench.core.transforms`); the executor
(`lawbench.studies.runner`) runs every cell the same way and returns one tidy table whose rows
are `lawbench.studies.record.Record` rows: the outcome, the measured columns, and the verdict of
each named check.

Declaring a custom study, in a case module (the scene's own name is filled in)::

    def omega_ratio(trial):
        return trial.outcome.v_plus[2] / trial.problem.v[2]

    class RockingBlock(Case):
        ...
        studies = (
            {
                "shape": "sweep",
                "name": "rocking_block",
                "title": "omega+/omega- over aspect ratios",
                "laws": "every",
                "grid": {"width": np.logspace(-1, 1, 9).tolist(), "mu": [0.0, 1.0]},
                "params": {"height": 1.0, "e": 0.0},
                "measures": {"omega_ratio": omega_ratio},
            },
        )

A measure reads the `Trial` and returns a number, a sequence of numbers (a list column), a
mapping of arrays, or None where it does not apply. Measures travel to worker processes by
reference: declare them as module-level functions (or `functools.partial` of one), not lambdas.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.checks.knobs import knob_values
from lawbench.core.errors import InvalidProblem

if TYPE_CHECKING:
    from lawbench.core.case import Case
    from lawbench.core.law import Law
    from lawbench.core.trial import Trial

Measure = Callable[[Any], Any]
# Which laws a study compares, when it names none: every law whose tags cover the scene's
# requirements ('covering'), every law that accepts the problem built at the study's fixed
# parameters ('able'), or every registered law, refusals included ('every').
LAW_CHOICES = ("covering", "able", "every")


def evenly(items: Sequence[Any], count: int | None) -> list[Any]:
    """``count`` of ``items`` at evenly spaced positions (all of them when fewer or None).

    The first and the last are among two or more; one is the first.
    """
    if count is None or count >= len(items):
        return list(items)
    return [items[k] for k in np.linspace(0, len(items) - 1, count).round().astype(int)]


def costly(law: Law) -> bool:
    """Whether ``law`` follows the impact through time (its cells cost the most).

    An engine stepping the scene, or a law that reads the contacts' stiffness and integrates
    the compliant impact.
    """
    return law.engine or law.tags.stiffness


def _is_truth(law: str, case: Case) -> bool:
    """Whether ``case``'s ground truth is ``law``'s answer."""
    truth = case.ground_truth
    return truth is not None and truth.law == law


def _cli(value: Any) -> str:
    """A value as ``--set`` reads it back exactly: lists comma-joined, floats in full."""
    if isinstance(value, list | tuple):
        return ",".join(_cli(v) for v in value)
    if isinstance(value, float):
        return repr(float(value))
    return str(value)


@dataclass(frozen=True)
class Job:
    """One cell: a law with options on a scene with parameters, optionally transformed.

    Attributes
    ----------
    law, case : str
        Registered names.
    params, options : mapping
        Scene parameters and law options given (the others take their defaults).
    transform : str
        A transform's spelling (``grazing=1e-08``), '' for none.
    repeat : int
        Which repetition of the same cell (timing studies solve a cell several times).
    """

    law: str
    case: str
    params: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)
    transform: str = ""
    repeat: int = 0

    @property
    def key(self) -> str:
        """A stable identity of the cell's content, for resuming."""
        content: list[Any] = [self.law, self.case, dict(self.params), dict(self.options)]
        if self.transform or self.repeat:
            content += [self.transform, self.repeat]
        text = json.dumps(content, sort_keys=True)
        import hashlib  # on first use: it loads OpenSSL, 3 ms of a small command's start-up

        return hashlib.sha1(text.encode()).hexdigest()[:16]

    def solve(self, settings: Mapping[str, Any] | None = None) -> Trial:
        """Build the problem, apply the transform and solve it: the `Trial` the checks read.

        A transformed problem is no longer the scene at its parameters: its trial is that of a
        problem given as it is (no scene, so no scene references, and the momenta every
        contact leaves alone are the conserved ones).

        An answer that breaks a promise is returned as it is: the cell's checks class it.

        Raises
        ------
        InvalidProblem, NotApplicable, SolverFailure
            As `lawbench.evaluate` does; a bad transform is an `InvalidProblem`.
        """
        from lawbench.core.trial import make_trial

        return make_trial(
            self.law,
            self.case,
            params=self.params,
            options=self.options,
            transform=self.transform,
            settings=settings,
            judged=False,
        )

    def command(self, max_seconds: float | None = None) -> str:
        """The ``lawbench solve`` command that solves this cell again, exactly."""
        words = ["lawbench", "solve", self.law, self.case]
        words += [f"--set {k}={_cli(v)}" for k, v in self.params.items()]
        words += [f"--option {k}={_cli(v)}" for k, v in self.options.items()]
        if self.transform:
            words.append(f"--transform {self.transform}")
        if max_seconds is not None:
            words.append(f"--max-seconds {max_seconds:g}")
        return " ".join(words)


@dataclass(frozen=True)
class Plan:
    """What the executor runs: cells, the checks deciding their verdicts, and what to measure."""

    name: str
    jobs: list[Job]
    checks: tuple[str, ...] = ()
    settings: Mapping[str, Any] = field(default_factory=dict)
    measures: Mapping[str, Measure] = field(default_factory=dict)
    # Per law and scene, the measures their cells leave out (`Study.costly_measures`).
    left_out: Mapping[tuple[str, str], frozenset[str]] = field(default_factory=dict)

    def measures_of(self, job: Job) -> dict[str, Measure]:
        """The measures of ``job``'s cell."""
        skipped = self.left_out.get((job.law, job.case), frozenset())
        return {name: m for name, m in self.measures.items() if name not in skipped}


@dataclass(frozen=True)
class Study:
    """A named grid of laws x scenes x parameters x options x transforms, with its columns.

    Attributes
    ----------
    name : str
        The name users type (``lawbench study NAME``).
    title : str
        What the study shows, with its fixed settings and units.
    cases : tuple of str or None
        The scenes it runs on; None for every registered scene.
    laws : tuple of str or str
        The laws it compares, or one of `LAW_CHOICES`.
    grid : mapping
        Scene parameter -> values; cells are the Cartesian product, in the order written.
    params : mapping
        Scene parameters fixed for every cell.
    options : mapping
        Law name -> option -> values (a grid of that law's options).
    knobs : sequence of float
        When given, each law's accuracy knob is swept over these values (`knob_values`).
    transform : str or None
        A transform of `lawbench.core.transforms.TRANSFORMS` applied to every cell, with each of
        ``transform_values``.
    transform_values : sequence of float
        The transform's values.
    measures : mapping
        Column name -> function of the `Trial` (module-level, see the module docstring).
    checks : tuple of str or None
        Checks whose verdicts the table carries (None: every single-solve check); a cell's
        verdict is the worst of them.
    settings : mapping
        Settings of the checks that solve again (``continuity_sizes``).
    repeats : int
        Solves per cell (timing studies keep the median).
    axes : tuple of str
        The columns a view draws along: a grid parameter, ``transform_value`` or a measure.
    units : mapping
        Measure (or quantity a view draws) -> its unit ('' for dimensionless); views label
        their axes with it (a grid parameter takes the unit of its scene's `Spec`).
    shape : str or None
        What kind of study it is: the shape it was declared with
        (`lawbench.studies.declared.SHAPES`: ``speed_accuracy``, ``extremes``, a custom
        ``sweep``, ...); the report's configuration chooses the section that draws it from this.
    slow : bool
        Left out of the quick report (a long sweep).
    full : mapping
        Field replacements in the full report (larger grids).
    quick : mapping
        Field replacements in the quick report (``costly_points``).
    costly_points : int or None
        The points of each swept axis (a grid parameter, an option, the transform's values)
        that a law following the impact through time (`costly`) is given, evenly spaced
        (`evenly`), its accuracy knob at its default, the setting a user gets; None gives it
        every point and every knob value.
    costly_measures : tuple of str or None
        With ``costly_points``, the measures such a law's cells are given (None: every one),
        but on a scene whose ground truth is that law's answer: the yardstick keeps them all.
    every_engine : bool
        False (the quick report) leaves out the engines' cells on the scenes that leave them
        to the full report (``Case.quick_engines``).
    """

    name: str
    title: str
    cases: tuple[str, ...] | None = None
    laws: tuple[str, ...] | str = "covering"
    grid: Mapping[str, Sequence[Any]] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Mapping[str, Sequence[Any]]] = field(default_factory=dict)
    knobs: Sequence[float] = ()
    transform: str | None = None
    transform_values: Sequence[float] = ()
    measures: Mapping[str, Measure] = field(default_factory=dict)
    checks: tuple[str, ...] | None = None
    settings: Mapping[str, Any] = field(default_factory=dict)
    repeats: int = 1
    axes: tuple[str, ...] = ()
    units: Mapping[str, str] = field(default_factory=dict)
    shape: str | None = None
    slow: bool = False
    full: Mapping[str, Any] = field(default_factory=dict)
    quick: Mapping[str, Any] = field(default_factory=dict)
    costly_points: int | None = None
    costly_measures: tuple[str, ...] | None = None
    every_engine: bool = True

    def __post_init__(self) -> None:
        if isinstance(self.laws, str) and self.laws not in LAW_CHOICES:
            raise ValueError(f"study {self.name}: laws {self.laws!r} not in {LAW_CHOICES}")

    def case_names(self) -> list[str]:
        """The scenes of the study."""
        from lawbench.core.case import CASES

        return list(self.cases) if self.cases is not None else CASES.names()

    def law_names(self, case: Case) -> list[str]:
        """The laws of the study on ``case`` (see ``laws``)."""
        from lawbench.core.law import LAWS

        if not isinstance(self.laws, str):
            return list(self.laws)
        if self.laws == "every":
            return LAWS.names()
        if self.laws == "able":
            problem = case.build(**self.params)
            return [law.name for law in LAWS.values() if law.refusal(problem) is None]
        return [law.name for law in LAWS.values() if law.tags.covers(case.requires)]

    def preset(self, mode: str) -> Study:
        """The study as the report's ``mode`` ('quick' or 'full') runs it."""
        if mode == "full":
            return dataclasses.replace(self, **self.full)
        return dataclasses.replace(self, **self.quick, every_engine=False)

    def with_params(self, given: Mapping[str, Any]) -> Study:
        """The study with parameters fixed (a grid parameter given is no longer swept)."""
        grid = {k: v for k, v in self.grid.items() if k not in given}
        return dataclasses.replace(self, grid=grid, params={**self.params, **given})

    def jobs(
        self, laws: Sequence[str] | None = None, cases: Sequence[str] | None = None
    ) -> Iterator[Job]:
        """Every cell, those of ``laws`` on ``cases`` when given.

        Scenes outermost, then laws, the parameter grid, the option grid, the transform values
        and the repeats. A law that follows the impact through time is given ``costly_points``
        points of each of them when that is set, and its accuracy knob at its default; an
        engine none on a scene that leaves it to the full report, unless ``every_engine``.

        Raises
        ------
        InvalidProblem
            For a parameter or option its scene or law does not accept, naming the study.
        """
        from lawbench.core.case import CASES
        from lawbench.core.law import LAWS
        from lawbench.core.transforms import spell

        for case_name in self.case_names():
            if cases is not None and case_name not in cases:
                continue
            case = CASES.get(case_name)
            for law_name in self.law_names(case):
                if laws is not None and law_name not in laws:
                    continue
                law = LAWS.get(law_name)
                if law.engine and not (self.every_engine or case.quick_engines):
                    continue
                count = self.costly_points if costly(law) else None
                option_grid = {k: list(v) for k, v in self.options.get(law_name, {}).items()}
                if self.knobs:
                    knob, values = knob_values(law, self.knobs)
                    if knob is not None:
                        option_grid[knob] = values if count is None else [law.option_values()[knob]]
                option_grid = {k: evenly(v, count) for k, v in option_grid.items()}
                grid = {k: evenly(v, count) for k, v in self.grid.items()}
                values = evenly(self.transform_values, count)
                transforms = [spell(self.transform, v) for v in values] or [""]
                for params in _product(grid):
                    params = {**self.params, **params}
                    for options in _product(option_grid):
                        self._check(case, law, params, options)
                        for transform in transforms:
                            for repeat in range(self.repeats):
                                yield Job(law_name, case_name, params, options, transform, repeat)

    def check_names(self) -> tuple[str, ...]:
        """The checks deciding the verdicts (``checks``, or every single-solve check)."""
        from lawbench.checks import SINGLE_SOLVE

        return tuple(SINGLE_SOLVE if self.checks is None else self.checks)

    def plan(self, laws: Sequence[str] | None = None, cases: Sequence[str] | None = None) -> Plan:
        """The executor's plan of this study (restricted to ``laws`` and ``cases``)."""
        from lawbench.core.case import CASES
        from lawbench.core.law import LAWS

        jobs = list(self.jobs(laws, cases))
        left_out = {}
        if self.costly_points is not None and self.costly_measures is not None:
            skipped = frozenset(self.measures) - frozenset(self.costly_measures)
            thinned = {
                (job.law, job.case)
                for job in jobs
                if costly(LAWS.get(job.law)) and not _is_truth(job.law, CASES.get(job.case))
            }
            left_out = dict.fromkeys(sorted(thinned), skipped)
        return Plan(
            self.name, jobs, self.check_names(), dict(self.settings), dict(self.measures), left_out
        )

    def _check(self, case: Case, law: Law, params: dict, options: dict) -> None:
        try:
            case.parameters(**params)
            law.option_values(options)
        except InvalidProblem as exc:
            raise InvalidProblem(f"study {self.name}, {law.name} on {case.name}: {exc}") from None


def _product(choices: Mapping[str, Sequence[Any]]) -> Iterator[dict[str, Any]]:
    names = list(choices)
    for combination in itertools.product(*(choices[name] for name in names)):
        yield dict(zip(names, combination, strict=True))
