"""Measured trials: the pre- and post-impact velocities a fit reproduces.

Data: one row per trial, two columns per generalized coordinate of the scene, named after the
coordinate (its name without the unit, ``v1 [m/s]`` -> ``v1``) with ``_minus`` for the
pre-impact and ``_plus`` for the post-impact velocity: ``v1_minus, v2_minus, v1_plus,
v2_plus`` for the ping-pong stack (`columns` lists them). Other columns are ignored. Every trial
is the scene built at the parameters, with its pre-impact velocity replaced by the measured one.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import CASES, Case
from lawbench.core.errors import InvalidProblem
from lawbench.files.paths import input_file


def coordinate_key(name: str) -> str:
    """A coordinate's name without its unit: ``'v1 [m/s]'`` -> ``'v1'``."""
    return name.split(" [")[0].strip()


def columns(case: str | Case, params: Mapping[str, Any] | None = None) -> tuple[list, list]:
    """The data columns of ``case``: pre-impact (``*_minus``) and post-impact (``*_plus``)."""
    scene = CASES.get(case)
    keys = [coordinate_key(c) for c in scene.coordinates(scene.parameters(**dict(params or {})))]
    return [f"{k}_minus" for k in keys], [f"{k}_plus" for k in keys]


def read_trials(
    data: str | Path | pd.DataFrame, case: str | Case, params: Mapping[str, Any] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Pre- and post-impact velocities (trials x coordinates) of a CSV file or a data frame.

    Raises
    ------
    InvalidProblem
        A file that cannot be read as CSV (the reason in one line), a missing column, or a
        value that is not a finite number, naming its row (1 is the first trial) and column.
    """
    if isinstance(data, pd.DataFrame):
        frame = data.astype(str)
    else:
        try:
            frame = pd.read_csv(
                input_file(data, "data"), dtype=str, keep_default_na=False, skipinitialspace=True
            )
        except (
            OSError,
            UnicodeDecodeError,
            pd.errors.ParserError,
            pd.errors.EmptyDataError,
        ) as exc:
            reason = " ".join(str(exc).split())  # the parser's message may span lines
            raise InvalidProblem(f"data {str(data)!r}: cannot be read ({reason})") from None
    frame.columns = [str(c).strip() for c in frame.columns]
    minus, plus = columns(case, params)
    missing = [c for c in minus + plus if c not in frame.columns]
    if missing:
        raise InvalidProblem(
            f"data: column {missing[0]!r} missing in every row (the scene needs "
            f"{', '.join(minus + plus)})"
        )
    if len(frame) == 0:
        raise InvalidProblem("data: no trials (no rows)")
    values = np.empty((len(frame), len(minus + plus)))
    for j, name in enumerate(minus + plus):
        for i, text in enumerate(frame[name]):
            try:
                number = float(str(text).strip())
            except ValueError:
                number = math.nan
            if not math.isfinite(number):
                raise InvalidProblem(
                    f"data: row {i + 1}, column {name!r}: {text!r} is not a number"
                )
            values[i, j] = number
    n = len(minus)
    return values[:, :n], values[:, n:]
