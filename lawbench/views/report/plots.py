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
from matplotlib.ticker import LogFormatter, LogLocator

from lawbench.core.law import LAWS

UNIT = re.compile(r"[\[(]([^\])]+)[\])]\s*$")
# Exact zeros (an exact law against itself, no steps) are drawn at this floor on log axes.
FLOOR = 1e-17
MARKERS = "osD^v<>phP*X"
SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
# The page shows a figure at most this wide (CSS px: the body's max-width); a wider SVG is
# scaled down, its text with it.
DISPLAY_WIDTH_PX = 1200.0
# CSS px per inch: an SVG's pt is 96/72 px in a browser.
CSS_DPI = 96.0
# A figure's panels together span at most this width (inches): shown at its natural size,
# 10 pt tick labels stay 13 px tall.
MAX_WIDTH = 11.5
LEGEND_FONT = "small"
# Inches between the legend below the panels and the figure's edge, and the panels' labels.
LEGEND_PAD = 0.1


class PowersOfTen(LogFormatter):
    """Log-axis tick labels in plain text with superscript exponents: 10⁻⁶, 2×10⁻⁶.

    Matplotlib's default labels are TeX-like, and laying them out took most of a report figure's
    drawing time. The major ticks' formatter labels decades; the minor ticks' one (``minor``)
    labels nothing on an axis that spans a decade or more, 2 and 5 times a power of ten on a
    shorter one, and 2, 3, 5 and 7 times below 0.4 of a decade: labels at least 0.14 decade
    apart, where 2, 3, 4 and 6 over a decade ran ``3×10⁻³`` into ``4×10⁻³``.
    """

    def __init__(self, minor: bool = False) -> None:
        super().__init__(10.0, labelOnlyBase=not minor)

    def set_locs(self, locs: Any = None) -> None:
        """Choose the minor ticks to label from the axis's span."""
        super().set_locs(locs)
        if self.labelOnlyBase or self.axis is None:
            return
        low, high = sorted(abs(v) for v in self.axis.get_view_interval())
        decades = math.log10(high / low) if low > 0 else math.inf
        self._sublabels = set() if decades >= 1 else {2, 5} if decades >= 0.4 else {2, 3, 5, 7}

    def _num_to_string(self, x: float, vmin: float, vmax: float) -> str:
        exponent = math.floor(math.log10(x) + 1e-9)
        coefficient = round(x / 10.0**exponent)
        if not math.isclose(x, coefficient * 10.0**exponent, rel_tol=1e-6):
            return ""  # a tick between multiples (2.5×10⁻⁴) would read as its neighbour's
        power = "10" + str(exponent).translate(SUPERSCRIPTS)
        return power if coefficient == 1 else f"{coefficient}×{power}"


def log_scale(ax: Axes, axes: str) -> None:
    """Put the ``axes`` of ``ax`` ('x', 'y' or 'xy') on a log scale labelled by `PowersOfTen`.

    At most six decades are labelled; over a wider span the labels skip decades.
    """
    for name in axes:
        getattr(ax, f"set_{name}scale")("log")
        axis = ax.xaxis if name == "x" else ax.yaxis
        axis.set_major_locator(LogLocator(10.0, numticks=6))
        axis.set_major_formatter(PowersOfTen())
        axis.set_minor_formatter(PowersOfTen(minor=True))


class ReportFigure(Figure):
    """A report figure: one legend for every panel, below the panels.

    Before each drawing every labelled line, bar or collection of every panel becomes one entry
    of a legend under the panels (one entry per label), and the panels' own legends are
    removed: a legend never hides a curve, an axis label or another panel, and a series drawn
    on one panel only (the ground truth's model) still has its entry. A figure that places a
    legend of its own (a figure legend, or a panel's legend of handles drawn nowhere) keeps it.
    """

    below: Any = None

    def draw(self, renderer: Any) -> None:
        """Gather the legends below the panels, then draw."""
        gather_legends(self)
        super().draw(renderer)


def gather_legends(fig: Figure) -> None:
    """Replace the panels' legends of ``fig`` by one legend below them (see `ReportFigure`)."""
    below = getattr(fig, "below", None)
    if any(legend is not below for legend in fig.legends):
        return
    entries: dict[str, Any] = {}
    title = None
    for ax in fig.axes:
        handles, labels = ax.get_legend_handles_labels()
        legend = ax.get_legend()
        if legend is not None and not {t.get_text() for t in legend.get_texts()} <= set(labels):
            continue  # its entries are handles of its own: it stays as placed
        entries |= {k: h for h, k in zip(handles, labels, strict=True) if k not in entries}
        if legend is not None:
            title = title or legend.get_title().get_text() or None
            legend.remove()
    if below is not None:
        below.remove()
    fig.below = None
    if not entries:
        return
    widest = max(len(k) for k in entries) * 0.075 + 0.6  # inches per column at 'small' text
    columns = max(1, min(len(entries), int(fig.get_figwidth() // widest)))
    fig.below = fig.legend(
        list(entries.values()),
        list(entries),
        loc="lower center",
        bbox_to_anchor=(0.5, LEGEND_PAD / fig.get_figheight()),
        ncols=columns,
        fontsize=LEGEND_FONT,
        title=title,
        frameon=False,
    )


def lay_out_once(fig: Figure) -> None:
    """Lay ``fig`` out for saving, once: its legend below the panels in a band of its own.

    The figure grows by the legend's height, the panels keeping their size above it; the layout
    then runs and stays as it is. Saved with a layout engine, or with a tight bounding box around
    a legend hanging below the figure, a figure is drawn twice.
    """
    gather_legends(fig)
    engine = fig.get_layout_engine()
    legend = getattr(fig, "below", None)
    renderer = fig.canvas.get_renderer()
    if legend is not None:
        band = legend.get_window_extent(renderer).height / fig.dpi + 2 * LEGEND_PAD
        height = fig.get_figheight() + band
        fig.set_figheight(height)
        engine.set(rect=(0.0, band / height, 1.0, 1.0))
        gather_legends(fig)  # anchored anew at the grown figure's bottom
    if engine is not None:
        engine.execute(fig)
        fig.set_layout_engine(None)


def figure(rows: int, cols: int, width: float = 4.2, height: float = 3.2) -> tuple[Figure, Any]:
    """A new `ReportFigure` with a ``rows`` x ``cols`` grid of axes (always a 2-D array).

    Panels are ``width`` x ``height`` inches, narrowed so that a row spans at most
    `MAX_WIDTH`: the page then shows the figure at its natural size.
    """
    width = min(width, MAX_WIDTH / cols)
    fig = ReportFigure(figsize=(cols * width, rows * height), layout="tight")
    return fig, fig.subplots(rows, cols, squeeze=False)


def displayed_height(fontsize: float, natural_width_px: float) -> float:
    """CSS px of text of ``fontsize`` pt in an SVG ``natural_width_px`` wide, as the page shows it.

    The SVG is drawn at its natural width up to `DISPLAY_WIDTH_PX`, scaled down beyond.
    """
    scale = min(1.0, DISPLAY_WIDTH_PX / natural_width_px)
    return fontsize * CSS_DPI / 72.0 * scale


def law_style(name: str) -> dict[str, Any]:
    """Colour and marker of a law, the same in every figure of a report."""
    try:
        names = LAWS.names()
    except Exception:  # a registry that fails to load still gives each law a style
        names = []
    index = names.index(name) if name in names else len(names)
    return {
        # Twenty distinct colours: tab10's, then their lighter partners in tab20.
        "color": colormaps["tab20"]((2 * index + index // 10) % 20),
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
