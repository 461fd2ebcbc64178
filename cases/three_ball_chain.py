"""Three balls on a line, all touching: the classic multiple-impact benchmark.

Generalized coordinates: the velocities v1, v2, v3 of balls 1, 2, 3 (left to right, m/s,
positive to the right). Contact 0 is between balls 1 and 2, contact 1 between balls 2 and 3;
gap rates are ``v2 - v1`` and ``v3 - v2``. Contact 0 has stiffness 1 N/m^exponent and contact 1
``stiffness_ratio`` times that (only compliant and energetic laws read stiffness). Geometry,
for the engines: balls of radius 0.1 m touching along x (`_chains.chain_geometry`). Source:
Brogliato, *An introduction to impact dynamics* (2010), three-ball chain, equation (29).
"""

from __future__ import annotations

import numpy as np

from lawbench.cases._chains import (
    NEWTONS_CRADLE,
    PLASTIC_CHAIN,
    SPRINGS,
    TwoContactChain,
    ball_velocities,
    masses_extremes,
    two_contact_studies,
)
from lawbench.core.case import CASES, Params, Reference
from lawbench.core.tags import Tags


def _equation_29(p: Params) -> np.ndarray:
    """Newton's law at both contacts at once, equal masses (Brogliato 2010, eq. 29)."""
    (v1, v2, v3), (e1, e2) = p["velocities"], p["e"]
    return (
        np.array(
            [
                (1 - 2 * e1) * v1 + (1 - e2 + 2 * e1) * v2 + (1 + e2) * v3,
                (1 + e1) * v1 + (1 - e2 - e1) * v2 + (1 + e2) * v3,
                (1 + e1) * v1 + (1 + 2 * e2 - e1) * v2 + (1 - 2 * e2) * v3,
            ]
        )
        / 3.0
    )


def _equal_masses(p: Params) -> str | None:
    return None if len(set(p["masses"])) == 1 else "needs equal masses"


def _moreau_as_newton(p: Params) -> str | None:
    """Moreau's law equals eq. (29) when it needs no tensile impulse and nothing separates."""
    if reason := _equal_masses(p):
        return reason
    if len(set(p["e"])) > 1:
        return "needs one e for both contacts"
    (v1, v2, v3), v_plus = p["velocities"], _equation_29(p)
    if v2 - v1 > 0 or v3 - v2 > 0:
        return "needs no contact separating before the impact"
    if v1 - v_plus[0] < 0 or v_plus[2] - v3 < 0:
        return "eq. (29) needs a tensile impulse here"
    return None


class ThreeBallChain(TwoContactChain):
    """Three balls on a line, touching, struck from the left by default."""

    name = "three_ball_chain"
    summary = "three balls on a line, touching (Brogliato 2010, eq. 29)"
    params = TwoContactChain.specs(
        [1.0, 0.0, 0.0],
        "pre-impact velocities of balls 1, 2, 3",
        "stiffness of contact 1 over contact 0",
    )
    requires = Tags(several_contacts=True)
    pairs = ((0, 1), (1, 2))
    # The smallest multiple impact: its start-up is the cost of the smallest command, and the
    # engines' cost per impact of a multiple impact.
    bench_roles = ("start_up", "engine_cost")
    ground_truth = SPRINGS
    references = (
        Reference(
            "eq. (29)",
            "Brogliato 2010, eq. (29): Newton's law at both contacts, equal masses",
            "newton",
            _equation_29,
            condition=_equal_masses,
        ),
        Reference(
            "eq. (29) as Moreau",
            "Brogliato 2010, remark after eq. (29): Moreau's law equals eq. (29) here",
            "moreau",
            _equation_29,
            condition=_moreau_as_newton,
        ),
        PLASTIC_CHAIN,
        NEWTONS_CRADLE,
    )

    examples = {
        "default": {},
        "head-on": {"velocities": [1.0, 0.0, -1.0], "e": [0.5, 1.0]},
        "unequal masses": {"masses": [1.0, 10.0, 0.1], "e": [0.8]},
        "separating contact": {"velocities": [1.0, 0.0, 0.75]},
    }

    def coordinates(self, params: Params) -> list[str]:
        """Velocities of balls 1, 2, 3."""
        return ball_velocities(3)

    def momentum_axes(self, params: Params) -> np.ndarray:
        """The chain is free: total momentum is conserved."""
        return np.ones((1, 3))


CASES.register(ThreeBallChain())


# The studies this scene declares, as data.
ThreeBallChain.studies = (
    *two_contact_studies("stiffness ratio (contact 1 over contact 0)", name="dispersion"),
    masses_extremes("striker's mass [kg], the others 1 kg", 2),
)
