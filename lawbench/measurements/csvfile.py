"""A user's own measured impacts, read from a CSV file as a measurement set.

One row per impact, with a header naming the columns (any order, further columns ignored):

=============  ===========================================================================
``n``          number of generalized coordinates
``m``          number of contacts
``d``          tangential directions per contact: 0 (frictionless, ``Wt`` empty), 1 or 2
``M``          the mass matrix, n*n numbers row by row
``Wn``         the normal Jacobian (n, m), n*m numbers row by row
``Wt``         the tangential Jacobian (n, m*d), n*m*d numbers row by row; empty when d = 0
``v_before``   the generalized velocity before the impact, n numbers
``v_after``    the generalized velocity measured after it, n numbers
``sigma``      optional: the standard uncertainty of ``v_after``, n numbers (or empty)
``train``      optional: 1 for an impact of the training half, 0 for the test half
=============  ===========================================================================

Numbers inside a cell are separated by spaces. The conventions are lawbench's: ``Wn.T @ v``
is the contacts' gap rate, negative when approaching. Without a ``train`` column the split is
drawn from the set's fixed seed. A bad cell raises `InvalidProblem` naming its column and its
row (the first row after the header is row 1).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.problem import ImpactProblem
from lawbench.measurements.impacts import (
    MeasuredImpact,
    MeasurementSet,
    Processing,
    Source,
    training_mask,
)

REQUIRED = ("n", "m", "d", "M", "Wn", "Wt", "v_before", "v_after")


def _numbers(row: dict[str, str], column: str, count: int, index: int) -> np.ndarray:
    """The ``count`` numbers of ``column`` in the row numbered ``index``."""
    text = (row.get(column) or "").strip()
    try:
        values = np.array([float(x) for x in text.split()], dtype=float)
    except ValueError:
        raise InvalidProblem(f"column {column!r}, row {index}: {text!r} is not numbers") from None
    if values.size != count or not np.isfinite(values).all():
        raise InvalidProblem(
            f"column {column!r}, row {index}: {values.size} numbers, expected {count} finite ones"
        )
    return values


def _count(row: dict[str, str], column: str, index: int, low: int) -> int:
    """The whole number of ``column`` in the row numbered ``index``, at least ``low``."""
    text = (row.get(column) or "").strip()
    if not text.isdigit() or int(text) < low:
        raise InvalidProblem(f"column {column!r}, row {index}: {text!r} is not a count >= {low}")
    return int(text)


def _impact(row: dict[str, str], index: int, name: str) -> MeasuredImpact:
    """The measured impact of one row."""
    n, m, d = (_count(row, c, index, low) for c, low in (("n", 1), ("m", 1), ("d", 0)))
    if d > 2:
        raise InvalidProblem(f"column 'd', row {index}: {d}, expected 0, 1 or 2")
    M = _numbers(row, "M", n * n, index).reshape(n, n)
    Wn = _numbers(row, "Wn", n * m, index).reshape(n, m)
    Wt = _numbers(row, "Wt", n * m * d, index).reshape(n, m * d) if d else None
    v = _numbers(row, "v_before", n, index)
    after = _numbers(row, "v_after", n, index)
    sigma = _numbers(row, "sigma", n, index) if (row.get("sigma") or "").strip() else None
    try:
        problem = ImpactProblem.from_arrays(M, Wn, v, Wt, e=0.0, mu=0.0)
        return MeasuredImpact(problem, after, sigma, name, index, {})
    except InvalidProblem as exc:
        raise InvalidProblem(f"row {index}: {exc}") from None


def read_csv(path: str | Path, name: str | None = None) -> MeasurementSet:
    """Read a CSV file of measured impacts (columns in the module's docstring) as a set.

    Raises
    ------
    InvalidProblem
        For a missing column or a bad cell, naming the column and the row.
    """
    path = Path(path)
    name = name or path.stem
    with path.open(newline="", encoding="utf-8") as handle:
        reader = csv.DictReader(handle)
        missing = [c for c in REQUIRED if c not in (reader.fieldnames or ())]
        if missing:
            raise InvalidProblem(
                f"{path.name}: missing column(s) {missing}; needs {list(REQUIRED)}"
            )
        rows = list(reader)
    impacts = [_impact(row, index, name) for index, row in enumerate(rows, start=1)]
    if rows and "train" in rows[0]:
        train = np.array([_count(r, "train", i, 0) == 1 for i, r in enumerate(rows, 1)])
    else:
        train = training_mask(len(impacts))
    processing = Processing(f"read from {path.name}, every row", len(impacts), {})
    source = Source(paper="", repository="", commit="", path=str(path), licence="")
    return MeasurementSet(
        name, f"measured impacts of {path.name}", source, lambda: (impacts, train, processing)
    )
