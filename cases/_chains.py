"""What the chain scenes share: two-contact chains, closed forms, ground truth and studies.

`lawbench.numerics.chains` builds the problems; this module holds the references of free chains,
the ground truth of every chain scene (compliant integration at the scene's stiffnesses) and the
studies the chain scenes declare alike (as data, `lawbench.studies.declared`), each run with
every contact elastic and with every contact plastic.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from lawbench.checks.knobs import decades
from lawbench.core.case import Case, GroundTruth, Reference, exactly, per_item
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.numerics.chains import (
    Pair,
    chain_problem,
    exponent_spec,
    gaps_spec,
    masses_spec,
    restitution_spec,
    stiffness_ratio_spec,
    velocities_spec,
)


class TwoContactChain(Case):
    """Balls on a line with two contacts, contact 0 of stiffness 1 and contact 1 of the ratio.

    A subclass says which balls each contact joins (``pairs``, None for a fixed wall); the
    parameters ``masses``, ``velocities`` and ``gaps`` take one value per ball or contact, ``e``
    one value or one per contact.
    """

    pairs: ClassVar[tuple[Pair, Pair]]

    @staticmethod
    def specs(velocities: list[float], velocities_doc: str, ratio_doc: str) -> tuple[Spec, ...]:
        """The parameters, unit masses and the given pre-impact ``velocities`` by default."""
        return (
            masses_spec([1.0] * len(velocities)),
            velocities_spec(velocities, velocities_doc),
            restitution_spec(),
            stiffness_ratio_spec(ratio_doc),
            exponent_spec(),
            gaps_spec(2),
        )

    def _check(self, params: dict[str, Any]) -> None:
        balls = max(ball for pair in self.pairs for ball in pair if ball is not None) + 1
        exactly(params, "masses", balls, "ball")
        exactly(params, "velocities", balls, "ball")
        exactly(params, "gaps", 2, "contact")
        per_item(params, "e", 2, "contact")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        return chain_problem(
            params["masses"],
            params["velocities"],
            pairs=list(self.pairs),
            restitution=params["e"],
            stiffness=[1.0, params["stiffness_ratio"]],
            exponents=[params["exponent"]] * 2,
            gaps=params["gaps"],
        )


SPRINGS = GroundTruth(
    why="the chain's outcome depends on how the contacts' stiffnesses share the impact, which "
    "only time integration of the unilateral springs resolves (Brogliato 2010, linear-spring "
    "limits of the three-ball chain)",
    law="compliant",
    options={"tol": 1e-10},
)


def _plastic_velocity(params: Mapping[str, Any]) -> np.ndarray:
    wall = params.get("wall", False)
    masses = np.asarray(params["masses"])
    velocities = np.asarray(params["velocities"])
    common = 0.0 if wall else float(masses @ velocities / masses.sum())
    return np.full(len(masses), common)


def _plastic_condition(params: Mapping[str, Any]) -> str | None:
    if any(params["e"]):
        return "needs e = 0 at every contact"
    masses = np.asarray(params["masses"])
    velocities = np.asarray(params["velocities"])
    # Impulse of the contact right of ball j = momentum the balls 1..j lose.
    impulses = np.cumsum(masses * (velocities - _plastic_velocity(params)))[:-1]
    if params.get("wall", False):
        impulses = np.append(impulses, masses @ velocities)
    if (impulses < 0).any():
        return "a contact would need a tensile impulse for the chain to stick"
    return None


# Brogliato, *An introduction to impact dynamics* (2010), remark after equation (29): with
# e = 0 Moreau's law gives every ball the velocity of the centre of mass (zero against a wall
# on the right). It holds while every contact impulse of the stuck chain is non-negative.
PLASTIC_CHAIN = Reference(
    name="plastic chain",
    source="Brogliato 2010, remark after eq. (29): Moreau's law at e = 0",
    law="moreau",
    v_plus=_plastic_velocity,
    condition=_plastic_condition,
)


def _cradle_condition(params: Mapping[str, Any]) -> str | None:
    masses, velocities = params["masses"], params["velocities"]
    if params.get("wall", False):
        return "needs a free chain (no wall)"
    if len(set(masses)) > 1:
        return "needs equal masses"
    if any(e != 1.0 for e in params["e"]):
        return "needs e = 1"
    if velocities[0] <= 0 or any(velocities[1:]):
        return "needs the first ball moving right and the others at rest"
    return None


NEWTONS_CRADLE = Reference(
    name="Newton's cradle",
    source="textbook solution (Brogliato 2010, 'Textbooks solutions'): the last ball leaves "
    "with the velocity of the first, the others stay at rest",
    law="sequential",
    v_plus=lambda p: np.eye(len(p["masses"]))[-1] * p["velocities"][0],
    condition=_cradle_condition,
)


# The restitutions every stability study of a chain is run at: elastic and plastic.
ELASTIC_AND_PLASTIC = {"e": [[0.0], [1.0]]}


def masses_extremes(title: str, others: int, **more: Any) -> dict[str, Any]:
    """The stability study along the striker's mass, 1e-6 to 1e6 kg, ``others`` balls of 1 kg.

    ``more`` are further arguments of the ``extremes`` shape (fixed parameters, laws).
    """

    def grid(step: int) -> dict[str, list]:
        return {
            "masses": [[r] + [1.0] * others for r in decades(-6, 6, step)],
            **ELASTIC_AND_PLASTIC,
        }

    return {
        "shape": "extremes",
        "name": "masses",
        "title": title,
        "axis": "masses",
        "grid": grid(3),
        **more,
        "full": {"grid": grid(1)},
    }


def two_contact_studies(stiffness_title: str, **shares: str) -> tuple[dict[str, Any], ...]:
    """The studies of a chain of two contacts whose stiffness ratio is a parameter.

    Its stiffness ratio pushed over eight decades (sixteen in the full report; its meaning in
    ``stiffness_title``), a grazing approach and contact 0 given twice, each elastic and plastic;
    the speed/accuracy trade; the energy shares per body over the stiffness ratio (``shares``:
    the study's ``name`` when not the default) and the continuity sweep.
    """
    return (
        {
            "shape": "extremes",
            "name": "stiffness",
            "title": stiffness_title,
            "axis": "stiffness_ratio",
            "grid": {"stiffness_ratio": decades(-4, 4, 4), **ELASTIC_AND_PLASTIC},
            "full": {"grid": {"stiffness_ratio": decades(-8, 8), **ELASTIC_AND_PLASTIC}},
        },
        {"shape": "grazing", "e": ELASTIC_AND_PLASTIC["e"]},
        {"shape": "duplicated_contact", "e": ELASTIC_AND_PLASTIC["e"]},
        {"shape": "speed_accuracy"},
        {
            "shape": "energy_shares",
            "ratios": decades(-3, 3, 2),
            "full_ratios": np.logspace(-3, 3, 25).tolist(),
            **shares,
        },
        {"shape": "continuity"},
    )
