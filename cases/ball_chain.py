"""A chain of n balls on a line, all touching, optionally against a wall on the right.

Generalized coordinates: the velocities v1 ... vn of the balls, left to right (m/s, positive to
the right). Contact i (0-based) is between balls i+1 and i+2, gap rate ``v[i+1] - v[i]``; with
``wall`` true, the last contact is between ball n and a fixed wall on its right, gap rate
``-vn``. ``stiffness`` and ``exponent`` are one value for every contact or one per contact
(default 1 N/m^1.5, Hertz). ``velocities`` gives the first balls; the
ones it leaves out are at rest, so the default is one ball striking a chain at rest (the
Newton's cradle of the textbooks). Geometry, for the engines, up to 64 balls: balls of radius
0.1 m touching along x, the wall a plane (`_chains.chain_geometry`). Source: Brogliato, *An
introduction to impact dynamics* (2010), chains of balls.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._chains import (
    BALL_RADIUS,
    ELASTIC_AND_PLASTIC,
    NEWTONS_CRADLE,
    PLASTIC_CHAIN,
    SPRINGS,
    ball_velocities,
    chain_problem,
    exponent_spec,
    gaps_spec,
    masses_extremes,
    masses_spec,
    restitution_spec,
    velocities_spec,
)
from lawbench.core.case import CASES, Case, Params, per_item
from lawbench.core.errors import InvalidProblem
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags


class BallChain(Case):
    """n balls on a line, touching, struck from the left by default."""

    name = "ball_chain"
    summary = "n balls on a line, touching, optionally against a wall on the right"
    params = (
        Spec("n", 5, "number of balls", kind="int", low=2, high=100_000),
        masses_spec([1.0]),
        velocities_spec([1.0], "pre-impact velocities of the first balls; the rest are at rest"),
        restitution_spec(),
        Spec(
            "wall", False, "a fixed wall right of the last ball, as the last contact", kind="bool"
        ),
        _specs.positives(
            "stiffness", [1.0], "contact stiffness, one value or one per contact", "N/m^exponent"
        ),
        exponent_spec("floats"),
        gaps_spec(1),
    )
    requires = Tags(several_contacts=True)
    ground_truth = SPRINGS
    references = (PLASTIC_CHAIN, NEWTONS_CRADLE)
    bench_roles = ("long_chain",)

    examples = {
        "default": {},
        "wall": {"wall": True},
        "plastic": {"e": [0.0]},
        "graded masses": {"n": 10, "masses": [float(k) for k in range(1, 11)], "e": [0.9]},
    }

    def _check(self, params: dict[str, Any]) -> None:
        n = params["n"]
        contacts = n if params["wall"] else n - 1
        per_item(params, "masses", n, "ball")
        velocities = params["velocities"]
        if len(velocities) > n:
            raise InvalidProblem(f"velocities has {len(velocities)} values, more than n = {n}")
        params["velocities"] = velocities + [0.0] * (n - len(velocities))
        per_item(params, "e", contacts, "contact")
        per_item(params, "gaps", contacts, "contact")
        per_item(params, "stiffness", contacts, "contact")
        per_item(params, "exponent", contacts, "contact")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        n = params["n"]
        pairs: list[tuple[int | None, int | None]] = [(i, i + 1) for i in range(n - 1)]
        if params["wall"]:
            pairs.append((n - 1, None))
        return chain_problem(
            params["masses"],
            params["velocities"],
            pairs=pairs,
            restitution=params["e"],
            stiffness=params["stiffness"],
            exponents=params["exponent"],
            gaps=params["gaps"],
            radius=BALL_RADIUS,
        )

    def coordinates(self, params: Params) -> list[str]:
        """Velocities of the n balls."""
        return ball_velocities(params["n"])

    def momentum_axes(self, params: Params) -> np.ndarray | None:
        """Total momentum is conserved unless a wall takes part."""
        return None if params["wall"] else np.ones((1, params["n"]))


CASES.register(BallChain())


# The studies this scene declares, as data; the masses on two balls, one contact: every law,
# those that treat one contact only included.
BallChain.studies = (
    {
        "shape": "extremes",
        "name": "length",
        "title": "chain length [balls]",
        "axis": "n",
        "grid": {"n": [100], **ELASTIC_AND_PLASTIC},
        "full": {"grid": {"n": [10, 100, 1000], **ELASTIC_AND_PLASTIC}},
    },
    masses_extremes("striker's mass [kg], the struck ball 1 kg", 1, params={"n": 2}, laws="able"),
    {"shape": "speed_accuracy"},
)
