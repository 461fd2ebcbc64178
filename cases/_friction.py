"""The ground truth of the scenes with one frictional contact: Darboux-Keller, Stronge's end."""

from __future__ import annotations

from lawbench.core.case import GroundTruth


def stronge(detail: str) -> GroundTruth:
    """Darboux-Keller impulse dynamics with Stronge's termination, for one frictional contact.

    ``detail`` says what the scene adds to the reason.
    """
    return GroundTruth(
        why="Coulomb friction resolved along the normal impulse (Darboux-Keller): stick, slip "
        "and slip reversal as they happen during the impact, which impulse-level laws do not "
        "follow; Stronge's energetic termination is the one that never creates energy "
        f"(Stronge 1990; Brogliato 2010, eqs. 12-15); {detail}",
        law="darboux_keller",
        options={"termination": "energetic", "tol": 1e-12},
    )
