"""Hold any law to the common checks, like scikit-learn's ``check_estimator``.

`check_law` runs every check the law's tags make applicable on every registered scene it can
treat (each named example; ``continuity`` and ``dispersion`` on the first example, the scene's
defaults, because they solve again) and on seeded random problems, and returns one row per
cell with its verdict (`lawbench.core.verdicts`). The law's findings make the failures its theory
predicts *law properties*; a *numerical failure* or an *unexplained* cell fails the law.
`cells` and `run_cell` give the same cells one at a time, for a parametrized test.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.checks import CHECKS, ON_REQUEST, SINGLE_SOLVE
from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem, LawbenchError
from lawbench.core.law import LAWS, Law
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.trial import Trial
from lawbench.core.verdicts import ACCEPTABLE, Verdict, of_error

if TYPE_CHECKING:
    import pandas as pd

SEVERAL_SOLVES = tuple(name for name in CHECKS if name not in (*SINGLE_SOLVE, *ON_REQUEST))
COLUMNS = ("law", "scene", "example", "check", "verdict", "value", "detail", "claim")
# Seeded random problems a check of a law adds at most.
MAX_RANDOM = 100_000


@dataclass(frozen=True)
class Cell:
    """One check of one law on one problem: a scene's named example, or a random problem."""

    law: str
    scene: str
    example: str
    check: str

    @property
    def id(self) -> str:
        """A readable identity, ``law-scene-example-check``."""
        return f"{self.law}-{self.scene}-{self.example}-{self.check}".replace(" ", "_")


def random_problem(seed: int) -> ImpactProblem:
    """A random free chain of 2 to 5 balls, masses over two decades, every contact approaching."""
    rng = np.random.default_rng(seed)
    balls = int(rng.integers(2, 6))
    Wn = np.zeros((balls, balls - 1))
    index = np.arange(balls - 1)
    Wn[index, index], Wn[index + 1, index] = -1.0, 1.0
    v = np.sort(rng.uniform(-1.0, 1.0, balls))[::-1].copy()
    return ImpactProblem.from_arrays(
        np.diag(10.0 ** rng.uniform(-1.0, 1.0, balls)),
        Wn,
        v,
        e=rng.uniform(0.0, 1.0, balls - 1),
        stiffness=10.0 ** rng.uniform(-1.0, 1.0, balls - 1),
        bodies={f"ball {i + 1}": [i] for i in range(balls)},
    )


def cells(
    law: Law, cases: list[str] | None = None, random_problems: int = 3, several: bool = True
) -> Iterator[Cell]:
    """Every cell `check_law` runs for ``law``, in order."""
    for case in CASES.values():
        if (cases is not None and case.name not in cases) or not law.tags.covers(case.requires):
            continue
        for number, example in enumerate(case.examples):
            names = [*SINGLE_SOLVE, *(SEVERAL_SOLVES if several and number == 0 else ())]
            for check in names:
                yield Cell(law.name, case.name, example, check)
    for seed in range(random_problems):
        for check in SINGLE_SOLVE:
            yield Cell(law.name, "random", str(seed), check)


@functools.lru_cache(maxsize=256)
def _trial(law: Law, scene: str, example: str) -> Trial | LawbenchError | Exception:
    """The trial of a cell's problem, or the error its solve raised."""
    from lawbench.core.trial import make_trial

    try:
        if scene == "random":
            return make_trial(law, random_problem(int(example)), judged=False)
        case = CASES.get(scene)
        return make_trial(law, case, params=case.examples[example], judged=False)
    except Exception as exc:  # the cell records it: refused, budget, or a bug
        return exc


def run_cell(law: Law, cell: Cell, continuity_sizes: tuple[float, ...] = (1e-6,)) -> dict[str, Any]:
    """The row of one cell: its verdict, value, detail and the claim that decided it."""
    row = {"law": cell.law, "scene": cell.scene, "example": cell.example, "check": cell.check}
    trial = _trial(law, cell.scene, cell.example)
    if isinstance(trial, Exception):
        detail = f"{type(trial).__name__}: {trial}"
        return {**row, "verdict": of_error(trial), "value": None, "detail": detail, "claim": None}
    trial.settings["continuity_sizes"] = list(continuity_sizes)
    try:
        result = CHECKS[cell.check](trial)
    except Exception as exc:  # a check that breaks on this law is a bug to show
        detail = f"the check raised {type(exc).__name__}: {exc}"
        return {
            **row,
            "verdict": Verdict.UNEXPLAINED,
            "value": None,
            "detail": detail,
            "claim": None,
        }
    claim = result.claim.describe() if result.claim else None
    return {
        **row,
        "verdict": result.verdict,
        "value": result.value,
        "detail": result.detail,
        "claim": claim,
    }


def declaration_problems(law: Law) -> list[str]:
    """What is wrong with the law object itself (name, source, tags, options, claims)."""
    problems = []
    for attribute in ("name", "summary", "source"):
        if not isinstance(getattr(law, attribute, None), str) or not getattr(law, attribute):
            problems.append(f"{attribute} is missing")
    for spec in getattr(law, "options", ()):
        if not isinstance(spec, Spec) or not spec.doc:
            problems.append(f"option {getattr(spec, 'name', spec)!r} has no Spec with a doc line")
            continue
        try:
            spec.coerce(spec.default)
        except InvalidProblem as exc:
            problems.append(f"option {spec.name}: its default is out of range ({exc})")
    for kind in ("findings", "guarantees"):
        for claim in getattr(law, kind, ()):
            if claim.check not in CHECKS:
                problems.append(f"{kind}: unknown check {claim.check!r}")
            if not (claim.source and claim.reason):
                problems.append(f"{kind}: a claim on {claim.check} has no source or reason")
            for case, example in claim.witnesses:
                if case not in CASES or example not in CASES.get(case).examples:
                    problems.append(f"{kind}: witness {case}/{example} is not a named example")
    return problems


@dataclass(frozen=True)
class CheckReport:
    """The verdict table of a law, and what is wrong with its declaration."""

    law: str
    rows: list[dict[str, Any]]
    declaration: list[str]

    @property
    def failures(self) -> list[dict[str, Any]]:
        """Cells a law may not ship: numerical failures and unexplained verdicts."""
        return [row for row in self.rows if row["verdict"] not in ACCEPTABLE]

    @property
    def passed(self) -> bool:
        """Whether every cell is acceptable and the declaration is sound."""
        return not self.failures and not self.declaration

    def to_frame(self) -> pd.DataFrame:
        """One row per cell, the verdict as a categorical of the taxonomy."""
        import pandas as pd

        frame = pd.DataFrame(self.rows, columns=list(COLUMNS))
        frame["verdict"] = pd.Categorical(
            [str(v) for v in frame["verdict"]], categories=[str(v) for v in Verdict]
        )
        return frame

    def counts(self) -> dict[str, int]:
        """Cells per verdict class."""
        return {str(v): sum(row["verdict"] == v for row in self.rows) for v in Verdict}


def check_law(
    law: str | Law,
    *,
    cases: list[str] | None = None,
    random_problems: int = 3,
    continuity_sizes: tuple[float, ...] = (1e-6,),
) -> CheckReport:
    """Run every applicable common check on ``law``; see the module docstring.

    Parameters
    ----------
    law : str or Law
        A registered law's name, or a law object (registered or not).
    cases : list of str, optional
        Only these scenes; every scene the law's tags cover by default.
    random_problems : int
        Seeded random chains to add (`random_problem`).
    continuity_sizes : tuple of float
        Perturbation sizes of the continuity check.

    Returns
    -------
    CheckReport
        ``passed`` is False when a cell is a numerical failure or unexplained, or the law's
        declaration is unsound.
    """
    law = LAWS.get(law)
    if isinstance(random_problems, bool) or not isinstance(random_problems, int):
        raise TypeError(f"random_problems must be an int, not {type(random_problems).__name__}")
    if not 0 <= random_problems <= MAX_RANDOM:
        raise InvalidProblem(f"random_problems = {random_problems}: must lie in [0, {MAX_RANDOM}]")
    for name in cases or ():
        CASES.get(name)  # an unknown scene is an error, never an empty table that passes
    rows = [run_cell(law, cell, continuity_sizes) for cell in cells(law, cases, random_problems)]
    return CheckReport(law.name, rows, declaration_problems(law))
