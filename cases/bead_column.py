"""A column of beads dropped onto a wall: Falcon et al.'s experiment.

Generalized coordinates: the velocities v1 ... vn of the beads along the vertical (m/s,
positive upwards, away from the wall); bead 1 rests on the wall, bead i+1 on bead i. Contact 0
is between the wall and bead 1 (gap rate ``v1``), contact i between beads i and i+1 (gap rate
``v[i+1] - v[i]``). Every bead falls with ``sqrt(2 g drop_height)``, the column touching
itself and the wall at the first instant; gravity is ignored during the impact.

Parameters: ``n`` beads (1 to 1000, default 10), ``drop_height`` (m, default 3.1e-3),
``e`` (one value or one per contact, default 1). Fixed by the experiment: stainless steel
beads 8 mm in diameter of 2.05e-3 kg, Hertz contacts (exponent 3/2) of stiffness 6.9716e9
N/m^1.5 between beads and 9.858e9 N/m^1.5 against the wall. Geometry, for the engines, up to 64
beads: beads of radius 4 mm along the wall's normal (`_chains.chain_geometry`).

Source: E. Falcon, C. Laroche, S. Fauve, C. Coste, Eur. Phys. J. B 5 (1998), as reported in
Brogliato, *An introduction to impact dynamics* (2010), 'Columns of balls impacting a wall':
measured peak wall force 52 N for h = 3.1 mm and 71 N for h = 5.1 mm, nearly independent of
the number of beads from 1 to 40, and an oscillation of the wall force with period
32.4 +/- 1 microseconds at h = 3.1 mm.
"""

from __future__ import annotations

import math
from typing import Any

from lawbench.cases import _specs
from lawbench.cases._chains import SPRINGS, ball_velocities, chain_problem, restitution_spec
from lawbench.core.case import CASES, Case, Params, per_item
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags

BEAD_MASS = 2.05e-3
BEAD_RADIUS = 4e-3
BEAD_STIFFNESS = 6.9716e9
WALL_STIFFNESS = 9.858e9
GRAVITY = 9.81
# Falcon et al. 1998, as reported in the lectures: drop height (m) -> measured peak force (N).
MEASURED_PEAK_FORCE = {3.1e-3: 52.0, 5.1e-3: 71.0}
MEASURED_PERIOD = 32.4e-6


class BeadColumn(Case):
    """n steel beads falling onto a steel wall."""

    name = "bead_column"
    summary = "a column of steel beads dropped onto a wall (Falcon et al. 1998)"
    params = (
        Spec("n", 10, "number of beads", kind="int", low=1, high=1000),
        _specs.positive("drop_height", 3.1e-3, "height the column falls from", "m"),
        restitution_spec(),
    )
    requires = Tags(several_contacts=True, stiffness=True)
    ground_truth = SPRINGS
    examples = {"default": {}, "one bead": {"n": 1}, "higher drop": {"drop_height": 5.1e-3}}

    def _check(self, params: dict[str, Any]) -> None:
        per_item(params, "e", params["n"], "contact")

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        n = params["n"]
        speed = math.sqrt(2.0 * GRAVITY * params["drop_height"])
        return chain_problem(
            [BEAD_MASS] * n,
            [-speed] * n,
            pairs=[(None, 0)] + [(i, i + 1) for i in range(n - 1)],
            restitution=params["e"],
            stiffness=[WALL_STIFFNESS] + [BEAD_STIFFNESS] * (n - 1),
            exponents=[1.5] * n,
            radius=BEAD_RADIUS,
        )

    def coordinates(self, params: Params) -> list[str]:
        """Velocities of the beads, bead 1 on the wall, positive upwards."""
        return ball_velocities(params["n"])


CASES.register(BeadColumn())

# The studies this scene declares, as data.
BeadColumn.studies = ({"shape": "speed_accuracy"},)
