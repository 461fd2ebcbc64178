"""Ground truths shared by several scenes.

The chains (balls on a line, with or without a wall; bead columns) have no closed form in
general: their outcome depends on how the contacts' stiffnesses share the impact, which only
time integration of the unilateral springs resolves (Brogliato 2010, linear-spring limits of
the three-ball chain). Their ground truth is the compliant model at the scene's stiffnesses,
integrated to a tight tolerance.
"""

from lawbench.case import GroundTruth

SPRING_CHAIN = GroundTruth(
    why="the chain's outcome depends on how the contacts' stiffnesses share the impact, which "
    "only time integration of the unilateral springs resolves (Brogliato 2010, linear-spring "
    "limits of the three-ball chain)",
    law="compliant",
    options={"tol": 1e-10},
)
