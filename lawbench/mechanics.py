"""Shared mechanics at a frozen configuration: energy, impulses to velocities, gap rates."""

from __future__ import annotations

import numpy as np

from lawbench.problem import ImpactProblem


def kinetic_energy(M: np.ndarray, v: np.ndarray) -> float:
    """Return ``v @ M @ v / 2`` (inf, without a warning, when it overflows)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return float(v @ M @ v) / 2.0


def generalized_impulse(
    problem: ImpactProblem, Pn: np.ndarray, Pt: np.ndarray | None = None
) -> np.ndarray:
    """Return the generalized impulse ``Wn @ Pn + Wt @ Pt`` (Pt None or empty: no friction)."""
    impulse = problem.Wn @ Pn
    if Pt is not None and np.size(Pt):
        impulse = impulse + problem.Wt @ Pt
    return impulse


def velocity_after(
    problem: ImpactProblem, Pn: np.ndarray, Pt: np.ndarray | None = None
) -> np.ndarray:
    """Return ``v + M^-1 (Wn @ Pn + Wt @ Pt)``, the velocity after the impulses."""
    return problem.v + problem.solve_mass(generalized_impulse(problem, Pn, Pt))


def gap_rates(problem: ImpactProblem, v: np.ndarray) -> np.ndarray:
    """Return the normal gap rates ``Wn.T @ v`` of every contact at velocity ``v``."""
    return problem.Wn.T @ v


def is_diagonal(G: np.ndarray) -> bool:
    """Whether the Delassus matrix decouples the contacts (no off-diagonal term)."""
    return not np.any(G - np.diag(np.diag(G)))
