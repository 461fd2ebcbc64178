"""Claims that several laws share, each declared once with its source.

A law lists the ones that apply to it in its ``findings`` (`lawbench.verdicts.Claim`).
"""

from lawbench.regions import EVERYWHERE, oblique_contacts
from lawbench.verdicts import Claim

PAOLI_DISCONTINUITY = Claim(
    "continuity",
    oblique_contacts,
    "Paoli 2005 (J. Differential Equations 211); Brogliato 2010, kinetic angle and continuity",
    "a rigid law meets small gaps event by event: as they vanish the outcome tends to binary "
    "impacts in the closing order, not to the law's simultaneous outcome, and the two closing "
    "orders disagree where the contacts meet at a kinetic angle other than 90 degrees",
    (("three_ball_chain", "default"),),
)

RIGID_DISPERSION = Claim(
    "dispersion",
    EVERYWHERE,
    "Brogliato 2010, energy dispersion in chains and the linear-spring limits of the three-ball "
    "chain; Nguyen and Brogliato 2014",
    "the law does not read the contacts' stiffness, so it cannot follow the spread of the "
    "energy over the bodies that the stiffness ratios decide in the compliant ground truth",
    (("two_balls_wall", "default"),),
)
