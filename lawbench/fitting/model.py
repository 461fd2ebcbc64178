"""The law's predictions of measured trials, and the least squares that fit them.

The search is `scipy.optimize.least_squares`' trust-region reflective method within the bounds
of the free coefficients' `Spec` ranges. Residuals are in the coordinates' own units,
unweighted.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from scipy import optimize

from lawbench.core.case import Case
from lawbench.core.law import Law
from lawbench.core.problem import ImpactProblem
from lawbench.fitting.coefficients import Free


class Model:
    """The law's predicted post-impact velocities of every trial, as a function of x."""

    def __init__(
        self,
        law: Law,
        scene: Case,
        free: list[Free],
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
        """The scene's parameters at the point ``x`` of the search (fitted scale)."""
        params = {k: list(v) if isinstance(v, list) else v for k, v in self.fixed.items()}
        for f, xi in zip(self.free, x, strict=True):
            value = f.to_value(float(xi))
            if f.index is None:
                params[f.name] = [value] if isinstance(params[f.name], list) else value
            else:
                params[f.name][f.index] = value
        return params

    def predict(self, x: np.ndarray, v_minus: np.ndarray) -> np.ndarray:
        """Post-impact velocities (trials x coordinates) of the trials ``v_minus`` at ``x``."""
        problem = self.scene.build(**self.params(x))
        return np.array([self._solve(problem, v) for v in v_minus])

    def _solve(self, problem: ImpactProblem, v: np.ndarray) -> np.ndarray:
        trial = dataclasses.replace(problem, v=np.asarray(v, dtype=float))
        return self.law.resolve(trial, **self.options).v_plus


def least_squares(
    model: Model,
    x0: np.ndarray,
    v_minus: np.ndarray,
    v_plus: np.ndarray,
    tol: float,
    diff_step: float,
) -> optimize.OptimizeResult:
    """The least-squares fit of ``model``'s predictions to ``v_plus``, from ``x0``.

    ``tol`` is scipy's ``ftol``, ``xtol`` and ``gtol``; ``diff_step`` the relative step of the
    finite-difference Jacobian; the step sizes follow the Jacobian's columns (``x_scale='jac'``).
    """
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
