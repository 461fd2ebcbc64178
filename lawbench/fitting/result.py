"""`FitResult`: what a fit found, as text and as a JSON-ready dictionary."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np


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
