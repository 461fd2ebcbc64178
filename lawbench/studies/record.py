"""The record of one cell: the same fields for every cell, whatever happened to it.

Like scipy's ``OptimizeResult``, a `Record` has fixed fields for all: the cell (law, scene,
parameters, options, transform), the outcome, the cost, the verdict, the error of a cell that
gave no answer (its class and message; for a `BudgetExceeded`, which budget, how much and after
how long), the command that reproduces it and the exit status that command gives. Per check it
adds ``NAME_value``, ``NAME_verdict``, ``NAME_finding`` (the index of the deciding finding in the
law's ``findings``, -1 for none) and ``NAME_detail``; per measure one column of its name.
Vectors, parameters and options are JSON text in a record; a run's file holds its tidy form
(`lawbench.studies.runfile.tidy`: a column per parameter, list columns, categorical verdicts).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from lawbench.checks import CheckResult
from lawbench.core.errors import BudgetExceeded, InvalidProblem, NotApplicable, SolverFailure
from lawbench.core.guards import WALL_CLOCK
from lawbench.core.trial import Trial
from lawbench.core.verdicts import Verdict, of_error
from lawbench.studies.study import Job

STEP_KEYS = ("steps", "impacts", "iterations")
# Worst first: a cell's verdict is the worst of its checks' (a check that does not apply to the
# cell says nothing about it).
SEVERITY = (
    Verdict.UNEXPLAINED,
    Verdict.NUMERICAL_FAILURE,
    Verdict.BUDGET,
    Verdict.LAW_PROPERTY,
    Verdict.HOLDS,
)
# ``lawbench solve``'s exit status per error class (0 for an answer).
EXIT_STATUS = ((InvalidProblem, 2), (NotApplicable, 3), (SolverFailure, 4))
_NESTED = ("checks", "measures")


def exit_status(error: BaseException | None) -> int:
    """The exit status of ``lawbench solve`` on a cell that raised ``error`` (None: 0)."""
    if error is None:
        return 0
    return next((code for kind, code in EXIT_STATUS if isinstance(error, kind)), 1)


def worst(verdicts: list[Verdict]) -> Verdict:
    """The worst of ``verdicts`` that are not *refused*; *holds* when none is left."""
    return next((v for v in SEVERITY if v in verdicts), Verdict.HOLDS)


def plain(value: Any) -> Any:
    """A measure's value in a table cell: floats as they are, anything else as JSON text."""
    if value is None:
        return math.nan
    if isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, str):
        return value
    return json.dumps(_lists(value), allow_nan=True)


def _lists(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _lists(v) for k, v in value.items()}
    if isinstance(value, np.ndarray | list | tuple):
        return [_lists(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


@dataclass
class Record:
    """The result of one cell.

    Attributes
    ----------
    index, key, study : int, str, str
        The cell's place in its run, its stable identity (for resuming) and its study.
    law, case, params, options, transform, repeat
        The cell (`lawbench.studies.study.Job`); parameters and options as JSON text.
    verdict : str
        The worst verdict of its checks, or that of the error that stopped it.
    status, error_class, error_message : str
        The law's status word, or 'error' with the error's class and message.
    budget, budget_amount, spent_s : str, float, float
        For a `BudgetExceeded`: the budget that ran out, its amount, the seconds spent.
    v_plus, Pn, Pt : str
        The outcome's vectors, as JSON text.
    T_minus, T_plus, dT : float
        Kinetic energies before and after, and the change (J).
    formulation, steps, wall_time_s, warnings
        How the law solved it, its steps or iterations, its own wall time, warnings raised.
    exit_status, reproducer : int, str
        The ``lawbench solve`` command that reruns the cell, and the exit status it gives.
    checks, measures : dict
        Check results and measured values, flattened into columns by `row`.
    """

    index: int
    key: str
    study: str
    law: str
    case: str
    params: str
    options: str
    transform: str
    repeat: int
    verdict: str
    status: str = "error"
    error_class: str = ""
    error_message: str = ""
    budget: str = ""
    budget_amount: float = math.nan
    spent_s: float = math.nan
    v_plus: str = ""
    Pn: str = ""
    Pt: str = ""
    T_minus: float = math.nan
    T_plus: float = math.nan
    dT: float = math.nan  # noqa: N815 (the outcome's name)
    formulation: str = ""
    steps: int = 0
    wall_time_s: float = math.nan
    warnings: str = ""
    exit_status: int = 0
    reproducer: str = ""
    checks: dict[str, CheckResult] = field(default_factory=dict)
    measures: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def empty(cls, index: int, study: str, job: Job) -> Record:
        """The fields every record has, before the cell is solved."""
        return cls(
            index=index,
            key=job.key,
            study=study,
            law=job.law,
            case=job.case,
            params=json.dumps(dict(job.params), sort_keys=True),
            options=json.dumps(dict(job.options), sort_keys=True),
            transform=job.transform,
            repeat=job.repeat,
            verdict=str(Verdict.HOLDS),
            reproducer=job.command(),
        )

    @classmethod
    def solved(
        cls,
        index: int,
        study: str,
        job: Job,
        trial: Trial,
        checks: dict[str, CheckResult],
        measures: dict[str, Any],
    ) -> Record:
        """The record of a cell that gave an answer."""
        record = cls.empty(index, study, job)
        outcome = trial.outcome
        diagnostics = outcome.diagnostics
        record.status = outcome.status
        record.v_plus = json.dumps(outcome.v_plus.tolist())
        record.Pn = json.dumps(outcome.Pn.tolist())
        record.Pt = json.dumps(outcome.Pt.tolist())
        record.T_minus, record.T_plus, record.dT = outcome.T_minus, outcome.T_plus, outcome.dT
        record.formulation = str(diagnostics.get("formulation", ""))
        record.steps = next((int(diagnostics[k]) for k in STEP_KEYS if k in diagnostics), 0)
        record.wall_time_s = diagnostics["wall_time_s"]
        record.verdict = str(worst([result.verdict for result in checks.values()]))
        record.checks, record.measures = checks, measures
        return record

    @classmethod
    def failed(
        cls, index: int, study: str, job: Job, error: BaseException, spent_s: float
    ) -> Record:
        """The record of a cell whose solve (or check, or measure) raised ``error``."""
        record = cls.empty(index, study, job)
        record.verdict = str(of_error(error))
        record.error_class, record.error_message = type(error).__name__, str(error)
        record.exit_status = exit_status(error)
        if isinstance(error, BudgetExceeded):
            record.budget, record.budget_amount = error.budget, float(error.amount)
            record.spent_s = spent_s if error.spent_s is None else error.spent_s
            if error.budget == WALL_CLOCK:
                record.reproducer = job.command(max_seconds=error.amount)
        return record

    def row(self) -> dict[str, Any]:
        """The flat row of a table."""
        row = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in _NESTED}
        for name, result in self.checks.items():
            claims = self._findings(result)
            row[f"{name}_value"] = math.nan if result.value is None else float(result.value)
            row[f"{name}_verdict"] = str(result.verdict)
            row[f"{name}_finding"] = claims.index(result.claim) if result.claim in claims else -1
            row[f"{name}_detail"] = result.detail
        row.update({name: plain(value) for name, value in self.measures.items()})
        return row

    def _findings(self, result: CheckResult) -> tuple:
        from lawbench.core.law import LAWS

        if result.verdict != Verdict.LAW_PROPERTY:
            return ()
        return LAWS.get(self.law).findings


def budget_text(row: Mapping[str, Any]) -> str:
    """Which budget a cell ran out of and after how long, in words ('' for other cells)."""
    budget = row.get("budget")
    if not isinstance(budget, str) or not budget:
        return ""
    amount, spent = row.get("budget_amount"), row.get("spent_s")
    unit = " s" if budget == WALL_CLOCK or budget.endswith("seconds") else ""
    text = f"budget {budget} = {amount:g}{unit}"
    return text + (f", after {spent:.3g} s" if spent == spent else "")
