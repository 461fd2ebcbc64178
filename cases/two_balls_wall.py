"""Two balls stacked on a fixed wall: ball 1 on ball 2 on the wall.

Generalized coordinates: the velocities v1 (ball 1, the outer one) and v2 (ball 2, touching
the wall) along the wall normal, m/s, positive away from the wall. Contact 0 is between the
balls (gap rate ``v1 - v2``), contact 1 between ball 2 and the wall (gap rate ``v2``). Gravity
is ignored during the impact. Contact 0 has stiffness 1 N/m^exponent, the wall contact
``stiffness_ratio`` times that. Geometry, for the engines: balls of radius 0.1 m along x on the
wall plane (`_chains.chain_geometry`). Source: Brogliato, *An introduction to impact dynamics*
(2010), equations (25)-(28); the kinetic angle of the two constraints (26) is obtuse, so
sequences of binary impacts depend on their order.
"""

from __future__ import annotations

import numpy as np

from lawbench.cases._chains import SPRINGS, TwoContactChain, ball_velocities, two_contact_studies
from lawbench.core.case import CASES, Params, Reference
from lawbench.core.tags import Tags


def _unpack(p: Params) -> tuple[float, float, float, float, float]:
    (m1, m2), (q1, q2), (e1, e2) = p["masses"], p["velocities"], p["e"]
    return m1 / m2, q1, q2, e1, e2


def _balls(m: float, e1: float, q1: float, q2: float) -> tuple[float, float]:
    """Binary Newton impact of ball 1 on ball 2 (m = m1/m2)."""
    return ((m - e1) * q1 + (1 + e1) * q2) / (1 + m), (m * (1 + e1) * q1 + (1 - e1 * m) * q2) / (
        1 + m
    )


def _equation_27(p: Params) -> np.ndarray:
    """Ball 2 on the wall, then ball 1 on ball 2 (Brogliato 2010, eq. 27)."""
    m, q1, q2, e1, e2 = _unpack(p)
    return np.array(
        [
            (m - e1) / (1 + m) * q1 - e2 * (1 + e1) / (1 + m) * q2,
            m * (1 + e1) / (1 + m) * q1 - e2 * (1 - e1 * m) / (1 + m) * q2,
        ]
    )


def _equation_28(p: Params) -> np.ndarray:
    """Balls, wall, balls again (Brogliato 2010, eq. 28); the braces are the first impact."""
    m, q1, q2, e1, e2 = _unpack(p)
    brace_1 = (m - e1) / (1 + m) * q1 + (1 + e1) / (1 + m) * q2
    brace_2 = m * (1 + e1) / (1 + m) * q1 + (1 - e1 * m) / (1 + m) * q2
    return np.array(
        [
            (m - e1) / (1 + m) * brace_1 - e2 * (1 + e1) / (1 + m) * brace_2,
            m * (1 + e1) / (1 + m) * brace_1 - e2 * (1 - e1 * m) / (1 + m) * brace_2,
        ]
    )


def _ends_after_27(p: Params) -> str | None:
    _, q1, q2, _, e2 = _unpack(p)
    if q2 >= 0 or q1 + e2 * q2 >= 0:
        return "needs the wall contact, then the ball contact, to approach in turn"
    if _equation_27(p)[1] < 0:
        return "ball 2 goes back to the wall: the sequence is longer"
    return None


def _ends_after_28(p: Params) -> str | None:
    m, q1, q2, e1, e2 = _unpack(p)
    q1_after, q2_after = _balls(m, e1, q1, q2)
    if q1 - q2 >= 0 or q2_after >= 0 or q1_after + e2 * q2_after >= 0:
        return "needs the ball contact, the wall contact, then the ball contact to approach in turn"
    if _equation_28(p)[1] < 0:
        return "ball 2 goes back to the wall: the sequence is longer"
    return None


class TwoBallsWall(TwoContactChain):
    """Ball 1 on ball 2 on a wall, both falling onto it."""

    name = "two_balls_wall"
    summary = "ball 1 on ball 2 on a fixed wall (Brogliato 2010, eqs. 25-28)"
    params = TwoContactChain.specs(
        [-1.0, -1.0],
        "pre-impact velocities of ball 1 (outer) and ball 2",
        "stiffness of the wall contact over the ball contact",
    )
    requires = Tags(several_contacts=True)
    pairs = ((1, 0), (None, 1))
    ground_truth = SPRINGS
    references = (
        Reference(
            "eq. (27)",
            "Brogliato 2010, eq. (27): wall impact, then ball impact",
            "sequential",
            _equation_27,
            options={"order": "right_to_left"},
            condition=_ends_after_27,
        ),
        Reference(
            "eq. (28)",
            "Brogliato 2010, eq. (28): ball impact, wall impact, ball impact",
            "sequential",
            _equation_28,
            options={"order": "left_to_right"},
            condition=_ends_after_28,
        ),
    )

    examples = {
        "default": {},
        "both approaching": {"velocities": [-2.0, -1.0], "e": [0.5, 0.8]},
        "light outer ball": {"masses": [0.1, 1.0]},
        "separating ball": {"velocities": [-1.0, 0.5], "e": [0.5]},
        "stiff wall": {"stiffness_ratio": 100.0},
    }

    def coordinates(self, params: Params) -> list[str]:
        """Velocities of ball 1 (outer) and ball 2, away from the wall."""
        return ball_velocities(2)


CASES.register(TwoBallsWall())


# The studies this scene declares, as data.
TwoBallsWall.studies = two_contact_studies("stiffness ratio (wall over balls)")
