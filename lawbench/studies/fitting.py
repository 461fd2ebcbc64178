"""Identify a law's coefficients from measured pre- and post-impact velocities.

`fit` finds the scene parameters (restitution, friction, stiffness ratio, ...) with which a law
best reproduces measured trials, by nonlinear least squares (`scipy.optimize.least_squares`,
trust-region reflective) within the bounds of the parameters' `Spec` ranges.

Data: one row per trial, two columns per generalized coordinate of the scene, named after the
coordinate (its name without the unit, ``v1 [m/s]`` -> ``v1``) with ``_minus`` for the
pre-impact and ``_plus`` for the post-impact velocity: ``v1_minus, v2_minus, v1_plus,
v2_plus`` for the ping-pong stack (`columns` lists them). Other columns are ignored. Every trial
is the scene built at the parameters, with its pre-impact velocity replaced by the measured one.

Free parameters: a scalar parameter by name (``stiffness_ratio``, ``mu``); a list parameter by
name (``e``: one value for every contact) or one entry of it (``e[1]``). A parameter bounded
only below by an excluded zero (stiffness ratios, masses) is fitted on a log scale, so that the
search sees ratios rather than differences; the others on their own scale.

Uncertainty, from the Jacobian J of the residuals at the optimum (in the fitted scale): the
noise variance is estimated as ``s^2 = RSS / (N - p)`` (N residuals, p coefficients), the
covariance is ``s^2 (J^T J)^-1``, mapped to the parameters' own scale by the delta method. A
singular value of J below ``flat_tol`` times the largest is a flat direction: the coefficients
that carry it are reported as not identifiable from the data (infinite standard error), and the
covariance of the others is taken on the orthogonal complement; a coefficient the law's answer
does not change with (a zero column of J: the law does not read it) is named as such, and its
correlations are undefined, printed as ``-`` and written as null. With ``noise`` (the standard
deviation of a measured velocity) the residual is also judged: a sum of squares above the
99.9% quantile of ``noise^2 chi^2(N - p)`` says the law cannot fit the data. ``bootstrap``
refits on trials resampled with replacement; ``holdout`` keeps a fraction of the trials out of
the fit and reports the residual there, the fair way to compare laws on one experiment.

Residuals are in the coordinates' own units, unweighted.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import optimize, stats

from lawbench.core.case import CASES, Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS, Law
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.files.paths import input_file

# Relative singular value of the Jacobian below which a direction counts as flat.
FLAT_TOL = 1e-4
# A coefficient carries a flat direction when its share of the singular vector exceeds this.
FLAT_SHARE = 0.3
# The law cannot fit when the residual exceeds this quantile of the noise's chi-square.
CHI2_QUANTILE = 0.999
_ITEM = re.compile(r"^(?P<name>[A-Za-z_]\w*)(\[(?P<index>\d+)\])?$")


# The ranges of fit's numeric arguments. The noise is the standard deviation of a measured
# velocity: below 1e-12 m/s no measurement resolves a velocity, above 1e6 m/s it measures
# nothing; scipy's tolerances must exceed the machine epsilon.
RANGES = {
    spec.name: spec
    for spec in (
        Spec("noise", None, "a measured velocity's standard deviation", "m/s", "float", 1e-12, 1e6),
        Spec("holdout", 0.0, "share of the trials kept out", "", "float", 0.0, 1.0, high_open=True),
        Spec("bootstrap", 0, "refits on resampled trials", "", "int", 0, 100_000),
        Spec("seed", 0, "seed of the resampling", "", "int", 0),
        Spec("tol", 1e-10, "tolerance of the least squares", "", "float", 1e-15, 0.1),
        Spec("diff_step", 1e-6, "relative step of the finite differences", "", "float", 1e-12, 0.1),
        Spec(
            "flat_tol", FLAT_TOL, "singular value ratio of a flat direction", "", "float", 0.0, 0.5
        ),
    )
}


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


@dataclass(frozen=True)
class _Free:
    """One fitted coefficient: where it sits in the parameters and how it is scaled."""

    label: str
    spec: Spec
    index: int | None
    low: float
    high: float
    log: bool

    @property
    def name(self) -> str:
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
        return math.log(value) if self.log else value

    def to_value(self, x: float) -> float:
        return math.exp(x) if self.log else x

    def bounds(self) -> tuple[float, float]:
        if self.log:
            return -np.inf, np.inf
        return self.low, self.high


def _labels(free: object) -> list[str]:
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


def _mapping(name: str, value: object) -> dict[str, Any]:
    """The argument ``name`` as a dict: a mapping of names to values, or None for none."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise TypeError(f"{name} must be a mapping of names to values, not {type(value).__name__}")
    return dict(value)


def _free_coefficients(scene: Case, free: list[str], fixed: dict[str, Any]) -> list[_Free]:
    """The coefficients named in ``free``.

    Each is a numeric parameter of ``scene``, or an entry of a list parameter that has it at the
    parameters ``fixed``.
    """
    specs = {s.name: s for s in scene.params}
    result: list[_Free] = []
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
        result.append(_Free(label, spec, index, low, high, log))
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


@dataclass
class FitResult:
    """What `fit` found.

    Attributes
    ----------
    law, case : str
        The law fitted and its scene.
    values : dict
        Coefficient -> fitted value.
    standard_errors : dict
        Coefficient -> standard error (inf when not identifiable, 0 with noise-free data).
    correlations : ndarray (p, p)
        Correlations of the coefficients (NaN, undefined, where a standard error is 0, inf or
        undefined).
    residuals : ndarray (trials,)
        Root mean square residual of each fitted trial (velocity units).
    rms : float
        Root mean square residual over every fitted velocity.
    sigma : float
        Estimated noise standard deviation, sqrt(RSS / (N - p)) (NaN, undefined, when
        N <= p; standard errors are then NaN too).
    singular_values : ndarray (p,)
        Singular values of the Jacobian in the fitted scale.
    non_identifiable : list of str
        Coefficients carrying a flat direction of the data.
    unread : list of str
        Coefficients the law's answer does not change with at any fitted trial (a zero column
        of the Jacobian: the law does not read them); each is also not identifiable.
    fits : bool or None
        Whether the residual is compatible with ``noise`` (None when no noise was given).
    verdict : str
        The fit's quality in words.
    holdout_residuals : ndarray or None
        Root mean square residual of each held-back trial.
    holdout_rms : float or None
        Root mean square residual over the held-back trials.
    bootstrap : dict or None
        Coefficient -> array of bootstrap estimates.
    params : dict
        Every scene parameter at the fit.
    trials, held_out : ndarray of int
        Indices of the fitted and held-back trials (rows of the data, from 0).
    success : bool
        Whether the optimizer converged.
    message : str
        The optimizer's message.
    nfev : int
        Evaluations of the residuals (each solves every trial).
    """

    law: str
    case: str
    values: dict[str, float]
    standard_errors: dict[str, float]
    correlations: np.ndarray
    residuals: np.ndarray
    rms: float
    sigma: float
    singular_values: np.ndarray
    non_identifiable: list[str]
    unread: list[str]
    fits: bool | None
    verdict: str
    params: dict[str, Any]
    trials: np.ndarray
    success: bool
    message: str
    nfev: int
    held_out: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    holdout_residuals: np.ndarray | None = None
    holdout_rms: float | None = None
    bootstrap: dict[str, np.ndarray] | None = None

    def text(self) -> str:
        """A plain-text report: coefficients, correlations, residuals and verdicts.

        An undefined number (a correlation of a coefficient that is not identifiable, a
        standard error with no degree of freedom left) is printed as ``-``.
        """
        lines = [f"{self.law} on {self.case}: {len(self.trials)} trials fitted ({self.message})"]
        lines.append(
            f"{'coefficient':<18}{'value':>14}{'std error':>14}"
            + (f"{'bootstrap sd':>14}{'2.5%':>12}{'97.5%':>12}" if self.bootstrap else "")
        )
        lines += [self._row(name) for name in self.values]
        if len(self.values) > 1:
            lines.append("correlations (-: undefined):")
            for name, row in zip(self.values, self.correlations, strict=True):
                lines.append(f"  {name:<16}" + " ".join(_cell(c, 7, ".3f") for c in row))
        sigma = "undefined (no more measured velocities than coefficients)"
        sigma = sigma if math.isnan(self.sigma) else f"{self.sigma:.3g}"
        lines.append(f"rms residual {self.rms:.3g}, estimated noise sigma {sigma}")
        lines.append("singular values of J: " + ", ".join(f"{s:.3g}" for s in self.singular_values))
        if self.non_identifiable:
            lines.append(
                "not identifiable from these data (flat direction): "
                + ", ".join(self.non_identifiable)
            )
        if self.unread:
            lines.append(
                f"not read by {self.law} (its answer does not change with them): "
                + ", ".join(self.unread)
            )
        lines.append(f"verdict: {self.verdict}")
        lines.append("residual per trial (row: rms):")
        lines += [f"  {i}: {r:.3g}" for i, r in zip(self.trials, self.residuals, strict=True)]
        if self.holdout_residuals is not None:
            lines.append(f"held-back trials: rms residual {self.holdout_rms:.3g}")
            lines += [
                f"  {i}: {r:.3g}"
                for i, r in zip(self.held_out, self.holdout_residuals, strict=True)
            ]
        return "\n".join(lines)

    def _row(self, name: str) -> str:
        """The line of coefficient ``name``: value, standard error, bootstrap spread."""
        row = f"{name:<18}{self.values[name]:>14.6g}{_cell(self.standard_errors[name], 14, '.3g')}"
        if self.bootstrap:
            draws = self.bootstrap[name]
            low, high = np.percentile(draws, [2.5, 97.5])
            spread = float(np.std(draws, ddof=1)) if len(draws) > 1 else math.nan
            row += f"{_cell(spread, 14, '.3g')}{low:>12.6g}{high:>12.6g}"
        return row

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dictionary of the result."""
        out = {
            "law": self.law,
            "case": self.case,
            "values": self.values,
            "standard_errors": {k: _finite(v) for k, v in self.standard_errors.items()},
            "correlations": [[_finite(c) for c in row] for row in self.correlations],
            "residuals": self.residuals.tolist(),
            "rms": self.rms,
            "sigma": _finite(self.sigma),
            "singular_values": self.singular_values.tolist(),
            "non_identifiable": self.non_identifiable,
            "unread": self.unread,
            "fits": self.fits,
            "verdict": self.verdict,
            "trials": self.trials.tolist(),
            "held_out": self.held_out.tolist(),
            "holdout_residuals": None
            if self.holdout_residuals is None
            else self.holdout_residuals.tolist(),
            "holdout_rms": self.holdout_rms,
            "success": self.success,
            "message": self.message,
            "nfev": self.nfev,
        }
        if self.bootstrap is not None:
            out["bootstrap"] = {k: v.tolist() for k, v in self.bootstrap.items()}
        return out


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _cell(value: float, width: int, form: str) -> str:
    """``value`` in ``form``, right-aligned in ``width``; an undefined value (NaN) as ``-``."""
    return f"{'-' if math.isnan(value) else format(value, form):>{width}}"


class _Model:
    """The law's predicted post-impact velocities of every trial, as a function of x."""

    def __init__(
        self,
        law: Law,
        scene: Case,
        free: list[_Free],
        fixed: dict[str, Any],
        options: dict[str, Any],
    ) -> None:
        self.law, self.scene, self.free, self.fixed, self.options = (
            law,
            scene,
            free,
            fixed,
            options,
        )

    def params(self, x: np.ndarray) -> dict[str, Any]:
        params = {k: list(v) if isinstance(v, list) else v for k, v in self.fixed.items()}
        for f, xi in zip(self.free, x, strict=True):
            value = f.to_value(float(xi))
            if f.index is None:
                params[f.name] = [value] if isinstance(params[f.name], list) else value
            else:
                params[f.name][f.index] = value
        return params

    def predict(self, x: np.ndarray, v_minus: np.ndarray) -> np.ndarray:
        problem = self.scene.build(**self.params(x))
        return np.array([self._solve(problem, v) for v in v_minus])

    def _solve(self, problem: ImpactProblem, v: np.ndarray) -> np.ndarray:
        trial = dataclasses.replace(problem, v=np.asarray(v, dtype=float))
        return self.law.resolve(trial, **self.options).v_plus


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
    law : str or Law
        The law whose coefficients are identified.
    case : str or Case
        The scene of the experiment.
    data : path or DataFrame
        Trials: columns ``<coordinate>_minus`` and ``<coordinate>_plus`` (`columns`).
    free : str or sequence of str
        The coefficients to fit: parameter names, or ``name[i]`` for one entry of a list (an
        index below the list's length at ``params``).
    params : mapping, optional
        Scene parameters held fixed (the others take their defaults).
    options : mapping, optional
        The law's options.
    start : mapping, optional
        Starting value of a free coefficient (a finite number, or its text, in the
        parameter's range); by default its value in ``params`` or its default. Either is
        moved inside the bounds by a millionth of their span.
    noise : float, optional
        Standard deviation of a measured velocity, in [1e-12, 1e6]; when given, the residual
        is judged.
    holdout : float
        Fraction of the trials held back from the fit, in [0, 1), chosen with ``seed``.
    bootstrap : int
        Number of refits on trials resampled with replacement (seeded by ``seed``), in
        [0, 100000].
    seed : int
        Seed of the holdout split and the bootstrap resamples, 0 or more.
    tol : float
        ``ftol``, ``xtol`` and ``gtol`` of `scipy.optimize.least_squares`, in [1e-15, 0.1].
    diff_step : float
        Relative finite-difference step of the Jacobian (above the law's own accuracy), in
        [1e-12, 0.1].
    flat_tol : float
        Relative singular value below which a direction of the Jacobian is flat, in [0, 0.5].

    Returns
    -------
    FitResult

    Raises
    ------
    InvalidProblem
        Bad data (naming row and column), an unknown coefficient or an entry past a list's
        end, a bad option, a starting value or a number outside its range (`RANGES`).
    TypeError
        Naming the argument of the wrong type (``free`` not names, ``params`` not a mapping,
        ``seed`` not an integer, ...).
    NotApplicable
        The law cannot treat the scene.

    Examples
    --------
    >>> import numpy as np, pandas as pd, lawbench
    >>> v = np.array([[-1.0, 0.0], [-2.0, 0.5]])
    >>> after = [lawbench.solve("newton", "two_balls_wall", velocities=list(r), e=[0.5]).v_plus
    ...          for r in v]
    >>> data = pd.DataFrame(np.hstack([v, after]), columns=["v1_minus", "v2_minus",
    ...                                                      "v1_plus", "v2_plus"])
    >>> result = lawbench.fit("newton", "two_balls_wall", data, free=["e"])
    >>> round(result.values["e"], 8)
    0.5
    """
    _check_numbers(
        noise,
        holdout=holdout,
        bootstrap=bootstrap,
        seed=seed,
        tol=tol,
        diff_step=diff_step,
        flat_tol=flat_tol,
    )
    labels, start = _labels(free), _mapping("start", start)
    law_obj, scene = LAWS.get(law), CASES.get(case)
    fixed = scene.parameters(**_mapping("params", params))
    law_opts = law_obj.option_values(_mapping("options", options))
    coefficients = _free_coefficients(scene, labels, fixed)
    v_minus, v_plus = read_trials(data, scene, fixed)
    model = _Model(law_obj, scene, coefficients, fixed, law_opts)
    x0 = _start(coefficients, fixed, start)
    rng = np.random.default_rng(seed)
    count = len(v_minus)
    order = rng.permutation(count)
    held = np.sort(order[: round(holdout * count)]) if holdout else np.zeros(0, dtype=int)
    kept = np.setdiff1d(np.arange(count), held)
    if len(kept) == 0:
        raise InvalidProblem(f"holdout = {holdout:g} leaves no trial to fit")
    solution = _least_squares(model, x0, v_minus[kept], v_plus[kept], tol, diff_step)
    result = _summarize(model, solution, v_minus[kept], v_plus[kept], noise, flat_tol)
    result.law, result.case, result.trials = law_obj.name, scene.name, kept
    if len(held):
        predicted = model.predict(solution.x, v_minus[held])
        per_trial = np.sqrt(((predicted - v_plus[held]) ** 2).mean(axis=1))
        result.held_out, result.holdout_residuals = held, per_trial
        result.holdout_rms = float(np.sqrt((per_trial**2).mean()))
    if bootstrap:
        draws = np.empty((bootstrap, len(coefficients)))
        for b in range(bootstrap):
            pick = rng.choice(kept, size=len(kept), replace=True)
            again = _least_squares(model, solution.x, v_minus[pick], v_plus[pick], tol, diff_step)
            draws[b] = [f.to_value(float(x)) for f, x in zip(coefficients, again.x, strict=True)]
        result.bootstrap = {f.label: draws[:, i] for i, f in enumerate(coefficients)}
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


def _start(free: list[_Free], fixed: dict[str, Any], start: dict[str, Any]) -> np.ndarray:
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


def _least_squares(
    model: _Model,
    x0: np.ndarray,
    v_minus: np.ndarray,
    v_plus: np.ndarray,
    tol: float,
    diff_step: float,
) -> optimize.OptimizeResult:
    bounds = np.array([f.bounds() for f in model.free]).T

    def residual(x: np.ndarray) -> np.ndarray:
        return (model.predict(x, v_minus) - v_plus).ravel()

    return optimize.least_squares(
        residual,
        x0,
        bounds=(bounds[0], bounds[1]),
        method="trf",
        ftol=tol,
        xtol=tol,
        gtol=tol,
        diff_step=diff_step,
        x_scale="jac",
    )


def _summarize(
    model: _Model,
    solution: optimize.OptimizeResult,
    v_minus: np.ndarray,
    v_plus: np.ndarray,
    noise: float | None,
    flat_tol: float,
) -> FitResult:
    free = model.free
    values = {f.label: float(f.to_value(x)) for f, x in zip(free, solution.x, strict=True)}
    r = solution.fun
    n_res, p = r.size, len(free)
    rss = float(r @ r)
    dof = n_res - p
    sigma = math.sqrt(rss / dof) if dof > 0 else math.nan
    J = np.atleast_2d(solution.jac)
    _, s, vt = np.linalg.svd(J, full_matrices=False)
    largest = s.max() if s.size and s.max() > 0 else 1.0
    flat = s <= flat_tol * largest
    blocked = np.zeros(p, dtype=bool)
    for k in np.flatnonzero(flat):
        blocked |= np.abs(vt[k]) > FLAT_SHARE
    # Covariance on the identifiable subspace (pseudo-inverse), infinite along flat directions.
    keep = ~flat
    inv = (vt[keep].T / s[keep] ** 2) @ vt[keep]
    cov_x = (sigma**2 if math.isfinite(sigma) else math.nan) * inv
    slope = np.array(
        [f.to_value(x) if f.log else 1.0 for f, x in zip(free, solution.x, strict=True)]
    )
    cov = cov_x * np.outer(slope, slope)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    se[blocked] = np.inf
    per_trial = np.sqrt((r.reshape(len(v_minus), -1) ** 2).mean(axis=1))
    fits, verdict = _judge(rss, dof, noise, v_minus, v_plus)
    non_identifiable = [f.label for f, b in zip(free, blocked, strict=True) if b]
    unread = [f.label for f, column in zip(free, J.T, strict=True) if not column.any()]
    if non_identifiable:
        verdict += "; not identifiable: " + ", ".join(non_identifiable)
    if unread:
        verdict += f" ({model.law.name}'s answer does not change with {', '.join(unread)})"
    return FitResult(
        law="",
        case="",
        values=values,
        standard_errors={f.label: float(e) for f, e in zip(free, se, strict=True)},
        correlations=_correlations(cov, se),
        residuals=per_trial,
        rms=math.sqrt(rss / n_res),
        sigma=sigma,
        singular_values=s,
        non_identifiable=non_identifiable,
        unread=unread,
        fits=fits,
        verdict=verdict,
        params=model.params(solution.x),
        trials=np.arange(len(v_minus)),
        success=bool(solution.success),
        message=str(solution.message),
        nfev=int(solution.nfev),
    )


def _correlations(cov: np.ndarray, se: np.ndarray) -> np.ndarray:
    """Correlations of the coefficients; NaN (undefined) where a standard error is 0 or inf.

    A coefficient that is not identifiable (an infinite standard error) has no correlation
    with any other: the pseudo-inverse's zero there says nothing of the data.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    defined = np.isfinite(se) & (se > 0)
    corr[~np.outer(defined, defined) | ~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, np.where(defined, 1.0, np.nan))
    return corr


def _judge(
    rss: float, dof: int, noise: float | None, v_minus: np.ndarray, v_plus: np.ndarray
) -> tuple[bool | None, str]:
    change = float(np.sqrt(((v_plus - v_minus) ** 2).mean())) or 1.0
    relative = math.sqrt(rss / v_plus.size) / change
    if noise is None:
        return None, (
            f"rms residual {relative:.3g} of the rms velocity change (give the noise to judge "
            "whether the law fits)"
        )
    if dof <= 0:
        return None, "as many coefficients as measured velocities: nothing left to judge the fit"
    limit = noise**2 * stats.chi2.ppf(CHI2_QUANTILE, dof)
    ratio = math.sqrt(rss / dof) / noise
    if rss > limit:
        return False, (
            f"the law cannot fit these data: residual {ratio:.3g} times the noise "
            f"(chi-square {rss / noise**2:.3g} for {dof} degrees of freedom, above its "
            f"{CHI2_QUANTILE:.1%} quantile)"
        )
    return True, f"fits within the noise: residual {ratio:.3g} times the noise"
