"""Figures of an outcome, of a path inside an impact, and of a run table, the matplotlib way.

Each function draws on the axes ``ax`` it is given, or on a new figure's axes when ``ax`` is
None, and returns the axes, so figures compose::

    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2)
    lawbench.plot_outcome(trial, ax=left)
    lawbench.plot_path(lawbench.solve("lzb", "three_ball_chain", {"path": True}), ax=right)

Colours, markers and unit labels are the report's (`lawbench.views.report.plots`): a law has the
same colour here as in every figure of the report. A legend sits right of its axes, never on
them (a figure laid out ``tight`` or ``constrained`` makes room for it).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.outcome import Outcome
from lawbench.core.trial import Trial
from lawbench.views.report import plots
from lawbench.views.report.inside import QUANTITIES

if TYPE_CHECKING:
    from matplotlib.axes import Axes

# Units of a run table's columns that are not scene parameters.
RECORD_UNITS = {"T_minus": "J", "T_plus": "J", "dT": "J", "Pn": "N s", "Pt": "N s"}
RECORD_UNITS |= {"wall_time_s": "s", "spent_s": "s"}
COMPONENT = re.compile(r"^(.+)\[(\d+)\]$")


def _axes(ax: Axes | None) -> Axes:
    """``ax``, or the axes of a new pyplot figure."""
    from matplotlib.axes import Axes

    if isinstance(ax, Axes):
        return ax
    if ax is not None:
        raise TypeError(f"ax must be matplotlib Axes or None, not {type(ax).__name__}")
    import matplotlib.pyplot as plt

    return plt.figure().add_subplot()


def _legend(ax: Axes, **options: Any) -> None:
    """The legend of ``ax`` beside it, right of the axes: it never hides a curve or a label."""
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0), **options)


def _outcome(result: Outcome | Trial) -> Outcome:
    """The outcome of the argument ``outcome``: an `Outcome`, or a `Trial`'s."""
    if isinstance(result, Trial):
        return result.outcome
    if not isinstance(result, Outcome):
        raise TypeError(f"outcome must be an Outcome or a Trial, not {type(result).__name__}")
    return result


def plot_outcome(
    outcome: Outcome | Trial, ax: Axes | None = None, *, coordinates: Sequence[str] | None = None
) -> Axes:
    """Bars of the pre- and post-impact velocity of every generalized coordinate.

    Parameters
    ----------
    outcome : Outcome or Trial
        A law's answer (`lawbench.solve`), or a trial (`lawbench.evaluate`), which also names
        the scene's coordinates.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure's axes when None.
    coordinates : sequence of str, optional
        The coordinates' names (``"v1 [m/s]"``); the scene's for a trial on a scene, else
        ``q1, q2, ...``.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on: two bars per coordinate (before, after), titled with the kinetic
        energy before and after.
    """
    result = _outcome(outcome)
    if coordinates is None and isinstance(outcome, Trial) and outcome.case is not None:
        coordinates = outcome.case.coordinates(outcome.params)
    names = list(coordinates or [f"q{k + 1}" for k in range(len(result.v_plus))])
    ax = _axes(ax)
    x = np.arange(len(names))
    if result.v_minus is not None:
        ax.bar(x - 0.2, result.v_minus, 0.4, label="before (v-)", color="0.65")
    ax.bar(x + 0.2, result.v_plus, 0.4, label="after (v+)", color="tab:blue")
    ax.axhline(0.0, color="black", linewidth=0.6)
    ax.set_xticks(x, [name.split(" [", 1)[0] for name in names])
    units = set(plots.by_unit(names))
    unit = units.pop() if len(units) == 1 else ""  # coordinates of several units share no unit
    ax.set_ylabel(f"velocity [{unit}]" if unit else "velocity")
    ax.set_title(f"T- = {result.T_minus:.4g} J, T+ = {result.T_plus:.4g} J")
    _legend(ax)
    return ax


def plot_path(outcome: Outcome | Trial, key: str = "stored_energy", ax: Axes | None = None) -> Axes:
    """A quantity along the impact against the impact variable, one line per component.

    Parameters
    ----------
    outcome : Outcome or Trial
        An answer solved with the option ``path=True`` of a law that follows the impact.
    key : str
        The path's quantity to draw (``stored_energy``, ``Pn``, ``force``, ``v``...).
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure's axes when None.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on; the abscissa is the path's first entry (time, normal impulse or
        the impulse-curve parameter), both axes labelled with their units.

    Raises
    ------
    InvalidProblem
        For an outcome without a path, or a ``key`` the path does not hold.
    """
    path = _outcome(outcome).path
    if not path:
        raise InvalidProblem("the outcome has no path: solve it with the law's option path=True")
    if key not in path:
        raise InvalidProblem(f"the path has no {key!r}; it holds {', '.join(path)}")
    x_key = next(iter(path))
    x = np.asarray(path[x_key], dtype=float).reshape(-1)
    values = np.asarray(path[key], dtype=float).reshape(len(x), -1)
    ax = _axes(ax)
    for j in range(values.shape[1]):
        ax.plot(x, values[:, j], label=f"{key}[{j}]" if values.shape[1] > 1 else key)
    ax.set_xlabel(_quantity(x_key))
    ax.set_ylabel(_quantity(key))
    if values.shape[1] > 1:
        _legend(ax)
    return ax


def _quantity(key: str) -> str:
    """A path entry's name and unit, ``stored energy [J]``."""
    name, unit = QUANTITIES.get(key, (key, "unit not stated"))
    return f"{name} [{unit}]"


def plot_sweep(
    frame: pd.DataFrame, x: str, y: str, ax: Axes | None = None, by: str = "law"
) -> Axes:
    """``y`` against ``x`` over the cells of a run table, one line per value of ``by``.

    Parameters
    ----------
    frame : pandas.DataFrame
        A run's or a study's table (`lawbench.load_run`).
    x, y : str
        Columns: a grid parameter, a measure, ``dT``; ``NAME[k]`` takes entry k of a list
        column (``v_plus[2]``, ``Pn[0]``).
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure's axes when None.
    by : str
        The column whose values are the lines; a law keeps its colour and marker of the report.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on; a cell without a value (a refused cell) leaves a gap out.

    Raises
    ------
    InvalidProblem
        For a column the table does not have.
    """
    if not isinstance(frame, pd.DataFrame):
        raise TypeError(f"frame must be a pandas DataFrame, not {type(frame).__name__}")
    drawn = pd.DataFrame({"x": _column(frame, x), "y": _column(frame, y), "by": _column(frame, by)})
    ax = _axes(ax)
    for name, group in drawn.dropna().groupby("by", sort=True):
        style = plots.law_style(str(name)) if by == "law" else {"marker": "o", "label": str(name)}
        ordered = group.sort_values("x")
        ax.plot(ordered["x"], ordered["y"], **style)
    units = _units(frame)
    ax.set_xlabel(plots.unit_label(x, units))
    ax.set_ylabel(plots.unit_label(y, units))
    _legend(ax, title=by)
    return ax


def _column(frame: pd.DataFrame, name: str) -> pd.Series:
    """A column of ``frame``, or entry k of a list column for ``NAME[k]``."""
    if name in frame:
        return frame[name]
    found = COMPONENT.match(name)
    if found and found.group(1) in frame:
        k = int(found.group(2))
        return frame[found.group(1)].map(lambda v: _entry(v, k))
    raise InvalidProblem(f"the table has no column {name!r}; it has {', '.join(frame.columns)}")


def _entry(vector: Any, k: int) -> float:
    if vector is None or not hasattr(vector, "__len__") or len(vector) <= k:
        return np.nan
    return float(vector[k])


def _units(frame: pd.DataFrame) -> dict[str, str]:
    """Unit per column: the scenes' parameters, the outcome's, the velocity's coordinates."""
    units = dict(RECORD_UNITS)
    for name in frame["case"].dropna().unique() if "case" in frame else []:
        case = CASES.get(name)
        units |= {spec.name: spec.unit for spec in case.params}
        coordinates = case.coordinates(case.parameters())
        units |= {f"v_plus[{k}]": plots.unit(c) for k, c in enumerate(coordinates)}
    return units


# One line style per method of a law, which keeps its colour.
LINE_STYLES = ("-", "--", ":", "-.")


def plot_profiles(ratios: Mapping[str, Sequence[float]], ax: Axes | None = None) -> Axes:
    """Dolan and Moré's (2002) performance profiles: per solver, the share of problems solved.

    Parameters
    ----------
    ratios : mapping of str to sequence of float
        Per solver (``"LAW METHOD"``), its time over the fastest solver's on each problem, inf
        where it did not solve it (`lawbench.bench.performance_profiles`).
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure's axes when None.

    Returns
    -------
    matplotlib.axes.Axes
        A step line per solver: the share of problems it solves within a factor tau of the
        fastest, tau on a log axis.
    """
    ax = _axes(ax)
    finite = [r[np.isfinite(r)] for r in map(np.asarray, ratios.values())]
    right = 2.0 * max((float(r.max()) for r in finite if r.size), default=1.0)
    seen: dict[str, int] = {}
    for (solver, r), solved in zip(ratios.items(), finite, strict=True):
        taus = np.concatenate([[1.0], np.sort(solved), [right]])
        shares = np.concatenate([[0.0], np.arange(1, solved.size + 1), [solved.size]])
        law = solver.split(" ")[0]
        seen[law] = seen.get(law, -1) + 1
        style = {"color": plots.law_style(law)["color"], "linestyle": LINE_STYLES[seen[law] % 4]}
        ax.step(taus, shares / len(r), where="post", label=solver, **style)
    plots.log_scale(ax, "x")
    ax.set_xlabel("tau: time over the fastest solver's")
    ax.set_ylabel("share of problems solved within tau")
    ax.set_ylim(0.0, 1.05)
    if ratios:
        _legend(ax)
    return ax
