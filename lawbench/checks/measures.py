"""Measures a study may ask for: functions of a solved `Trial`, one column each.

*Model error* and *numerical error* are two different measures, never one column:

- `model_error`: the distance of the outcome from the scene's ground truth
  (``Case.ground_truth``: a closed-form `Reference` where it holds, else a converged solution of
  a stated model),
  ``max |v+ - v_truth| / max |v-|``;
- `numerical_error`: the distance from the law's own answer at its tightest accuracy knob
  (`lawbench.checks.knobs.tightest`), the same way; 0 for an exact law, None for a knob that chooses
  between models (an ordering) rather than an accuracy.

`model_distance` is the model error against the ground truth's model itself, where the truth
has a closed form too (the yardstick check's companion, `lawbench.checks.yardstick`), and
`model_seconds` that model's own wall time on the trial's problem.

Both solve again in the worker; each answer is kept per process (`lawbench.checks.solved`),
so a sweep pays for the ground truth once per worker. A measure returns None where it does not
apply.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.checks.continuity import jumps
from lawbench.checks.dispersion import dispersion_index as _index
from lawbench.checks.knobs import tightest
from lawbench.checks.solved import digest, velocity_after
from lawbench.core.errors import LawbenchError
from lawbench.core.law import LAWS
from lawbench.core.mechanics import energy_shares as _shares
from lawbench.core.problem import ImpactProblem
from lawbench.core.trial import Trial


def _solve(
    law: str, options: dict[str, Any], problem: ImpactProblem, trial: Trial | None = None
) -> np.ndarray | None:
    """``law``'s post-impact velocity on ``problem``, once per process; None when it fails."""
    try:
        return velocity_after(law, options, problem, trial)
    except LawbenchError:
        return None


def _distance(trial: Trial, v: np.ndarray | None) -> float | None:
    if v is None:
        return None
    scale = max(float(np.abs(trial.problem.v).max()), 1e-300)
    return float(np.abs(trial.outcome.v_plus - v).max() / scale)


def truth(trial: Trial) -> np.ndarray | None:
    """The scene's ground truth on this trial's problem, or None where it has none.

    A closed form holds at the scene's own parameters only: not on a transformed problem, nor
    where its condition fails; there the scene's model, if it declares one, is the truth.
    """
    case = trial.case
    ground = case.ground_truth if case is not None else None
    if ground is None:
        return None
    if ground.reference is not None:
        closed = _closed_form(trial, ground.reference)
        if closed is not None:
            return closed
    if ground.law is not None:
        return _solve(ground.law, dict(ground.options), trial.problem, trial)
    return None


def _closed_form(trial: Trial, name: str) -> np.ndarray | None:
    """The case's reference ``name`` on this trial, None where it does not hold."""
    case = trial.case
    reference = next(r for r in case.references if r.name == name)
    if reference.condition(trial.params) or any(trial.params.get("gaps", ())):
        return None
    if digest(case.build(**trial.params)) != digest(trial.problem):
        return None
    return np.asarray(reference.v_plus(trial.params), dtype=float)


def model_error(trial: Trial) -> float | None:
    """``max |v+ - v_truth| / max |v-|`` against the scene's ground truth."""
    return _distance(trial, truth(trial))


def numerical_error(trial: Trial) -> float | None:
    """``max |v+ - v_own| / max |v-|`` against the law's answer at its tightest knob."""
    law = trial.law
    if law.tags.accuracy_knob is None:
        return 0.0
    tight = tightest(law)
    if not tight:
        return None
    return _distance(trial, _solve(law.name, {**trial.options, **tight}, trial.problem, trial))


def _model(trial: Trial) -> tuple[str, dict[str, Any]] | None:
    """The scene's ground-truth model and its options, None where it declares none."""
    ground = trial.case.ground_truth if trial.case is not None else None
    if ground is None or ground.law is None:
        return None
    return ground.law, dict(ground.options)


def model_distance(trial: Trial) -> float | None:
    """``max |v+ - v_model| / max |v-|`` against the ground truth's model, closed form aside."""
    model = _model(trial)
    return None if model is None else _distance(trial, _solve(*model, trial.problem, trial))


def model_seconds(trial: Trial) -> float | None:
    """The wall time of the ground truth's model on this trial's problem, solved afresh (s)."""
    model = _model(trial)
    if model is None:
        return None
    law, options = model
    try:
        return float(LAWS.get(law).resolve(trial.problem, **options).diagnostics["wall_time_s"])
    except LawbenchError:
        return None


def truth_velocity(trial: Trial) -> list[float] | None:
    """The ground truth's post-impact velocity itself (a list column)."""
    v = truth(trial)
    return None if v is None else v.tolist()


def energy_shares(trial: Trial) -> dict[str, float]:
    """Share of the post-impact kinetic energy carried by each body."""
    return _shares(trial.problem, trial.outcome.v_plus)


def dispersion_index(trial: Trial) -> float:
    """Normalized entropy of the energy shares (0: one body has it all, 1: spread evenly)."""
    return _index(_shares(trial.problem, trial.outcome.v_plus))


def continuity_jumps(trial: Trial) -> dict[str, list[float]] | None:
    """Outcome jump per perturbation size, under gaps and under velocities.

    At the sizes of the study's ``continuity_sizes`` setting
    (`lawbench.checks.continuity.jumps`); None on one contact or when a perturbed solve fails.
    """
    if trial.problem.m < 2:
        return None
    sizes = tuple(trial.settings.get("continuity_sizes", (1e-2, 1e-4, 1e-6)))
    try:
        return {**jumps(trial, sizes), "sizes": list(sizes)}
    except LawbenchError:
        return None


def impact_path(trial: Trial) -> dict[str, Any] | None:
    """The quantities along the impact (option ``path``) and the phases the law reports."""
    outcome = trial.outcome
    if not outcome.path:
        return None
    diagnostics = outcome.diagnostics
    return {
        "path": {key: np.asarray(value, dtype=float) for key, value in outcome.path.items()},
        "phases": list(diagnostics.get("phases", [])),
        "phase_impulses": [float(p) for p in diagnostics.get("phase_impulses", [])],
    }
