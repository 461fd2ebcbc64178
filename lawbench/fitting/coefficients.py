"""The coefficients a fit frees: which scene parameter each is, its scale and its start.

Free parameters: a scalar parameter by name (``stiffness_ratio``, ``mu``); a list parameter by
name (``e``: one value for every contact) or one entry of it (``e[1]``). A parameter bounded
only below by an excluded zero (stiffness ratios, masses) is fitted on a log scale, so that the
search sees ratios rather than differences; the others on their own scale.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lawbench.core.case import Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.spec import Spec

_ITEM = re.compile(r"^(?P<name>[A-Za-z_]\w*)(\[(?P<index>\d+)\])?$")


@dataclass(frozen=True)
class Free:
    """One fitted coefficient: where it sits in the parameters and how it is scaled."""

    label: str
    spec: Spec
    index: int | None
    low: float
    high: float
    log: bool

    @property
    def name(self) -> str:
        """The name of the parameter the coefficient belongs to."""
        return self.spec.name

    def checked(self, value: object) -> float:
        """A starting value given for this coefficient, checked against its parameter's range.

        Raises
        ------
        InvalidProblem
            Naming ``start`` and the coefficient, for a value that is not a finite number in
            the parameter's range.
        """
        alone = dataclasses.replace(self.spec, name=f"start {self.label}", kind="float")
        return alone.coerce(value)

    def to_x(self, value: float) -> float:
        """The coefficient's ``value`` in the fitted scale (its logarithm on a log scale)."""
        return math.log(value) if self.log else value

    def to_value(self, x: float) -> float:
        """The coefficient's value at ``x`` of the fitted scale."""
        return math.exp(x) if self.log else x

    def bounds(self) -> tuple[float, float]:
        """The search's bounds in the fitted scale (none on a log scale)."""
        if self.log:
            return -np.inf, np.inf
        return self.low, self.high


def free_labels(free: object) -> list[str]:
    """The argument ``free`` as a list of names: one name, or a sequence of names.

    Raises
    ------
    TypeError
        For anything else, naming ``free`` (or the entry ``free[k]`` that is not a name).
    """
    names = [free] if isinstance(free, str) else free
    if not isinstance(names, Sequence):
        raise TypeError(
            f"free must be a coefficient name or a sequence of them, not {type(free).__name__}"
        )
    for k, name in enumerate(names):
        if not isinstance(name, str):
            raise TypeError(
                f"free[{k}] must be a coefficient name (str), not {type(name).__name__}"
            )
    return [name.strip() for name in names]


def as_dict(name: str, value: object) -> dict[str, Any]:
    """The argument ``name`` as a dict: a mapping of names to values, or None for none."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise TypeError(f"{name} must be a mapping of names to values, not {type(value).__name__}")
    return dict(value)


def free_coefficients(scene: Case, free: list[str], fixed: dict[str, Any]) -> list[Free]:
    """The coefficients named in ``free``.

    Each is a numeric parameter of ``scene``, or an entry of a list parameter that has it at the
    parameters ``fixed``.
    """
    specs = {s.name: s for s in scene.params}
    result: list[Free] = []
    for label in free:
        match = _ITEM.match(label)
        if match is None or match["name"] not in specs:
            raise InvalidProblem(
                f"free coefficient {label!r}: not a parameter of {scene.name} "
                f"(its numeric parameters: {', '.join(_numeric(specs.values()))})"
            )
        spec = specs[match["name"]]
        index = None if match["index"] is None else int(match["index"])
        if spec.kind not in ("float", "floats") or (index is not None and spec.kind != "floats"):
            raise InvalidProblem(
                f"free coefficient {label!r}: {spec.name} is a {spec.kind}, not a number to fit"
            )
        if index is not None:
            _check_index(label, spec.name, index, len(fixed[spec.name]))
        low = -np.inf if spec.low is None else spec.low
        high = np.inf if spec.high is None else spec.high
        log = spec.low == 0.0 and spec.low_open and spec.high is None
        result.append(Free(label, spec, index, low, high, log))
    labels = [f.label for f in result]
    if not result or len(set(labels)) < len(labels):
        raise InvalidProblem(f"free = {list(free)}: give distinct coefficients, at least one")
    return result


def _check_index(label: str, name: str, index: int, length: int) -> None:
    """Refuse entry ``index`` of list parameter ``name`` when it has only ``length`` entries."""
    if index >= length:
        entries = f"1 entry ({name}[0])" if length == 1 else f"{length} entries"
        last = "" if length == 1 else f" ({name}[0] to {name}[{length - 1}])"
        raise InvalidProblem(
            f"free coefficient {label!r}: {name} has {entries} at these parameters{last}"
        )


def _numeric(specs: Any) -> list[str]:
    return [s.name for s in specs if isinstance(s, Spec) and s.kind in ("float", "floats")]


def start_point(free: list[Free], fixed: dict[str, Any], start: dict[str, Any]) -> np.ndarray:
    """The starting point of the search, in the fitted scale.

    A coefficient starts at its value in ``start``, else at its value in ``fixed``; either is
    moved inside its bounds by a millionth of their span, so that the search begins inside.

    Raises
    ------
    InvalidProblem
        For a ``start`` that names no free coefficient or holds a value out of its range.
    """
    unknown = sorted(set(start) - {f.label for f in free}, key=str)
    if unknown:
        raise InvalidProblem(f"start {unknown[0]!r}: not a free coefficient")
    x0 = []
    for f in free:
        if f.label in start:
            value = f.checked(start[f.label])
        else:
            given = fixed[f.name]
            value = float(given[f.index or 0] if isinstance(given, list) else given)
        if f.log:
            x0.append(f.to_x(value))
            continue
        low, high = f.bounds()
        span = (high - low) if math.isfinite(high - low) else 1.0
        margin = 1e-6 * span
        x0.append(min(max(value, low + margin), high - margin))
    return np.array(x0)
