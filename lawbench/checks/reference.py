"""The check against the analytic and published references of a case."""

from __future__ import annotations

import numpy as np

from lawbench.checks.base import check
from lawbench.core.trial import Trial

# References are closed forms; the laws they describe are exact up to solver polishing.
REFERENCE_TOLERANCE = 1e-8


@check("reference", promised=True)
def reference(trial: Trial) -> tuple:
    """Largest error of ``v_plus`` against every reference that describes this run."""
    if trial.case is None:
        return None, None, "a problem given as it is has no references"
    errors, reasons = {}, []
    scale = max(float(np.abs(trial.problem.v).max()), 1e-300)
    for ref in trial.case.references:
        reason = ref.applies(trial.law.name, trial.outcome.diagnostics["options"], trial.params)
        if reason:
            reasons.append(f"{ref.name}: {reason}")
            continue
        expected = np.asarray(ref.v_plus(trial.params), dtype=float)
        errors[ref.name] = float(np.abs(trial.outcome.v_plus - expected).max()) / scale
    if not errors:
        return None, None, "no reference applies" + (f" ({'; '.join(reasons)})" if reasons else "")
    worst = max(errors, key=errors.get)
    passed = errors[worst] <= REFERENCE_TOLERANCE
    sources = ", ".join(f"{name} ({error:.2g})" for name, error in errors.items())
    return errors[worst], passed, f"relative error against {sources}"
