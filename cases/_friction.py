"""The ground truth of the frictional scenes: compliant contact with friction, in time."""

from __future__ import annotations

from lawbench.core.case import GroundTruth


def springs_with_friction(detail: str) -> GroundTruth:
    """Compliant contacts with tangential springs and Coulomb sliders, integrated in time.

    ``detail`` says what the scene adds to the reason.
    """
    return GroundTruth(
        why="each contact a unilateral normal force law (Hunt-Crossley, its damping from e by "
        "Flores' rule, at the scene's stiffnesses) with a tangential spring in series with a "
        "Coulomb slider, integrated in time: stick, slip and slip reversal happen as the "
        "forces decide, during the impact, and several contacts share it as their stiffnesses "
        "decide, which no impulse-level law follows (Jia, IJRR 2013, the same springs in "
        "impulse space; Brogliato 2010, compliant contacts); it never creates energy, and at "
        f"e = 0 its contacts are plastic; {detail}",
        law="compliant",
        options={"tol": 1e-10},
    )
