"""Answers a check or a measure solves again, kept per process.

The cells of a study share their scene's ground truth (the model error, the dispersion check)
and a law's answer at its tightest knob (the numerical error): a worker solves each once. An
answer is kept under the law's complete options and the problem's digest, so a ground truth
and a tightest knob that name the same options differently are one solve; a failed solve is
kept too, and raised again. The trial being checked is an answer already: asked for its own
law, options and problem (the ground truth's model checked against itself), it serves.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from lawbench.core.errors import LawbenchError
from lawbench.core.law import LAWS
from lawbench.core.metric import is_sparse
from lawbench.core.problem import ImpactProblem
from lawbench.core.trial import Trial

# (law, options, problem digest) -> v_plus, or the error that stopped the solve.
_SOLVED: dict[str, np.ndarray | LawbenchError] = {}
# Options that bound a solve's wall-clock time without changing the answer it gives.
BOUNDS = frozenset({"max_seconds"})


def digest(problem: ImpactProblem) -> str:
    """A digest of every number of ``problem`` and of its contacts' coefficients."""
    import hashlib  # on first use: it loads OpenSSL, 3 ms of a small command's start-up

    found = hashlib.sha1(repr(problem.contacts).encode())
    for part in (problem.M, problem.Wn, problem.Wt, problem.v, problem.gaps):
        if part is None:
            continue
        # A sparse matrix by its stored entries and their places (CSC, as the problem keeps it).
        arrays = (part.data, part.indices, part.indptr) if is_sparse(part) else (part,)
        for array in arrays:
            found.update(np.ascontiguousarray(array).tobytes())
    return found.hexdigest()


def velocity_after(
    law: str, options: dict[str, Any], problem: ImpactProblem, trial: Trial | None = None
) -> np.ndarray:
    """``law``'s post-impact velocity on ``problem`` with ``options``, solved once per process.

    ``trial``'s own answer where it is that solve.

    Raises
    ------
    LawbenchError
        The solve's own error, raised again on every later call.
    """
    values = LAWS.get(law).option_values(options)
    if trial is not None and _is_solve_of(trial, law, values, problem):
        return trial.outcome.v_plus
    key = json.dumps([law, values, digest(problem)], sort_keys=True, default=str)
    if key not in _SOLVED:
        try:
            _SOLVED[key] = LAWS.get(law).resolve(problem, **values).v_plus
        except LawbenchError as exc:
            _SOLVED[key] = exc
    answer = _SOLVED[key]
    if isinstance(answer, LawbenchError):
        raise answer
    return answer


def _is_solve_of(trial: Trial, law: str, values: dict[str, Any], problem: ImpactProblem) -> bool:
    """Whether ``trial`` is ``law`` solved on ``problem`` with option ``values``, bounds aside."""
    used = trial.outcome.diagnostics.get("options")
    if trial.law.name != law or trial.problem is not problem or used is None:
        return False
    return {k: v for k, v in used.items() if k not in BOUNDS} == {
        k: v for k, v in values.items() if k not in BOUNDS
    }
