"""`fit`: the scene parameters with which a law best reproduces measured trials.

`fit` finds the scene parameters (restitution, friction, stiffness ratio, ...) by nonlinear
least squares within the bounds of the parameters' `Spec` ranges, in named steps: check the
arguments, set the model up, split off the held-back trials, fit, judge the uncertainty
(`lawbench.fitting.uncertainty`), then score the held-back trials and refit on bootstrap
resamples. ``bootstrap`` refits on trials resampled with replacement; ``holdout`` keeps a
fraction of the trials out of the fit and reports the residual there, the fair way to compare
laws on one experiment.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.case import CASES, Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS, Law
from lawbench.core.spec import Spec
from lawbench.fitting.coefficients import as_dict, free_coefficients, free_labels, start_point
from lawbench.fitting.model import Model, least_squares
from lawbench.fitting.result import FitResult
from lawbench.fitting.trials import read_trials
from lawbench.fitting.uncertainty import FLAT_TOL, summarize

# The ranges of fit's numeric arguments. The noise is the standard deviation of a measured
# velocity: below 1e-12 m/s no measurement resolves a velocity, above 1e6 m/s it measures
# nothing; scipy's tolerances must exceed the machine epsilon.
RANGES = {
    spec.name: spec
    for spec in (
        Spec(
            "noise",
            None,
            "a measured velocity's standard deviation",
            unit="m/s",
            low=1e-12,
            high=1e6,
        ),
        Spec("holdout", 0.0, "share of the trials kept out", low=0.0, high=1.0, high_open=True),
        Spec("bootstrap", 0, "refits on resampled trials", kind="int", low=0, high=100_000),
        Spec("seed", 0, "seed of the resampling", kind="int", low=0),
        Spec("tol", 1e-10, "tolerance of the least squares", low=1e-15, high=0.1),
        Spec("diff_step", 1e-6, "relative step of the finite differences", low=1e-12, high=0.1),
        Spec("flat_tol", FLAT_TOL, "singular value ratio of a flat direction", low=0.0, high=0.5),
    )
}


@dataclass(frozen=True)
class _Trials:
    """The measured velocities, and which trials are fitted and which held back."""

    v_minus: np.ndarray
    v_plus: np.ndarray
    kept: np.ndarray
    held: np.ndarray


def fit(
    law: str | Law,
    case: str | Case,
    data: str | Path | pd.DataFrame,
    free: Sequence[str],
    params: Mapping[str, Any] | None = None,
    options: Mapping[str, Any] | None = None,
    start: Mapping[str, float] | None = None,
    noise: float | None = None,
    holdout: float = 0.0,
    bootstrap: int = 0,
    seed: int = 0,
    tol: float = 1e-10,
    diff_step: float = 1e-6,
    flat_tol: float = FLAT_TOL,
) -> FitResult:
    """Fit ``free`` coefficients of ``law`` on ``case`` to measured trials.

    Parameters
    ----------
    law, case : str, Law or Case
        The law whose coefficients are identified, and the scene of the experiment.
    data : path or DataFrame
        Trials: columns ``<coordinate>_minus`` and ``<coordinate>_plus`` (`columns`).
    free : str or sequence of str
        Parameter names, or ``name[i]`` for one entry of a list (below its length at ``params``).
    params, options : mapping, optional
        Scene parameters held fixed (the others take their defaults); the law's options.
    start : mapping, optional
        Starting values of free coefficients in their parameters' ranges (default: ``params``
        or the default), moved inside the bounds by a millionth of their span.
    noise : float, optional
        Standard deviation of a measured velocity: when given, the residual is judged.
    holdout, bootstrap, seed : float, int, int
        Share of the trials held back, refits on resampled trials, seed of both.
    tol, diff_step, flat_tol : float
        scipy's ``ftol = xtol = gtol``; relative finite-difference step of the Jacobian (above
        the law's own accuracy); relative singular value of a flat direction.

    Returns
    -------
    FitResult

    Raises
    ------
    InvalidProblem
        Bad data, an unknown coefficient or list entry, a bad option, a number out of range.
    TypeError
        Naming the argument of the wrong type (``free`` not names, ``seed`` not an integer, ...).
    NotApplicable
        The law cannot treat the scene.

    Examples
    --------
    >>> import numpy as np, pandas as pd, lawbench
    >>> v = np.array([[-1.0, 0.0], [-2.0, 0.5]])
    >>> after = [lawbench.solve("newton", "two_balls_wall", velocities=list(r), e=[0.5]).v_plus
    ...          for r in v]
    >>> columns = ["v1_minus", "v2_minus", "v1_plus", "v2_plus"]
    >>> data = pd.DataFrame(np.hstack([v, after]), columns=columns)
    >>> round(lawbench.fit("newton", "two_balls_wall", data, free=["e"]).values["e"], 8)
    0.5
    """
    numbers_given = {"holdout": holdout, "bootstrap": bootstrap, "seed": seed, "tol": tol}
    _check_numbers(noise, **numbers_given, diff_step=diff_step, flat_tol=flat_tol)
    model, start = _model(law, case, free, params, options, start)
    velocities = read_trials(data, model.scene, model.fixed)
    x0 = start_point(model.free, model.fixed, start)
    rng = np.random.default_rng(seed)
    trials = _split(velocities, holdout, rng)
    kept = trials.kept
    solution = least_squares(model, x0, trials.v_minus[kept], trials.v_plus[kept], tol, diff_step)
    result = summarize(model, solution, trials.v_minus[kept], trials.v_plus[kept], noise, flat_tol)
    result.law, result.case, result.trials = model.law.name, model.scene.name, kept
    if len(trials.held):
        _score_held_out(result, model, solution.x, trials)
    if bootstrap:
        result.bootstrap = _bootstrap(model, solution.x, trials, bootstrap, rng, tol, diff_step)
    return result


def _check_numbers(noise: float | None, **given: object) -> None:
    """Refuse a numeric argument of `fit` of the wrong type or outside its range (`RANGES`)."""
    if noise is not None:
        given["noise"] = noise
    for name, value in given.items():
        spec = RANGES[name]
        whole = spec.kind == "int"
        if not isinstance(value, numbers.Integral if whole else numbers.Real) or isinstance(
            value, bool
        ):
            wanted = "an integer" if whole else "a real number"
            raise TypeError(f"{name} must be {wanted}, not {type(value).__name__}")
        spec.coerce(value)


def _model(
    law: str | Law,
    case: str | Case,
    free: Sequence[str],
    params: Mapping[str, Any] | None,
    options: Mapping[str, Any] | None,
    start: Mapping[str, float] | None,
) -> tuple[Model, dict[str, Any]]:
    """The model of ``law`` on ``case`` with its ``free`` coefficients, and ``start`` checked.

    Raises
    ------
    TypeError, InvalidProblem
        As `fit` does, for its arguments ``free``, ``start``, ``params`` and ``options``.
    """
    labels, starts = free_labels(free), as_dict("start", start)
    law_obj, scene = LAWS.get(law), CASES.get(case)
    fixed = scene.parameters(**as_dict("params", params))
    law_opts = law_obj.option_values(as_dict("options", options))
    coefficients = free_coefficients(scene, labels, fixed)
    return Model(law_obj, scene, coefficients, fixed, law_opts), starts


def _split(
    velocities: tuple[np.ndarray, np.ndarray], holdout: float, rng: np.random.Generator
) -> _Trials:
    """The trials, a share ``holdout`` of them (drawn with ``rng``) held back from the fit.

    Raises
    ------
    InvalidProblem
        When the share held back leaves no trial to fit.
    """
    v_minus, v_plus = velocities
    count = len(v_minus)
    order = rng.permutation(count)
    held = np.sort(order[: round(holdout * count)]) if holdout else np.zeros(0, dtype=int)
    kept = np.setdiff1d(np.arange(count), held)
    if len(kept) == 0:
        raise InvalidProblem(f"holdout = {holdout:g} leaves no trial to fit")
    return _Trials(v_minus, v_plus, kept, held)


def _score_held_out(result: FitResult, model: Model, x: np.ndarray, trials: _Trials) -> None:
    """Record in ``result`` the residuals of the held-back trials at the fitted ``x``."""
    held = trials.held
    predicted = model.predict(x, trials.v_minus[held])
    per_trial = np.sqrt(((predicted - trials.v_plus[held]) ** 2).mean(axis=1))
    result.held_out, result.holdout_residuals = held, per_trial
    result.holdout_rms = float(np.sqrt((per_trial**2).mean()))


def _bootstrap(
    model: Model,
    x: np.ndarray,
    trials: _Trials,
    count: int,
    rng: np.random.Generator,
    tol: float,
    diff_step: float,
) -> dict[str, np.ndarray]:
    """Coefficient -> its ``count`` refits from ``x``, on fitted trials drawn with replacement."""
    kept, coefficients = trials.kept, model.free
    draws = np.empty((count, len(coefficients)))
    for b in range(count):
        pick = rng.choice(kept, size=len(kept), replace=True)
        again = least_squares(model, x, trials.v_minus[pick], trials.v_plus[pick], tol, diff_step)
        draws[b] = [f.to_value(float(xi)) for f, xi in zip(coefficients, again.x, strict=True)]
    return {f.label: draws[:, i] for i, f in enumerate(coefficients)}
