"""The uncertainty of fitted coefficients, and whether the law fits within the noise.

From the Jacobian J of the residuals at the optimum (in the fitted scale): the noise variance
is estimated as ``s^2 = RSS / (N - p)`` (N residuals, p coefficients), the covariance is
``s^2 (J^T J)^-1``, mapped to the parameters' own scale by the delta method. A singular value
of J below ``flat_tol`` times the largest is a flat direction: the coefficients that carry it
are reported as not identifiable from the data (infinite standard error), and the covariance of
the others is taken on the orthogonal complement; a coefficient the law's answer does not
change with (a zero column of J: the law does not read it) is named as such, and its
correlations are undefined, printed as ``-`` and written as null. With ``noise`` (the standard
deviation of a measured velocity) the residual is also judged: a sum of squares above the
99.9% quantile of ``noise^2 chi^2(N - p)`` says the law cannot fit the data.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, stats

from lawbench.fitting.model import Model
from lawbench.fitting.result import FitResult

# Relative singular value of the Jacobian below which a direction counts as flat.
FLAT_TOL = 1e-4
# A coefficient carries a flat direction when its share of the singular vector exceeds this.
FLAT_SHARE = 0.3
# The law cannot fit when the residual exceeds this quantile of the noise's chi-square.
CHI2_QUANTILE = 0.999


def summarize(
    model: Model,
    solution: optimize.OptimizeResult,
    v_minus: np.ndarray,
    v_plus: np.ndarray,
    noise: float | None,
    flat_tol: float,
) -> FitResult:
    """The `FitResult` of ``solution`` on the trials ``v_minus`` -> ``v_plus``.

    Its law, scene and trials are those of the caller to fill in.
    """
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
