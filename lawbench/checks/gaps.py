"""A rigid law through initial gaps, event by event.

A rigid law resolves an impact at one instant among the contacts that are closed. When a scene
starts with small gaps, the bodies meet them one after the other: the contacts that are closed
and approach are resolved by the law, the bodies fly freely (velocities constant, gaps changing
at their gap rates) until the next contact closes, and so on until no contact approaches. Laws
that resolve time themselves (``follows_gaps``, the compliant contacts) receive the gaps as they
are.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from lawbench.core.errors import SolverFailure
from lawbench.core.law import Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem

APPROACH_TOLERANCE = 1e-12


def resolve_with_gaps(
    law: Law, problem: ImpactProblem, options: dict[str, Any], max_events: int = 10_000
) -> Outcome:
    """Resolve ``problem`` with ``law``, meeting its gaps one event at a time.

    Raises
    ------
    SolverFailure
        After ``max_events`` impacts and flights with contacts still approaching.
    """
    if law.follows_gaps:
        return law.resolve(problem, **options)
    v, gaps = problem.v.copy(), problem.gaps.copy()
    Pn, Pt = np.zeros(problem.m), np.zeros(problem.m * problem.d)
    threshold = -APPROACH_TOLERANCE * max(float(np.abs(problem.un).max()), 1e-300)
    sequence: list[list[int]] = []
    for _ in range(max_events):
        un = problem.Wn.T @ v
        closed = gaps <= 0.0
        if (closed & (un < threshold)).any():
            if sequence and sequence[-1] == "impact":
                break  # the law left a closed contact approaching: no flight is possible
            outcome = law.resolve(dataclasses.replace(problem, v=v, gaps=gaps), **options)
            v, Pn, Pt = outcome.v_plus, Pn + outcome.Pn, Pt + outcome.Pt
            sequence.append("impact")
            continue
        flying = ~closed & (un < threshold)
        if not flying.any():
            break
        duration = float(np.min(gaps[flying] / -un[flying]))
        first = np.flatnonzero(flying)[np.argmin(gaps[flying] / -un[flying])]
        gaps = np.maximum(gaps + un * duration, 0.0)
        gaps[first] = 0.0
        sequence.append(f"flight to contact {first}")
    else:
        raise SolverFailure(f"{law.name}: contacts still approach after {max_events} events")
    diagnostics = {"formulation": "events through gaps", "events": sequence}
    return Outcome.from_velocity(problem, v, Pn, Pt, diagnostics=diagnostics)
