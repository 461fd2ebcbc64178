"""Studies as data: a grid of laws x scene parameters x options, and what to measure.

A study is declared where its scene or law is (in the module of the case or the law) and
registered in `STUDIES`; the engine knows none by name. Its grid expands deterministically into
jobs (one law with options on one scene with parameters); the executor runs every job the same
way and returns one tidy table whose rows carry the outcome, the measured columns and the
verdict of each named check.

Declaring a study, in a case module::

    STUDIES.register(
        Study(
            name="rocking_block",
            title="omega+/omega- against Housner's ratio over aspect ratios",
            case="rocking_block",
            grid={"width": np.logspace(-1, 1, 9).tolist(), "mu": [0.0, 1.0]},
            params={"height": 1.0, "e": 0.0},
            measures={"omega_ratio": lambda trial: trial.outcome.v_plus[2] / trial.problem.v[2]},
        )
    )

``laws`` None means every registered law whose tags cover the scene's. A measure reads the
`Trial` and returns a float (or a sequence of floats, stored as a list column).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from lawbench.registry import Registry

Measure = Callable[[Any], Any]


@dataclass(frozen=True)
class Job:
    """One cell of a study: a law with options on a scene with parameters."""

    law: str
    case: str
    params: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Study:
    """A named grid of laws x scene parameters x options, with the columns it measures.

    Attributes
    ----------
    name : str
        The name users type (``lawbench study NAME``).
    title : str
        What the study shows, with its fixed settings and units.
    case : str
        The scene it runs on.
    laws : tuple of str or None
        The laws it compares; None for every law whose tags cover the scene.
    grid : mapping
        Scene parameter -> values; rows are the Cartesian product, in the order written.
    params : mapping
        Scene parameters fixed for every row.
    options : mapping
        Law name -> option -> values (a grid of that law's options).
    measures : mapping
        Column name -> function of the `Trial`.
    checks : tuple of str
        Checks whose verdicts the table carries.
    slow : bool
        Left out of quick runs (a long sweep).
    """

    name: str
    title: str
    case: str
    laws: tuple[str, ...] | None = None
    grid: Mapping[str, Sequence[Any]] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Mapping[str, Sequence[Any]]] = field(default_factory=dict)
    measures: Mapping[str, Measure] = field(default_factory=dict)
    checks: tuple[str, ...] = ("energy_gain",)
    slow: bool = False

    def law_names(self) -> list[str]:
        """The laws of the study: those named, or every law whose tags cover the scene."""
        from lawbench.case import CASES
        from lawbench.law import LAWS

        if self.laws is not None:
            return list(self.laws)
        requires = CASES.get(self.case).requires
        return [law.name for law in LAWS if law.tags.covers(requires)]

    def jobs(self) -> Iterator[Job]:
        """Every cell, laws outermost, then the parameter grid, then the option grid."""
        names = list(self.grid)
        for law in self.law_names():
            option_grid = dict(self.options.get(law, {}))
            for values in itertools.product(*(self.grid[n] for n in names)):
                params = {**self.params, **dict(zip(names, values, strict=True))}
                for options in itertools.product(*option_grid.values()):
                    yield Job(law, self.case, params, dict(zip(option_grid, options, strict=True)))


class _Studies(Registry[Study]):
    """Studies are declared in the law and case modules: loading them loads both packages."""

    def _load(self) -> None:
        from lawbench.case import CASES
        from lawbench.law import LAWS

        LAWS.names()
        CASES.names()
        self._loaded = True


STUDIES: _Studies = _Studies("study", "lawbench.cases")
