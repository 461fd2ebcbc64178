"""A ball strikes the face of a disk standing on a rough floor (Zhang, Liu, Zhao, Brogliato 2013).

A homogeneous disk (radius r, thickness 2h, mass md) stands upright on its rim on a rough
horizontal floor; a ball (mass mb, radius much smaller than r, treated as a particle) moving
horizontally at speed vb strikes the disk's face normally at point D, at height b above the
disk's centre O on its vertical axis. Source: H. J. Zhang, C. S. Liu, Z. Zhao, B. Brogliato,
*Energy evolution in complex impacts with friction*, Sci. China Phys. Mech. Astron. 56 (2013)
875-881, Section 2 and eq. (1); the disk-floor line contact discretized into three points.
The scene declares no geometry, so the engines refuse it: an upright disk on a floor is a line
contact, which an engine meets at points of its own rather than the source's three, and the
ball is a particle.

Generalized coordinates (the source's): q = (yb, zb, yd, zd, theta); velocities ``vyb, vzb``
(ball, m/s), ``vyd, vzd`` (disk centre, m/s), ``omega`` (disk, rad/s). y is horizontal along
the disk's symmetry axis (the ball's flight), z vertical up, omega the rotation rate in the
(y, z) plane, positive from y towards z. M = diag(mb, mb, md, md, I) with the disk's moment of
inertia about a diameter, I = md (r^2 / 4 + (2h)^2 / 12). Gravity is ignored during the impact.

Contacts (derivation of W and N, the source's matrices being garbled in extraction). A point of
the disk at offset rho = (rho_y, rho_z) from O moves at (vyd - omega rho_z, vzd + omega rho_y).

- A, B, C: the rim on the floor, at rho = (-h, -r), (0, -r), (h, -r). Normal +z, so the gap
  rate is vzd + omega rho_y: ``vzd - h omega``, ``vzd``, ``vzd + h omega``. Tangent +y: the
  slip rate of every floor point is ``vyd + r omega``.
- D: the ball on the face y = yd - h (the ball comes from -y), rho = (-h, b). The normal points
  from the disk to the ball, -y, so the gap rate is -(vyb - (vyd - b omega)) =
  ``-vyb + vyd - b omega`` (the ball approaches for vyb > vyd - b omega). Tangent +z: the slip
  rate of the ball over the face is vzb - (vzd + omega (-h)) = ``vzb - vzd + h omega``.

Columns of Wn (A, B, C, D) and Wt (A, B, C, D), rows (vyb, vzb, vyd, vzd, omega)::

    Wn = [[ 0,  0, 0, -1],      Wt = [[0, 0, 0,  0],
          [ 0,  0, 0,  0],            [0, 0, 0,  1],
          [ 0,  0, 0,  1],            [1, 1, 1,  0],
          [ 1,  1, 1,  0],            [0, 0, 0, -1],
          [-h,  0, h, -b]]            [r, r, r,  h]]

Parameters (``lawbench describe disk_ball``): ``b`` (m, impact height above O, within
[-r, r]), ``vb`` (m/s), ``radius`` r and ``half_thickness`` h (m), ``disk_mass`` md and
``ball_mass`` mb (kg), ``mu_floor`` and ``mu_ball`` (Coulomb, at A, B, C and at D), ``e``
(Stronge's energetic coefficient, one value or one per contact A, B, C, D),
``stiffness_ratio`` (stiffness of each floor point over the ball contact's) and ``exponent``
(1.5: Hertz). The defaults (a 0.5 kg disk of radius 5 cm, 1 cm thick, struck at 1 m/s by a
20 g ball, mu 0.3 at the floor and 0.2 at the ball, e = 0.6) are illustrative: the source's
values are on pages the extraction does not hold. The source's reference law is the energetic
multiple-impact law with Coulomb friction (``lzb``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.cases import _specs
from lawbench.cases._chains import exponent_spec, stiffness_ratio_spec
from lawbench.cases._friction import springs_with_friction
from lawbench.core.case import CASES, Case, Params, per_item
from lawbench.core.errors import InvalidProblem
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags

CONTACTS = ("A", "B", "C", "D")


def disk_inertia(mass: float, radius: float, half_thickness: float) -> float:
    """Moment of inertia of a homogeneous disk about a diameter (kg m^2)."""
    return mass * (radius**2 / 4.0 + (2.0 * half_thickness) ** 2 / 12.0)


def jacobians(radius: float, half_thickness: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """Normal and tangential Jacobians (5 x 4 each) of contacts A, B, C, D (module docstring)."""
    r, h = radius, half_thickness
    Wn = np.array(
        [
            [0.0, 0.0, 0.0, -1.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0, 0.0],
            [-h, 0.0, h, -b],
        ]
    )
    Wt = np.array(
        [
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, -1.0],
            [r, r, r, h],
        ]
    )
    return Wn, Wt


class DiskBall(Case):
    """A ball strikes an upright disk on a rough floor; four frictional contacts."""

    name = "disk_ball"
    summary = "ball striking a disk standing on a rough floor (Zhang, Liu, Zhao, Brogliato 2013)"
    params = (
        Spec("b", 0.02, "impact height above the disk's centre, on its axis", unit="m"),
        _specs.positive("vb", 1.0, "ball speed towards the disk", "m/s"),
        _specs.positive("radius", 0.05, "disk radius r", "m"),
        _specs.positive("half_thickness", 0.005, "half the disk's thickness, h", "m"),
        _specs.positive("disk_mass", 0.5, "disk mass md", "kg"),
        _specs.positive("ball_mass", 0.02, "ball mass mb", "kg"),
        Spec("mu_floor", 0.3, "Coulomb friction at the floor points A, B, C", low=0.0),
        Spec("mu_ball", 0.2, "Coulomb friction between ball and disk (D)", low=0.0),
        Spec(
            "e",
            [0.6],
            "Stronge's energetic restitution, one value or one per contact A, B, C, D",
            kind="floats",
            low=0.0,
            high=1.0,
        ),
        stiffness_ratio_spec("stiffness of each floor point over that of the ball contact"),
        exponent_spec(),
    )
    requires = Tags(friction=True, several_contacts=True)
    ground_truth = springs_with_friction(
        "the source resolves the impact with the energetic multiple-impact law, whose "
        "stiffness ratios and exponent are the springs' own (Zhang et al. 2013)"
    )
    examples = {
        "default": {},
        "struck low": {"b": -0.04},
        "struck high": {"b": 0.045},
        "frictionless": {"mu_floor": 0.0, "mu_ball": 0.0},
    }

    def _check(self, params: dict[str, Any]) -> None:
        per_item(params, "e", len(CONTACTS), "contact A, B, C, D")
        if abs(params["b"]) > params["radius"]:
            raise InvalidProblem(
                f"b = {params['b']:g}: the impact point must lie on the disk "
                f"(|b| <= radius = {params['radius']:g})"
            )

    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        r, h, md, mb = (
            params["radius"],
            params["half_thickness"],
            params["disk_mass"],
            params["ball_mass"],
        )
        Wn, Wt = jacobians(r, h, params["b"])
        floor = {
            "mu": params["mu_floor"],
            "stiffness": params["stiffness_ratio"],
            "exponent": params["exponent"],
        }
        ball = {"mu": params["mu_ball"], "stiffness": 1.0, "exponent": params["exponent"]}
        contacts = [
            Contact(e=e, **(ball if name == "D" else floor))
            for name, e in zip(CONTACTS, params["e"], strict=True)
        ]
        return ImpactProblem(
            M=np.diag([mb, mb, md, md, disk_inertia(md, r, h)]),
            Wn=Wn,
            Wt=Wt,
            v=np.array([params["vb"], 0.0, 0.0, 0.0, 0.0]),
            contacts=contacts,
            bodies={"ball": (0, 1), "disk": (2, 3, 4)},
        )

    def coordinates(self, params: Params) -> list[str]:
        """Ball velocity, disk centre velocity and disk rotation rate."""
        return ["vyb [m/s]", "vzb [m/s]", "vyd [m/s]", "vzd [m/s]", "omega [rad/s]"]


CASES.register(DiskBall())


def disk_translation(trial: Any) -> float:
    """The disk's horizontal velocity after the impact over the ball's speed before it."""
    return float(trial.outcome.v_plus[2] / trial.problem.v[0])


def disk_rotation(trial: Any) -> float:
    """The disk's rotation rate after the impact times its radius, over the ball's speed."""
    return float(trial.outcome.v_plus[4] * trial.params["radius"] / trial.problem.v[0])


def ball_rebound(trial: Any) -> float:
    """The ball's horizontal velocity after the impact over its speed before it."""
    return float(trial.outcome.v_plus[0] / trial.problem.v[0])


def energy_change(trial: Any) -> float:
    """DT / T-."""
    return float((trial.outcome.T_plus - trial.outcome.T_minus) / trial.outcome.T_minus)


def primary_contacts(trial: Any) -> list[float] | None:
    """The energetic law's primary contacts in turn (0-3: A, B, C, D); None for other laws."""
    primaries = trial.outcome.diagnostics.get("primaries")
    return None if primaries is None else [float(j) for j in primaries]


def stored_energy_peaks(trial: Any) -> list[float] | None:
    """The largest energy stored at each contact A, B, C, D along the impact (J), from the path."""
    path = trial.outcome.path
    if not path or "stored_energy" not in path:
        return None
    return np.asarray(path["stored_energy"]).max(axis=0).tolist()


# The studies this scene declares, as data.
DiskBall.studies = (
    {
        "shape": "sweep",
        "name": "disk_ball",
        "title": "disk struck by a ball at height b (m) on its axis, r = 5 cm: disk translation "
        "vyd+/vb, rotation r omega+/vb, ball rebound vyb+/vb and dT/T- for every law that "
        "treats it",
        "laws": "covering",
        "grid": {"b": np.linspace(-0.045, 0.045, 7).tolist()},
        "measures": {
            "disk_translation": disk_translation,
            "disk_rotation": disk_rotation,
            "ball_rebound": ball_rebound,
            "energy_change": energy_change,
            "primary_contacts": primary_contacts,
        },
        "checks": ("energy_gain", "admissible", "friction_cone"),
        "axes": ("b", "disk_translation", "disk_rotation", "ball_rebound", "energy_change"),
        "units": dict.fromkeys(
            ("disk_translation", "disk_rotation", "ball_rebound", "energy_change"), ""
        ),
    },
    {
        "shape": "impact_paths",
        "name": "disk_ball_energies",
        "title": "disk struck low, at the centre and high (b = -4.5, 0, 4.5 cm): the stored "
        "energy per contact along the impact (contacts 0-2 the floor points A, B, C; 3 the ball "
        "D), of the energetic law (Zhang et al. 2013, its central figure) against its "
        "impulse-time variable, and of the compliant ground truth against time; the energetic "
        "law's primary contacts",
        "laws": ("lzb", "compliant"),
        "axis": "b",
        "values": [-0.045, 0.0, 0.045],
        "quantities": ("stored_energy",),
        "extra": {"stored_energy_peaks": stored_energy_peaks, "primary_contacts": primary_contacts},
    },
    {"shape": "speed_accuracy"},
)
