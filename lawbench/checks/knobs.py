"""Values a sweep gives: powers of ten, and the values of a law's accuracy knob.

A law names its accuracy knob in its tags (``accuracy_knob``: a tolerance, a number of steps, a
choice of method). `knob_values` is what a speed/accuracy sweep gives that knob, `tightest` the
options of the law's own converged answer, the yardstick of its numerical error
(`lawbench.checks.measures.numerical_error`). Both keep to the values the knob's `Spec`
accepts, so a law whose tolerance stops at 1e-10 is never asked for 1e-12, and to the finest
time step a law declares (``Tags.finest_knob``): an engine stepped at 1e-12 s would need 1e10
steps for a 10 ms impact, and ran into its step bound instead of answering.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.core.errors import InvalidProblem

if TYPE_CHECKING:
    from lawbench.core.law import Law
    from lawbench.core.spec import Spec

# Values of an integer accuracy knob in a sweep.
INT_KNOBS = (10, 100, 1_000, 10_000, 100_000)
# The tightest value tried for a numeric accuracy knob (or the nearest its spec accepts).
TIGHTEST = 1e-12


def decades(start: int, stop: int, step: int = 1) -> list[float]:
    """Powers of ten ``10**start ... 10**stop`` (both included) every ``step`` decades."""
    return [float(10.0**k) for k in range(start, stop + int(np.sign(step)), step)]


def knob_values(law: Law, values: Sequence[float]) -> tuple[str | None, list[Any]]:
    """A law's accuracy knob and the values a sweep gives it.

    Those of ``values`` its spec accepts, every choice of a choice knob, a few decades of an
    integer one; ``(None, [None])`` for an exact law.
    """
    knob = law.tags.accuracy_knob
    spec = next((s for s in law.options if s.name == knob), None)
    if spec is None:
        return None, [None]
    if spec.choices:
        return knob, list(spec.choices)
    if spec.kind == "bool":
        return knob, [False, True]
    candidates = INT_KNOBS if spec.kind == "int" else values
    finest = law.tags.finest_knob
    kept = [v for v in candidates if _accepts(spec, v) and (finest is None or v >= finest)]
    return knob, kept or [spec.default]


def tightest(law: Law) -> dict[str, Any]:
    """Options at a law's tightest numeric knob; {} for an exact law or a choice knob."""
    knob = law.tags.accuracy_knob
    spec = next((s for s in law.options if s.name == knob), None)
    if spec is None or spec.choices or spec.kind in ("bool", "str"):
        return {}
    if spec.kind == "int":
        return {knob: max(v for v in (*INT_KNOBS, spec.default) if _accepts(spec, v))}
    if law.tags.finest_knob is not None:
        return {knob: law.tags.finest_knob}
    accepted = [TIGHTEST * 10.0**k for k in range(12) if _accepts(spec, TIGHTEST * 10.0**k)]
    return {knob: accepted[0]} if accepted else {}


def _accepts(spec: Spec, value: Any) -> bool:
    try:
        spec.coerce(value)
    except InvalidProblem:
        return False
    return True
