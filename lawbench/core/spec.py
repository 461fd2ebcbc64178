"""Specifications of named values: case parameters and law options.

A `Spec` says what a value means (doc, unit), what it may be (kind, bounds, choices) and what
it is by default, and turns what a user typed (a number, a list, or a string from the command
line such as ``"1,0,0"``) into a checked Python value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import KW_ONLY, dataclass
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem

KINDS = ("float", "int", "bool", "str", "floats")
_TRUE = {"true", "yes", "1", "on"}
_FALSE = {"false", "no", "0", "off"}
# The items of a list numpy converts to floats as Python's float() does; a list holding any
# other type (a bool, None, a nested list, a complex number) is read item by item.
_PLAIN_ITEMS = frozenset({float, int, str, np.float64})


@dataclass(frozen=True)
class Spec:
    """A named value of a case or a law.

    ``name``, ``default``, ``doc``, ``unit``, ``kind``, ``low``, ``high`` and ``low_open`` may
    be given in this order; ``choices`` and ``high_open`` only by keyword. A long positional
    construction reads better with its bounds named: ``Spec("tol", 1e-10, "tolerance",
    kind="float", low=0.0, high=0.1, low_open=True)``.

    Parameters
    ----------
    name : str
        The name users type.
    default : Any
        The value when none is given.
    doc : str
        What it means.
    unit : str
        SI unit, '' for dimensionless.
    kind : str
        'float', 'int', 'bool', 'str', or 'floats' (a list; a single number is a list of one).
    low, high : float or None
        Bounds of a number, or of every number of a list.
    low_open, high_open : bool
        Whether ``low`` or ``high`` itself is excluded.
    choices : tuple of str or None
        The allowed values of a 'str'.
    """

    name: str
    default: Any
    doc: str
    unit: str = ""
    kind: str = "float"
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    _: KW_ONLY
    choices: tuple[str, ...] | None = None
    high_open: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"Spec {self.name!r}: unknown kind {self.kind!r}")

    def describe_range(self) -> str:
        """The allowed values in words, for listings and messages."""
        if self.choices:
            return " | ".join(self.choices)
        if self.kind == "bool":
            return "true | false"
        if self.low is None and self.high is None:
            return "any"
        low = "-inf" if self.low is None else f"{self.low:g}"
        high = "inf)" if self.high is None else f"{self.high:g}{')' if self.high_open else ']'}"
        return f"{'(' if self.low_open or self.low is None else '['}{low}, {high}"

    def coerce(self, value: Any) -> Any:
        """Return ``value`` checked and converted to this spec's kind.

        Raises
        ------
        InvalidProblem
            Naming this spec and the value when it cannot be converted or is out of range.
        """
        if self.kind == "floats":
            items = value.split(",") if isinstance(value, str) else value
            if not isinstance(items, Sequence) or isinstance(items, str | bytes):
                items = [items]
            if len(items) == 0:
                raise InvalidProblem(f"{self.name} is empty: give at least one number")
            return self._numbers(items)
        if self.kind == "float":
            return self._number(self.name, value, float)
        if self.kind == "int":
            return self._number(self.name, value, int)
        if self.kind == "bool":
            return self._bool(value)
        text = str(value)
        if self.choices and text not in self.choices:
            raise InvalidProblem(
                f"{self.name} = {text!r}: must be one of {', '.join(self.choices)}"
            )
        return text

    def _bool(self, value: Any) -> bool:
        if isinstance(value, bool):
            return value
        text = str(value).strip().lower()
        if text in _TRUE | _FALSE:
            return text in _TRUE
        raise InvalidProblem(f"{self.name} = {value!r}: must be true or false")

    def _numbers(self, items: Sequence[Any]) -> list[float]:
        """The items of a 'floats' list, checked and converted in one pass over an array.

        A list that does not convert, or holds a number out of range, is read item by item,
        which raises naming the first bad one (``masses[3] = 'x': not a number``).
        """
        numbers = None
        if set(map(type, items)) <= _PLAIN_ITEMS:
            try:
                numbers = np.array(items, dtype=float)
            except (TypeError, ValueError, OverflowError):
                numbers = None
        if numbers is None or not self._all_allowed(numbers):
            return [self._number(f"{self.name}[{i}]", x, float) for i, x in enumerate(items)]
        return numbers.tolist()

    def _all_allowed(self, numbers: np.ndarray) -> bool:
        """Whether every entry of a float array is finite and within the bounds."""
        allowed = np.isfinite(numbers)
        if self.low is not None:
            allowed &= (numbers > self.low) if self.low_open else (numbers >= self.low)
        if self.high is not None:
            allowed &= (numbers < self.high) if self.high_open else (numbers <= self.high)
        return bool(allowed.all())

    def _number(self, label: str, value: Any, kind: type) -> float | int:
        try:
            number = float(value.strip() if isinstance(value, str) else value)
        except (TypeError, ValueError, OverflowError):
            # OverflowError: an integer beyond the largest double (10**400).
            raise InvalidProblem(f"{label} = {value!r}: not a number") from None
        if isinstance(value, bool):
            raise InvalidProblem(f"{label} = {value!r}: not a number")
        if not math.isfinite(number):
            raise InvalidProblem(f"{label} = {number}: must be a finite number")
        if kind is int:
            if number != int(number):
                raise InvalidProblem(f"{label} = {value!r}: must be a whole number")
            number = int(number)
        too_low = self.low is not None and (
            number < self.low or (self.low_open and number == self.low)
        )
        too_high = self.high is not None and (
            number > self.high or (self.high_open and number == self.high)
        )
        if too_low or too_high:
            raise InvalidProblem(f"{label} = {number:g}: must lie in {self.describe_range()}")
        return number
