"""Frictionless Moreau on redundant contacts and a mass matrix of condition 1e9.

A heavy body (masses of 1e9) and a light one (masses of 1), each of three coordinates and
struck at four contacts: the four normals of a body are dependent, so the Delassus matrix is
singular, and its diagonal spans ten decades. The impact decouples into the two bodies, which
cvxpy solves one at a time (each well conditioned) for the cross-check.
"""

import cvxpy as cp
import numpy as np
import pytest
import scipy.linalg

import lawbench
from lawbench.core.problem import ImpactProblem

MOREAU = lawbench.LAWS.get("moreau")


def heavy_and_light(seed, e):
    """The two bodies, their contacts approaching, as one impact problem; and the pieces."""
    rng = np.random.default_rng(seed)
    pieces = []
    for mass in (1e9, 1.0):
        A = rng.normal(size=(3, 3))
        v = rng.normal(size=3)
        Wn = rng.normal(size=(3, 4))
        Wn *= -np.sign(Wn.T @ v)[None, :]
        pieces.append((mass * (A @ A.T + 3 * np.eye(3)), Wn, v))
    M, Wn, v = (
        scipy.linalg.block_diag(*p) if k < 2 else np.concatenate(p)
        for k, p in enumerate(zip(*pieces, strict=True))
    )
    return ImpactProblem.from_arrays(M=M, Wn=Wn, v=v, e=e), pieces


def projected_by_cvxpy(M, Wn, v, e):
    """Moreau's ``v+ = -e v- + (1 + e) argmin |w - v-|_M`` over ``Wn.T w >= 0``, in cvxpy."""
    w = cp.Variable(v.size)
    objective = cp.Minimize(0.5 * cp.quad_form(w - v, cp.psd_wrap(M / M[0, 0])))
    cp.Problem(objective, [Wn.T @ w >= 0]).solve(solver=cp.CLARABEL)
    return -e * v + (1 + e) * w.value


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_redundant_contacts_at_condition_1e9_are_answered_right(seed):
    """clarabel's QPs leave the light body's active set unresolved: their objective, the
    energy, is all the heavy body's. Both in the velocities and in the impulses, where clarabel
    ended 'AlmostSolved' (seeds 0 and 2) and the polish found no active set in its answer, or
    'Solved' (seed 1). The answer is now the one cvxpy gives each body alone, to 1e-6 of its
    own speed, and no contact approaches."""
    problem, pieces = heavy_and_light(seed, 0.5)
    outcome = MOREAU.resolve(problem)
    assert outcome.diagnostics["polished"]
    for k, (M, Wn, v) in enumerate(pieces):
        body = slice(3 * k, 3 * k + 3)
        expected = projected_by_cvxpy(M, Wn, v, 0.5)
        np.testing.assert_allclose(outcome.v_plus[body], expected, atol=1e-6 * np.abs(v).max())
    assert (problem.Wn.T @ outcome.v_plus >= -1e-9 * np.abs(problem.un).max()).all()
