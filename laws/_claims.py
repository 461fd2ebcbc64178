"""Claims that several laws share, each declared once with its source.

A law lists the ones that apply to it in its ``findings`` (`lawbench.core.verdicts.Claim`).
"""

from lawbench.checks.regions import (
    EVERYWHERE,
    coupled_friction,
    dissipative_contacts,
    oblique_contacts,
    recompressed_contact,
    separating_contact,
)
from lawbench.core.verdicts import Claim, Region

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

FROZEN_CONFIGURATION = Claim(
    "dispersion",
    recompressed_contact,
    "Liu, Zhao and Brogliato, Proc. R. Soc. A 464 (2008) and Jia, Mason and Erdmann, IJRR 32(1) "
    "(2013): the springs act at a frozen configuration",
    "the springs act at a frozen configuration, so a contact whose energy went back to zero "
    "keeps no gap and is compressed again as soon as it approaches, where the compliant ground "
    "truth first closes the gap it opened; the energy then spreads differently (two balls on a "
    "wall 100 times stiffer than the ball contact: v+ = (1.414, 0.014) against (1.008, 0.992) "
    "with linear springs)",
    (("two_balls_wall", "stiff wall"),),
)

ENERGETIC_DISSIPATION = Claim(
    "dispersion",
    dissipative_contacts,
    "Liu, Zhao and Brogliato, Proc. R. Soc. A 464 (2008) and Jia, Mason and Erdmann, IJRR 32(1) "
    "(2013): the energy is taken at each end of compression; Brogliato 2010, compliant models",
    "an energetic coefficient takes the energy at the end of each compression, a dashpot all "
    "along the impact, and the two spread the remaining energy differently over the bodies; "
    "the compliant ground truth is itself one damping rule among several (ping-pong stack at "
    "e = 0.950043, 0.846529, k2/k1 = 3: jia v+ = (1.057, 0.551) v0, compliant Hunt-Crossley "
    "(1.160, 0.433) v0, Kelvin-Voigt (1.192, 0.463) v0; all three agree at e = 1)",
    (("ping_pong", "default"),),
)


SLIP_REVERSAL_GAIN = Claim(
    "energy_gain",
    coupled_friction,
    "Kane and Levinson 1985; Brogliato 2010, eqs. (6)-(9)",
    "kinematic restitution with Coulomb friction on the post-impact slip (at one contact "
    "Whittaker's law, Brogliato 2010 eq. 8): inertial coupling reverses the slip during the "
    "impact, and dT = -e Pn un- - mu Pn |ut+| - P.G P / 2 is then positive for e close to 1 "
    "(Kane and Levinson's paradox)",
    (("falling_rod", "energy gain"), ("double_pendulum", "default")),
)


def separating_held(check: str, region: Region = separating_contact) -> Claim:
    """Moreau's unilateral law gains energy on a contact that separates before the impact.

    ``check`` is ``energy_gain`` or ``energy_kept``; ``region`` narrows where it applies.
    """
    return Claim(
        check,
        region,
        "Brogliato 2010, Moreau's law; dT = sum Pn_j (un-_j + un+_j) / 2",
        "a contact that separates before the impact, dragged into it by its neighbours, is "
        "held at un+ = 0 without restitution, and its impulse adds Pn un- / 2 > 0 to the "
        "energy change: kinematic restitution per contact is not dissipative once a "
        "separating contact takes part",
        (("three_ball_chain", "separating contact"),),
    )


def keeps_energy(source: str, reason: str) -> Claim:
    """The law keeps the energy of elastic frictionless impacts: a loss or gain is numerical."""
    return Claim("energy_kept", EVERYWHERE, source, reason)


def never_creates_energy(source: str, reason: str, region: Region = EVERYWHERE) -> Claim:
    """The law never creates energy in ``region``: a gain there is numerical."""
    return Claim("energy_gain", region, source, reason)
