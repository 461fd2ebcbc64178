"""What Moreau's law refuses of a frictional answer: impulses that only cancel, or leave a cone.

Both are answers the solvers can end with on problems beyond their precision (dependent contact
directions, cones narrower than clarabel's tolerances) and that no check of the solver sees.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.core.errors import SolverFailure


def refuse_cancelling(G: Any, P: np.ndarray, tol: float, scale: float) -> None:
    """Refuse impulses whose contributions to the local velocities cancel beyond precision.

    Where the contact directions depend on each other (a singular contact Delassus matrix, a
    body with fewer coordinates than its contact has directions) Coulomb's states have
    impulses of any size along the dependence, and the exact state's slip formula gives ones
    of 1e12 or more whose velocities are their rounding: an answer that left the contact
    approaching, or dissipated nothing at e < 1, with an FC3D error of 1e-16.
    """
    rounding = np.finfo(float).eps * float(np.max(abs(G) @ np.abs(P)))
    if rounding > tol**0.5 * scale:
        raise SolverFailure(
            f"moreau: impulses up to {np.abs(P).max():.3g} change the local velocities (of "
            f"size {scale:.3g}) only through their cancellation, to within {rounding:.3g}: "
            "the contact directions depend on each other"
        )


def refuse_outside_cones(P: np.ndarray, mu: np.ndarray, d: int, tol: float) -> None:
    """Refuse impulses whose tangential part leaves a Coulomb cone by more than ``sqrt(tol)``.

    Of the largest impulse. At ``mu`` near 1e-9 the cone QP's cone ``(mu Pn, Pt)`` is below
    clarabel's tolerances, and its polish, kept for lowering the natural residual, made a
    contact stick with ``|Pt|`` of 0.2 where ``mu Pn`` is 5e-10: an energy gain, status ok.
    """
    m = len(mu)
    excess = np.linalg.norm(P[m:].reshape(m, d), axis=1) - mu * P[:m]
    j = int(np.argmax(excess))
    if excess[j] > tol**0.5 * float(np.abs(P).max()):
        raise SolverFailure(
            f"moreau: contact {j}'s tangential impulse leaves its Coulomb cone by "
            f"{excess[j]:.3g} (mu Pn = {mu[j] * P[j]:.3g}): the cones are too narrow for the "
            "solver's tolerances"
        )
