"""A lamina pivoted at a fixed point O strikes an anvil: one planar frictional contact.

Generalized coordinates: the angular velocity ``omega`` of the lamina about O (rad/s). The
contact point sits so that its normal velocity (positive away from the anvil) is ``f0 * omega``
and its tangential velocity ``h0 * omega``: ``Wn = [[f0]]``, ``Wt = [[h0]]`` and the mass matrix
is the moment of inertia about O, ``M = [[inertia]]``. Gravity is ignored during the impact.
Geometry, for the engines: the lamina's striking part a solid ball on a hinge through O (axis z,
a massless arm), touching the anvil, the fixed plane ``y = -h0`` below it, at the contact point
``(f0, -h0, 0)`` from O, normal y and tangent x, so that the contact point moves at
``omega (h0, f0, 0)``; the ball's mass makes its moment of inertia about O the lamina's.

Parameters (defaults): ``inertia`` 1 kg m^2; ``omega`` -1 rad/s (pre-impact, approaching the
anvil when ``f0 * omega < 0``); ``f0`` 1 m and ``h0`` 0.5 m (lever arms of the normal and
tangential velocities); ``e`` 0.5, the restitution coefficient every termination reads (each as
its own kind); ``mu`` 0.5. The defaults give ``mu |h0| / |f0| = 0.25``: the contact slips during
compression, slip and normal velocity vanish together, and the slip reverses in restitution.

Source: Brogliato, *An introduction to impact dynamics* (lectures, 2010), the lamina colliding
an anvil, frictionless and with Coulomb friction, after V.A. Lubarda (J. Appl. Mech., 2010).
With ``r = (|f0| - mu |h0|) / (|f0| + mu |h0|)`` friction lengthens the normal lever arm in
compression (``|f0| + mu |h0|``) and shortens it in restitution (``|f0| - mu |h0|``), so the
three coefficients giving one outcome are related by ``ep = en / r`` and ``e*^2 = ep en``, hence
``en < e* < ep`` (lectures, eq. 12): Newton's termination gives ``omega+ = -e omega-``,
Poisson's ``-e r omega-`` and Stronge's ``-e sqrt(r) omega-``. When ``mu |h0| >= |f0|`` (the
friction cone contains O) sticking is permanent once reached and the impact is plastic,
``omega+ = 0``, whatever the termination (lectures, "case of large friction").
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._friction import springs_with_friction
from lawbench.cases._geometry import plane, solid_sphere
from lawbench.core.case import CASES, Case, Params, Reference
from lawbench.core.geometry import ContactPair, Geometry, Joint
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags

# The radius of the ball that strikes the anvil, over the contact point's distance from O.
BALL_RADIUS = 0.1
_SOURCE = "Lubarda 2010 as given by Brogliato 2010, lamina on an anvil, eqs. (12)-(14)"


def lever_ratio(p: Params) -> float:
    """``(|f0| - mu |h0|) / (|f0| + mu |h0|)``: restitution over compression lever arm."""
    f0, arm = abs(p["f0"]), p["mu"] * abs(p["h0"])
    return (f0 - arm) / (f0 + arm)


def _approaches(p: Params) -> str | None:
    if p["f0"] * p["omega"] >= 0:
        return "needs the lamina to approach the anvil (f0 * omega < 0)"
    return None


def _rebounds(p: Params) -> str | None:
    if reason := _approaches(p):
        return reason
    if p["mu"] * abs(p["h0"]) >= abs(p["f0"]):
        return "needs mu |h0| < |f0| (otherwise the impact is plastic)"
    return None


def _sticks(p: Params) -> str | None:
    if reason := _approaches(p):
        return reason
    if p["mu"] * abs(p["h0"]) < abs(p["f0"]):
        return "needs mu |h0| >= |f0| (permanent sticking)"
    return None


def _rebound(factor: float) -> Any:
    """Reference velocity ``-e * factor(r) * omega-`` of one termination."""

    def v_plus(p: Params) -> np.ndarray:
        return np.array([-p["e"] * factor(lever_ratio(p)) * p["omega"]])

    return v_plus


def _termination(name: str, factor: Any, formula: str) -> Reference:
    return Reference(
        f"Lubarda, {name} termination",
        f"{_SOURCE}: omega+ = {formula}",
        "darboux_keller",
        _rebound(factor),
        options={"termination": name},
        condition=_rebounds,
    )


@functools.lru_cache(maxsize=64)
def _geometry(inertia: float, f0: float, h0: float, e: float, mu: float) -> Geometry | None:
    """The striking ball on a hinge through O, against the anvil plane ``y = -h0``.

    None when the contact point is O itself (no lever arm: nothing for an engine to turn).
    Cached: a geometry is immutable, and a sweep of omega keeps it.
    """
    arm = math.hypot(f0, h0)
    if arm == 0:
        return None
    radius = BALL_RADIUS * arm
    centre = (f0, radius - h0, 0.0)
    # A solid ball's moment of inertia about O: m (|centre|^2 + 2 radius^2 / 5).
    mass = inertia / (f0**2 + (radius - h0) ** 2 + 0.4 * radius**2)
    ball = solid_sphere("lamina", mass, radius, centre)
    anvil = plane("anvil", (f0, -h0, 0.0), (0.0, 1.0, 0.0))
    pair = ContactPair("lamina", "anvil", (f0, -h0, 0.0), (0, 1, 0), ((1, 0, 0),), e, mu)
    joints = [Joint("hinge", "lamina", (0.0, 0.0, 1.0)), Joint("fixed", "anvil")]
    # omega turns the ball about O: its centre moves at omega z x centre.
    to_bodies = np.zeros((12, 1))
    to_bodies[:6, 0] = (-centre[1], centre[0], 0.0, 0.0, 0.0, 1.0)
    to_generalized = np.zeros((1, 12))
    to_generalized[0, 5] = 1.0
    return Geometry((ball, anvil), tuple(joints), (pair,), to_bodies, to_generalized)


class Lamina(Case):
    """A lamina pivoted at O strikes an anvil with friction (one planar contact)."""

    name = "lamina"
    summary = "lamina pivoted at a fixed point strikes an anvil with friction (Lubarda 2010)"
    params = (
        Spec(
            "inertia",
            1.0,
            "moment of inertia of the lamina about O",
            unit="kg m^2",
            low=0.0,
            low_open=True,
        ),
        Spec(
            "omega", -1.0, "pre-impact angular velocity (f0 * omega < 0 approaches)", unit="rad/s"
        ),
        Spec("f0", 1.0, "normal lever arm: normal contact velocity = f0 * omega", unit="m"),
        Spec("h0", 0.5, "tangential lever arm: tangential contact velocity = h0 * omega", unit="m"),
        Spec(
            "e",
            0.5,
            "restitution coefficient (each law reads it as its own kind)",
            low=0.0,
            high=1.0,
        ),
        _specs.friction(0.5),
    )
    requires = Tags(friction=True)
    # Stepping the engines through this scene's studies adds seconds to the quick report.
    quick_engines = False
    ground_truth = springs_with_friction(
        "on the lamina the slip can stop and stick during the impact, which decides between "
        "Lubarda's closed forms (one per termination of the rigid impulse dynamics)"
    )
    references = (
        _termination("newton", lambda r: 1.0, "-e omega-"),
        _termination("poisson", lambda r: r, "-e r omega-"),
        _termination("energetic", math.sqrt, "-e sqrt(r) omega-"),
        Reference(
            "plastic (mu |h0| >= |f0|)",
            f"{_SOURCE}: permanent sticking, omega+ = 0 for every termination",
            "darboux_keller",
            lambda p: np.zeros(1),
            condition=_sticks,
        ),
    )
    examples = {
        "default": {},
        "slip reversal, lively": {"e": 0.9, "mu": 0.3, "h0": 1.0},
        "permanent stick": {"mu": 1.0, "h0": 1.5},
        "frictionless": {"mu": 0.0},
        "mirrored arms": {"f0": -1.0, "h0": -0.5, "omega": 1.0},
    }

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        return ImpactProblem(
            M=[[params["inertia"]]],
            Wn=[[params["f0"]]],
            Wt=[[params["h0"]]],
            v=[params["omega"]],
            contacts=[Contact(e=params["e"], mu=params["mu"])],
            bodies={"lamina": [0]},
            geometry=_geometry(
                params["inertia"], params["f0"], params["h0"], params["e"], params["mu"]
            ),
        )

    def coordinates(self, params: Params) -> list[str]:
        """The angular velocity about O."""
        return ["omega (rad/s)"]


CASES.register(Lamina())


# The studies this scene declares, as data.
Lamina.studies = (
    {"shape": "speed_accuracy"},
    {"shape": "large_friction"},
    {"shape": "grazing", "e": [0.0, 1.0]},
    {"shape": "duplicated_contact", "e": [0.0, 1.0]},
)
