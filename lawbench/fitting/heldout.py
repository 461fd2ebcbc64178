"""Judging predictions of measured impacts: errors in the kinetic metric, their summary, baselines.

The error of a predicted post-impact velocity ``v_pred`` against the measured ``v_meas`` is
relative and has no unit: ``sqrt(dv^T M dv / v^T M v)`` with ``dv = v_pred - v_meas`` and ``v``
the velocity before, so that rotation and translation weigh by the body's inertia. With
``M = L L^T`` (Cholesky), ``L^T dv / sqrt(v^T M v)`` is the vector whose norm is that error:
the residual a least-squares fit in the kinetic metric reduces (`weights`). Beside it, the
errors of each contact's normal and tangential velocity after the impact (``Wn^T v``, ``Wt^T
v``), relative to the speed of the contact points before it.

The baselines are the two models every law must beat, fitted on the training impacts in the
same metric: a ratio of post- to pre-impact velocity per generalized coordinate, and an affine
map from pre- to post-impact velocity. Both read the coordinates as one frame shared by every
impact of a set (true of every set that ships: the world frame of the ellipse's plane, of the
cube's table, of Kharaz's anvil).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.measurements import MeasuredImpact

# Resamples of the bootstrap confidence interval of a median error, and its fixed seed.
BOOTSTRAP = 2000
BOOTSTRAP_SEED = 0
# Fact keys that give one published coefficient each, by the contact field it is: a set's
# ``normal_restitution`` and ``dem_friction`` are the pair DEM benchmarks use.
PUBLISHED_FIELDS = {"normal_restitution": "e", "dem_friction": "mu"}
PUBLISHED_PAIR_NAME = "DEM benchmarks"


def weights(impacts: Sequence[MeasuredImpact]) -> np.ndarray:
    """Per impact, ``L^T / sqrt(v^T M v)`` (impacts x n x n), ``M = L L^T``.

    A velocity ``w`` maps to ``weights[i] @ w``, whose norm is ``w``'s kinetic norm relative
    to the impact's pre-impact velocity.
    """
    out = []
    for impact in impacts:
        problem = impact.problem.dense()
        M = np.asarray(problem.M, dtype=float)
        scale = math.sqrt(2.0 * problem.T_minus) or 1.0
        out.append(np.linalg.cholesky(M).T / scale)
    return np.array(out)


@dataclass(frozen=True)
class Errors:
    """Per impact: the relative error in the kinetic metric and at the contacts.

    Attributes
    ----------
    kinetic : ndarray (impacts,)
        ``sqrt(dv^T M dv / v^T M v)``.
    normal, tangential : ndarray (impacts,)
        Root mean square over the contacts of the error of ``Wn^T v`` and of the norm of the
        error of ``Wt^T v`` after the impact, over the largest contact-point speed before it.
    """

    kinetic: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray


def errors(impacts: Sequence[MeasuredImpact], predicted: np.ndarray) -> Errors:
    """The errors of ``predicted`` (impacts x n) against the measured velocities after."""
    kinetic, normal, tangential = [], [], []
    for impact, w, v_pred in zip(impacts, weights(impacts), predicted, strict=True):
        problem = impact.problem.dense()
        dv = v_pred - impact.v_after
        kinetic.append(float(np.linalg.norm(w @ dv)))
        before = np.asarray(problem.Wn).T @ problem.v
        dn = np.asarray(problem.Wn).T @ dv
        if problem.Wt is None:
            speed, dt = np.abs(before), np.zeros(problem.m)
        else:
            Wt = np.asarray(problem.Wt)
            ut = (Wt.T @ problem.v).reshape(problem.m, problem.d)
            speed = np.hypot(before, np.linalg.norm(ut, axis=1))
            dt = np.linalg.norm((Wt.T @ dv).reshape(problem.m, problem.d), axis=1)
        scale = float(speed.max()) or 1.0
        normal.append(math.sqrt(float(np.mean(dn**2))) / scale)
        tangential.append(math.sqrt(float(np.mean(dt**2))) / scale)
    return Errors(np.array(kinetic), np.array(normal), np.array(tangential))


def summary(kinetic: np.ndarray, seed: int = BOOTSTRAP_SEED) -> dict[str, float]:
    """Median, interquartile range and the bootstrap 95% interval of the median of ``kinetic``.

    The interval takes the 2.5% and 97.5% percentiles of the medians of `BOOTSTRAP` resamples
    drawn with replacement by a generator seeded with ``seed``; NaN for no errors.
    """
    if not len(kinetic):
        return dict.fromkeys(("median_error", "iqr", "ci_low", "ci_high"), math.nan)
    draws = np.random.default_rng(seed).integers(0, len(kinetic), (BOOTSTRAP, len(kinetic)))
    medians = np.median(kinetic[draws], axis=1)
    q1, q3 = np.percentile(kinetic, [25, 75])
    low, high = np.percentile(medians, [2.5, 97.5])
    return {
        "median_error": float(np.median(kinetic)),
        "iqr": float(q3 - q1),
        "ci_low": float(low),
        "ci_high": float(high),
    }


def published(facts: Mapping[str, Any]) -> dict[str, dict[str, float]]:
    """The published contact coefficients a set's facts give, by the name of their source.

    ``published_fits`` maps a source's name to a tuple whose fields ``published_fits_meaning``
    names in parentheses (``"(mu, e) of the authors' fits"``); keys of `PUBLISHED_FIELDS` give
    one field each, together the pair `PUBLISHED_PAIR_NAME`.
    """
    found: dict[str, dict[str, float]] = {}
    fits = facts.get("published_fits") or {}
    meaning = re.search(r"\(([^)]*)\)", str(facts.get("published_fits_meaning", "")))
    if fits and meaning is None:
        raise InvalidProblem("published_fits: published_fits_meaning names no fields")
    names = [name.strip() for name in meaning.group(1).split(",")] if fits else []
    for source, values in fits.items():
        found[str(source)] = {k: float(v) for k, v in zip(names, values, strict=True)}
    pair = {field: float(facts[key]) for key, field in PUBLISHED_FIELDS.items() if key in facts}
    if pair:
        found[PUBLISHED_PAIR_NAME] = pair
    return found


def _ratio_basis(v: np.ndarray) -> np.ndarray:
    """Columns ``v_k e_k``: a post-impact velocity ``diag(r) v``, one ratio per coordinate."""
    return np.diag(v)


def _affine_basis(v: np.ndarray) -> np.ndarray:
    """Columns ``v_l e_k`` and ``e_k``: a post-impact velocity ``A v + b``."""
    n = len(v)
    return np.hstack([np.kron(np.eye(n), v[None, :]), np.eye(n)])


# The baselines: each a basis of velocities that a post-impact velocity combines linearly.
BASELINES: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "baseline: ratio per coordinate": _ratio_basis,
    "baseline: affine map": _affine_basis,
}


def fit_baseline(
    basis: Callable[[np.ndarray], np.ndarray], train: Sequence[MeasuredImpact]
) -> np.ndarray:
    """The coefficients of ``basis`` that best map the velocities before to those after.

    Linear least squares in the kinetic metric over the training impacts ``train``; the
    minimum-norm solution when they do not determine the coefficients.
    """
    rows, targets = [], []
    for impact, w in zip(train, weights(train), strict=True):
        rows.append(w @ basis(impact.problem.v))
        targets.append(w @ impact.v_after)
    theta, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(targets), rcond=None)
    return theta


def predict_baseline(
    basis: Callable[[np.ndarray], np.ndarray],
    theta: np.ndarray,
    impacts: Sequence[MeasuredImpact],
) -> np.ndarray:
    """The velocities after ``impacts`` (impacts x n) that ``basis`` at ``theta`` predicts."""
    return np.array([basis(impact.problem.v) @ theta for impact in impacts])
