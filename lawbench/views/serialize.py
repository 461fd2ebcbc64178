"""Turn outcomes and trials into plain JSON-ready values."""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.checks import CheckResult
from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.trial import Trial


def plain(value: Any) -> Any:
    """Return ``value`` with numpy arrays and scalars turned into lists, floats and ints."""
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


def trial_record(trial: Trial, checks: dict[str, CheckResult]) -> dict[str, Any]:
    """The JSON object of ``lawbench solve --json``."""
    outcome = trial.outcome
    record = {
        "law": trial.law.name,
        "case": trial.scene,
        "params": trial.params,
        "coordinates": (
            trial.case.coordinates(trial.params)
            if trial.case is not None
            else [f"v[{i}]" for i in range(trial.problem.n)]
        ),
        "v_minus": trial.problem.v,
        "v_plus": outcome.v_plus,
        "Pn": outcome.Pn,
        "Pt": outcome.Pt,
        "T_minus": outcome.T_minus,
        "T_plus": outcome.T_plus,
        "checks": {name: result.as_dict() for name, result in checks.items()},
        "status": outcome.status,
        "diagnostics": outcome.diagnostics,
    }
    if outcome.path is not None:
        record["path"] = outcome.path
    return plain(record)


def contact_record(law: str, problem: ContactProblem, solution: ContactSolution) -> dict[str, Any]:
    """The JSON object of ``lawbench solve --json`` on a contact-space problem (FCLIB local)."""
    return plain(
        {
            "law": law,
            "case": problem.name,
            "contacts": problem.m,
            "dim": problem.dim,
            "status": "ok",
            "r": solution.r,
            "u": solution.u,
            "fc3d_error": solution.fc3d_error,
            "diagnostics": solution.diagnostics,
        }
    )
