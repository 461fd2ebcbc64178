"""Work the report sends to its guarded workers besides the runner's rows.

Each task is a module-level function of plain arguments, so a spawned worker can receive it;
it raises whatever the solve raises, and the guard records it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lawbench.api import evaluate
from lawbench.checks.continuity import jumps
from lawbench.law import LAWS
from lawbench.problem import ImpactProblem
from lawbench.record import STEP_KEYS


def solve_problem(law: str, problem: ImpactProblem, options: dict[str, Any]) -> dict[str, Any]:
    """Record of ``law`` on a problem the report built itself (fields of the runner's record)."""
    outcome = LAWS.get(law).resolve(problem, **options)
    diagnostics = outcome.diagnostics
    return {
        "law": law,
        "status": outcome.status,
        "error_class": "",
        "error_message": "",
        "v_plus": outcome.v_plus.tolist(),
        "Pn": outcome.Pn.tolist(),
        "Pt": outcome.Pt.tolist(),
        "T_minus": outcome.T_minus,
        "T_plus": outcome.T_plus,
        "dT": outcome.dT,
        "wall_time_s": diagnostics["wall_time_s"],
        "steps": next((int(diagnostics[k]) for k in STEP_KEYS if k in diagnostics), 0),
    }


def continuity_jumps(
    law: str, case: str, params: dict[str, Any], sizes: Sequence[float]
) -> dict[str, list[float]]:
    """Outcome jumps per perturbation size (`lawbench.checks.continuity.jumps`)."""
    return jumps(evaluate(law, case, **params), tuple(sizes))


def impact_path(law: str, case: str, params: dict[str, Any]) -> dict[str, Any]:
    """Quantities along the impact (option ``path``) and the phases a law reports."""
    trial = evaluate(law, case, {"path": True}, **params)
    outcome = trial.outcome
    if not outcome.path:
        raise ValueError(f"{law} returned no path on {case}")
    diagnostics = outcome.diagnostics
    return {
        "path": {key: np.asarray(value, dtype=float) for key, value in outcome.path.items()},
        "phases": list(diagnostics.get("phases", [])),
        "phase_impulses": [float(p) for p in diagnostics.get("phase_impulses", [])],
        "formulation": str(diagnostics.get("formulation", "")),
        "dT": outcome.dT,
        "T_minus": outcome.T_minus,
    }
