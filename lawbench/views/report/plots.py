"""Shared figure helpers: figures without pyplot, law styles, log axes, units and labels."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatter

from lawbench.core.law import LAWS

UNIT = re.compile(r"[\[(]([^\])]+)[\])]\s*$")
# Exact zeros (an exact law against itself, no steps) are drawn at this floor on log axes.
FLOOR = 1e-17
MARKERS = "osD^v<>phP*X"
SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


class PowersOfTen(LogFormatter):
    """Log-axis tick labels in plain text with superscript exponents: 10⁻⁶, 2×10⁻⁶.

    Matplotlib's default labels are TeX-like, and laying them out took most of a report figure's
    drawing time.
    """

    def _num_to_string(self, x: float, vmin: float, vmax: float) -> str:
        exponent = math.floor(math.log10(x) + 1e-9)
        coefficient = round(x / 10.0**exponent)
        power = "10" + str(exponent).translate(SUPERSCRIPTS)
        return power if coefficient == 1 else f"{coefficient}×{power}"


def log_scale(ax: Axes, axes: str) -> None:
    """Put the ``axes`` of ``ax`` ('x', 'y' or 'xy') on a log scale labelled by `PowersOfTen`."""
    for name in axes:
        getattr(ax, f"set_{name}scale")("log")
        axis = ax.xaxis if name == "x" else ax.yaxis
        axis.set_major_formatter(PowersOfTen(10.0))
        axis.set_minor_formatter(PowersOfTen(10.0, labelOnlyBase=False))


def figure(rows: int, cols: int, width: float = 4.2, height: float = 3.2) -> tuple[Figure, Any]:
    """A new figure with a ``rows`` x ``cols`` grid of axes (always a 2-D array)."""
    fig = Figure(figsize=(cols * width, rows * height), layout="tight")
    return fig, fig.subplots(rows, cols, squeeze=False)


def law_style(name: str) -> dict[str, Any]:
    """Colour and marker of a law, the same in every figure of a report."""
    try:
        names = LAWS.names()
    except Exception:  # a registry that fails to load still gives each law a style
        names = []
    index = names.index(name) if name in names else len(names)
    return {
        "color": colormaps["tab10"](index % 10),
        "marker": MARKERS[index % len(MARKERS)],
        "label": name,
    }


def floored(values: Any) -> np.ndarray:
    """``values`` as floats with zeros and tinier values raised to `FLOOR` (NaN kept)."""
    array = np.asarray(values, dtype=float)
    return np.where(np.isnan(array), np.nan, np.maximum(np.abs(array), FLOOR))


def unit(coordinate: str) -> str:
    """The unit a coordinate's name ends with (``"omega [rad/s]"`` -> ``"rad/s"``), or ''."""
    found = UNIT.search(coordinate)
    return found.group(1) if found else ""


def by_unit(coordinates: list[str]) -> dict[str, list[int]]:
    """Indices of the coordinates per unit, in order: quantities of one unit share an axis."""
    groups: dict[str, list[int]] = {}
    for k, name in enumerate(coordinates):
        groups.setdefault(unit(name), []).append(k)
    return groups


def unit_label(name: str, units: Mapping[str, str]) -> str:
    """``name [unit]`` (``[-]`` dimensionless); a vector's component takes its measure's."""
    unit = units.get(name, units.get(name.split("[", 1)[0]))
    if unit is None:
        return f"{name} [unit not stated]"
    return f"{name} [{unit or '-'}]"
