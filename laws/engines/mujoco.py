"""MuJoCo as an impact law: the scene built as an MJCF model and stepped through the impact.

Source: MuJoCo 3 (E. Todorov, T. Erez and Y. Tassa, IROS 2012; documentation
https://mujoco.readthedocs.io: Computation, "Soft contact model" and "Contact"; Modeling,
"Solver parameters" for solref and solimp and "Contact" for the pair element; XML reference,
option, pair). MuJoCo has no restitution coefficient: a contact is a soft constraint whose
reference acceleration ``aref = -b v - k r`` (r the penetration, v its rate) the solver reaches
in proportion to the impedance ``d`` in (0, 1) (solimp): solref ``(timeconst, dampratio)``
sets k and b from a time constant and a damping ratio, solref ``(-k, -b)`` sets them directly.
Friction forces lie in the cone of coefficient mu (pyramidal by default, elliptic on request);
their reference acceleration is ``-b v``, the normal direction's damping (or solreffriction's).

Conventions: the common stepping rule of the engine laws (`lawbench.laws.engines._base`), with
MuJoCo's semi-implicit Euler step; a step's contact force is the one mj_contactForce gives at
its start (contact frame: the normal from the contact's first geom to its second, then two
tangents), acting on the second geom's body, once the constraint forces are made those of the
acceleration the step integrated (its velocity change over the step): MuJoCo's solver stops at
its tolerance (XML reference, option: tolerance) with the two apart at small forces. Every
geom collides only through the scene's declared pairs (contype and conaffinity 0, one explicit
pair per two bodies), with no margin: a contact is active once the bodies overlap. Bodies: the
body frame at the centre of mass with the given mass and principal inertia (inertial element);
free joints (freejoint), planar joints (two slides in the plane and a hinge about its normal),
hinges and slides; fixed bodies are geoms of the world body. Gravity is off.

Settings (option ``settings``):

- ``default``, what a user gets: MuJoCo's defaults (timestep 0.002 s, solref (0.02, 1), solimp
  (0.9, 0.95, 0.001, 0.5, 2), pyramidal cone), each pair's sliding friction the scene's mu.
  MuJoCo has no restitution coefficient, and its documented default contact is critically
  damped: e has no effect.
- ``tuned``, as rigid and faithful to e and mu as MuJoCo allows: solref ``(-k, -b)`` with
  ``k = (2 pi / (STEPS_PER_CONTACT dt))^2``, the stiffest contact whose period the step resolves
  in `STEPS_PER_CONTACT` steps, and ``b = 2 zeta sqrt(k)``; solimp (`IMPEDANCE`, `IMPEDANCE`,
  0.001, 0.5, 2), an impedance near 1, so that the solver reaches the reference acceleration
  and each contact is the oscillator ``x'' = -b x' - k x``; an elliptic cone with
  solreffriction ``(-k, -max(b, 2 sqrt(k)))``, friction damped at least critically; timestep
  1e-5 s. The damping ratio zeta is the one whose oscillator, released where its force returns
  to zero (MuJoCo's contact force never pulls, so the contact ends there, before the gap
  reopens), leaves at ``e`` (`released_restitution`; Brogliato 2010, Kelvin-Voigt restitution
  with termination at zero force, and its overdamped branch). The relation of a gap that
  reopens, ``e = exp(-zeta pi / sqrt(1 - zeta^2))``, misses that end: a sphere striking a wall
  head-on leaves at 0.128, 0.391, 0.546 and 0.806 of its speed for e = 0, 0.3, 0.5 and 0.8
  with it, and at 0.000, 0.293, 0.495 and 0.798 with the relation used here (measured, 200 steps
  per period). An e below `LEAST_RESTITUTION` takes its damping (no finite damping reaches 0).

Measured against Moreau's law (the rigid limit these settings aim at), tuned, relative to the
largest pre-impact velocity: 5e-5 on the elastic three-ball chain and 3e-6 on the rocking
block. Friction is MuJoCo's weak point: on the sphere striking a wall at 45 degrees (e = 0.8,
mu = 0.3) the normal rebound is 4 % low with the default spin and 18 % low without spin (0.93
m/s against 1.13, the sphere rolling after the impact in Moreau's law): a friction damped
enough to stop the slip within the contact takes part of the normal rebound with it in
MuJoCo's elliptic cone, and with the normal damping alone (the pyramidal cone, or no
solreffriction) the friction of an elastic contact is too weak to stop the slip (3.6 rad/s of
spin against 10.1). The defaults give (0.25, 0.37, 0.38) on the elastic three-ball chain, a
third of its energy.
"""

from __future__ import annotations

import functools
import math
from types import ModuleType

import numpy as np
import scipy.optimize

from lawbench.checks.regions import coupled_friction, oblique_contacts, option
from lawbench.core.errors import NotApplicable
from lawbench.core.geometry import Body, ContactPair, rotation_matrix
from lawbench.core.law import LAWS
from lawbench.core.verdicts import Claim
from lawbench.laws._claims import RIGID_DISPERSION
from lawbench.laws.engines._base import (
    EngineLaw,
    Force,
    Scene,
    Start,
    damping_for,
    engine_options,
    plane_axes,
    quietly,
    require,
)
from lawbench.laws.engines._regions import (
    elastic_contact,
    moving_impact,
    normal_turned,
    overlap_given_back,
    turning_impact,
)

require("mujoco")

_DOCS = "MuJoCo documentation, https://mujoco.readthedocs.io (Computation: soft contact model)"
# Steps over one period of a tuned contact's oscillation (about half of them in contact).
STEPS_PER_CONTACT = 200
# The impedance of a tuned contact: the share of its reference acceleration the solver reaches.
IMPEDANCE = 0.9999
# The least damping of the friction of a tuned contact, over sqrt(k): critical damping.
FRICTION_DAMPING = 2.0
# A solver's residual below this fraction of the step's constraint force is rounding: not read.
ROUNDING = 1e-12


@functools.cache
def _mujoco() -> ModuleType:
    """The mujoco module, imported on first use."""
    return quietly("mujoco")


def released_restitution(zeta: float) -> float:
    """The restitution of a damped oscillator released where its force returns to zero.

    The contact ``x'' = -b x' - k x`` with damping ratio ``zeta = b / (2 sqrt(k))`` pushes while
    ``b x' + k x > 0`` and lets go where that force vanishes, before the gap reopens. Below
    critical damping (Brogliato 2010, Kelvin-Voigt restitution with termination at zero
    force) ``e = exp(-2 zeta arccos(zeta) / sqrt(1 - zeta^2))``; at zeta = 1 its limit
    ``exp(-2)``; above, with ``rho = s1 / s2`` the ratio of the two decay rates
    ``s = zeta -+ sqrt(zeta^2 - 1)``, the force vanishes at ``t = 2 ln(1 / rho) / (s2 - s1)``
    and the exit speed is ``e = rho^((1 + rho) / (1 - rho))``, which tends to 0 as zeta grows.
    """
    if zeta < 1.0:
        return math.exp(-2.0 * zeta * math.acos(zeta) / math.sqrt(1.0 - zeta * zeta))
    if zeta == 1.0:
        return math.exp(-2.0)
    root = math.sqrt(zeta * zeta - 1.0)
    rho = (zeta - root) / (zeta + root)
    return rho ** ((1.0 + rho) / (1.0 - rho))


def damping_ratio(e: float) -> float:
    """The damping ratio whose contact, released at zero force, leaves at restitution ``e``."""
    return damping_for(e, released_restitution, 1e6)


class MuJoCo(EngineLaw):
    """MuJoCo: the scene stepped with MuJoCo's soft contacts."""

    name = "mujoco"
    summary = (
        "MuJoCo: the scene's bodies stepped through the impact with MuJoCo's soft contacts, at "
        "its defaults or tuned stiff, e mapped to the contact's damping"
    )
    source = f"MuJoCo 3 (Todorov, Erez and Tassa, IROS 2012); {_DOCS}"
    steps = {"default": 0.002, "tuned": 1e-5}
    settings_words = {
        "default": "MuJoCo at its defaults (solref 0.02, 1; e has no effect)",
        "tuned": "MuJoCo tuned (solref -k, -b from e, impedance near 1, elliptic cone)",
    }
    separating_rule = (
        "MuJoCo's own: a contact acts while its bodies overlap, so a separating contact takes "
        "a force only where its neighbours push it back into overlap"
    )
    options = engine_options(
        steps,
        "MuJoCo's defaults, timestep 0.002 s, solref (0.02, 1), solimp (0.9, 0.95, 0.001, "
        "0.5, 2), pyramidal cone, each pair's sliding friction mu; e has no effect",
        f"solref (-k, -b) with k = (2 pi / ({STEPS_PER_CONTACT} dt))^2 and b from e (a damped "
        f"oscillator released at zero force), solimp ({IMPEDANCE}, {IMPEDANCE}, 0.001, 0.5, "
        "2), elliptic cone with solreffriction (-k, -max(b, 2 sqrt(k))), timestep 1e-5 s",
    )
    findings = (
        RIGID_DISPERSION,
        overlap_given_back(
            _DOCS, "the lamina approaching at 1e-10 m/s gains 3.2e-18 J where it brought 5e-21 J"
        ),
        Claim(
            "energy_gain",
            coupled_friction,
            f"{_DOCS}: a reference acceleration per constraint row; Todorov 2014, "
            "analytically-invertible dynamics with contacts and constraints",
            "MuJoCo's contact force derives from no potential and no dissipation: each row of a "
            "contact, normal and frictional, has a reference acceleration (the normal one a "
            "damped spring), and the solver finds the forces in the cone that best meet "
            "them together. Where inertia couples a contact's normal and tangential rows, the "
            "friction's force feeds the normal row's spring and the normal impulse grows with "
            "friction: the lamina of the example 'slip reversal, lively' (one coordinate for "
            "both rows, e = 0.9, mu = 0.3) takes Pn = 2.93 against 1.90 without friction and "
            "leaves with 1.84 times its energy tuned, the same at dt = 1e-6 s; the rod of the "
            "example 'energy gain' with 1.07 times; at the defaults the billiard shot at mu = 1 "
            "with 1.42 times",
        ),
        Claim(
            "admissible",
            option("settings", "default") & moving_impact,
            f"{_DOCS}; Modeling: solver parameters (solref default 0.02, 1)",
            "at its defaults a contact's time constant is 20 ms: the impact lasts long enough "
            "for the bodies to leave the configuration the problem is frozen at, and a contact "
            "the engine no longer meets is left approaching along its frozen normal (the "
            "billiard shot lasts 26 ms, the ball slides 26 mm out from under the tip and the "
            "cue passes it: un+ = -0.79 m/s)",
            (("billiard", "default"),),
        ),
        normal_turned(
            f"{_DOCS}; Modeling: solver parameters (solref default 0.02, 1)",
            "the billiard shot at mu = 0 takes |Pt| = 0.059 N s",
        ),
        Claim(
            "admissible",
            option("settings", "default") & turning_impact,
            f"{_DOCS}; Modeling: solver parameters (solref default 0.02, 1)",
            "at its defaults a contact is soft and the impact lasts tens of steps, while the "
            "bodies turn: MuJoCo applies each step's force at the contact's arm of that step, "
            "the problem's Jacobian at the frozen configuration, so the gap rate read there is "
            "off by up to |omega|^2 r T (the rocking block of width and height 1 m landing at "
            "1 rad/s with e = 0: 56 ms, the pivot left approaching at -2.2e-3 m/s where "
            "MuJoCo's own velocity separates it at +4.5e-4, which the forces at their own arms "
            "give exactly)",
        ),
        Claim(
            "continuity",
            oblique_contacts,
            f"{_DOCS}; Brogliato 2010, kinetic angle and continuity",
            "a contact acts from the first step that finds its bodies overlapping: a gap that "
            "closes within a step starts its contact a step later than a contact closed from "
            "the start, and where the contacts share the impact (a kinetic angle other than 90 "
            "degrees) the outcome moves by what that step changes (2 % on the three-ball chain "
            "at both settings)",
            (("three_ball_chain", "default"),),
        ),
        Claim(
            "energy_kept",
            option("settings", "default"),
            f"{_DOCS}; Modeling: solver parameters (solref default 0.02, 1)",
            "at its defaults a contact is critically damped whatever e: the elastic three-ball "
            "chain keeps 34 % of its energy, v+ = (0.25, 0.37, 0.38)",
            (("three_ball_chain", "default"),),
        ),
        *(
            Claim(
                check,
                option("settings", "tuned") & elastic_contact,
                f"{_DOCS}; Brogliato 2010, Kelvin-Voigt restitution",
                "tuned, an elastic contact is an undamped spring stepped by semi-implicit Euler "
                f"at {STEPS_PER_CONTACT} steps per period, and released at a step's end: the "
                "bodies leave with up to 2e-4 of the energy more or less than they brought",
            )
            for check in ("energy_gain", "energy_kept")
        ),
    )

    def _open(self, start: Start) -> Scene:
        return _MuJoCoScene(start)


def _numbers(values: object) -> str:
    """Numbers as an MJCF attribute value."""
    return " ".join(f"{float(x):.17g}" for x in np.ravel(values))


def _joints(kind: str, axis: np.ndarray, anchor: np.ndarray, centre: np.ndarray) -> list[tuple]:
    """A body's MJCF joints as (type, world axis, world anchor); a free joint is one.

    A planar joint is two slides along orthogonal directions of its plane and a hinge about
    its normal through the centre of mass ``centre``.
    """
    if kind == "free":
        return [("free", None, centre)]
    if kind == "planar":
        first, second = plane_axes(axis)
        return [("slide", first, centre), ("slide", second, centre), ("hinge", axis, centre)]
    return [(kind, axis, anchor)]


class _MuJoCoScene(Scene):
    """The geometry as an MJCF model, with its data at the pre-impact state."""

    def __init__(self, start: Start) -> None:
        geometry, poses = start.geometry, start.poses
        self.mujoco, self.geometry, self.dt, self.reach = _mujoco(), geometry, start.dt, start.reach
        # Each body's joints (none for a fixed body) and rotation at its pose.
        self.joints: list[list[tuple]] = []
        self.rotations = [rotation_matrix(quaternion) for _, quaternion in poses]
        try:
            self.model = self.mujoco.MjModel.from_xml_string(self._model(poses, start.tuned))
        except ValueError as exc:
            raise NotApplicable(f"mujoco: the scene's model does not compile ({exc})") from None
        self.data = self.mujoco.MjData(self.model)
        names = [body.name for body in geometry.bodies]
        self.owner = {self.model.geom(f"g{k}").id: name for k, name in enumerate(names)}
        self.ids = [self.model.body(f"b{k}").id if j else None for k, j in enumerate(self.joints)]
        geoms = {name: geom for geom, name in self.owner.items()}
        self.pair_geoms = [(geoms[pair.a], geoms[pair.b]) for pair in geometry.pairs]
        self._set_velocities(start.velocities)
        self.mujoco.mj_kinematics(self.model, self.data)
        self.force, self.velocity = np.zeros(6), np.zeros(6)

    def _model(self, poses: list[tuple[np.ndarray, tuple[float, ...]]], tuned: bool) -> str:
        """The MJCF text of the scene: fixed bodies are geoms of the world body."""
        elements = []
        for k, body in enumerate(self.geometry.bodies):
            position, quaternion = poses[k]
            joint = self.geometry.joint(body.name)
            place = f'pos="{_numbers(position)}" quat="{_numbers(quaternion)}"'
            if joint.kind == "fixed":
                elements.append(self._geom(k, body, place))
                self.joints.append([])
                continue
            R = self.rotations[k]
            axis, anchor = np.asarray(joint.axis), np.asarray(joint.anchor)
            joints = _joints(joint.kind, axis, anchor, np.asarray(position))
            self.joints.append(joints)
            inner = [
                "<freejoint/>"
                if kind == "free"
                else f'<joint type="{kind}" axis="{_numbers(R.T @ along)}" '
                f'pos="{_numbers(R.T @ (through - position))}"/>'
                for kind, along, through in joints
            ]
            inner.append(
                f'<inertial pos="0 0 0" mass="{body.mass!r}" '
                f'diaginertia="{_numbers(body.inertia)}"/>'
            )
            inner.append(self._geom(k, body, ""))
            elements.append(f'<body name="b{k}" {place}>{"".join(inner)}</body>')
        option = f'timestep="{self.dt!r}" gravity="0 0 0"'
        if tuned:
            option += ' cone="elliptic"'
        return (
            f'<mujoco model="lawbench"><option {option}/><worldbody>{"".join(elements)}'
            f"</worldbody><contact>{''.join(self._pairs(tuned))}</contact></mujoco>"
        )

    @staticmethod
    def _geom(k: int, body: Body, place: str) -> str:
        """The body's geom, colliding only through the declared pairs."""
        size = "0 0 1" if body.shape == "plane" else _numbers(body.size)
        return (
            f'<geom name="g{k}" type="{body.shape}" size="{size}" {place} contype="0" '
            'conaffinity="0"/>'
        )

    def _pairs(self, tuned: bool) -> list[str]:
        """One pair element per two bodies that touch, with their coefficients.

        Raises
        ------
        NotApplicable
            When two bodies touch at points of different coefficients: MuJoCo sets them per
            pair of geoms.
        """
        index, elements, seen = self.geometry.index, [], {}
        for pair in self.geometry.pairs:
            key = frozenset((pair.a, pair.b))
            if key in seen:
                if (seen[key].e, seen[key].mu) != (pair.e, pair.mu):
                    raise NotApplicable(
                        f"mujoco: {pair.a!r} and {pair.b!r} touch at points of different "
                        "coefficients, and MuJoCo sets them per pair of geoms"
                    )
                continue
            seen[key] = pair
            a, b = index[pair.a], index[pair.b]
            coefficients = self._coefficients(pair, tuned)
            elements.append(f'<pair geom1="g{a}" geom2="g{b}" {coefficients}/>')
        return elements

    def _coefficients(self, pair: ContactPair, tuned: bool) -> str:
        """A pair's condim, friction and, tuned, solref, solimp and solreffriction."""
        condim = 3 if pair.mu > 0 else 1
        text = f'condim="{condim}" friction="{pair.mu!r} {pair.mu!r} 0.005 0.0001 0.0001"'
        if not tuned:
            return text
        k = (2 * math.pi / (STEPS_PER_CONTACT * self.dt)) ** 2
        b = 2 * damping_ratio(pair.e) * math.sqrt(k)
        friction = max(b, FRICTION_DAMPING * math.sqrt(k))
        impedance = f"{IMPEDANCE!r} {IMPEDANCE!r} 0.001 0.5 2"
        return (
            f'{text} solref="{-k!r} {-b!r}" solimp="{impedance}" '
            f'solreffriction="{-k!r} {-friction!r}"'
        )

    def _set_velocities(self, velocities: np.ndarray) -> None:
        """The joints' velocities that give each body its velocity (B, 6).

        A free joint takes the centre's velocity in the world frame and the angular velocity in
        the body's; a slide the velocity along its axis, a hinge the angular velocity about it.
        """
        qvel, address = self.data.qvel, 0
        for k, joints in enumerate(self.joints):
            v, w = velocities[k][:3], velocities[k][3:]
            for kind, axis, _ in joints:
                if kind == "free":
                    qvel[address : address + 6] = np.concatenate([v, self.rotations[k].T @ w])
                    address += 6
                else:
                    qvel[address] = (v if kind == "slide" else w) @ axis
                    address += 1

    def step(self) -> tuple[list[Force], np.ndarray]:
        """One mj_step: the forces of its contacts, and the bodies' velocities.

        The velocities are mj_objectVelocity's, from the body velocities (cvel) mj_step computed
        before integrating: those the step started from. The stepping rule keeps them once
        steps without force have passed (`lawbench.laws.engines._base.QUIET_STEPS`), where they
        are the same.
        """
        mujoco, model, data = self.mujoco, self.model, self.data
        mujoco.mj_step(model, data)
        self._balance()
        forces = []
        for i in range(data.ncon):
            contact = data.contact[i]
            mujoco.mj_contactForce(model, data, i, self.force)
            on_second = contact.frame.reshape(3, 3).T @ self.force[:3]
            first, second = (self.owner[int(g)] for g in contact.geom)
            forces.append(Force(second, first, np.array(contact.pos), on_second))
        velocities = np.zeros((len(self.ids), 6))
        for k, body in enumerate(self.ids):
            if body is not None:
                mujoco.mj_objectVelocity(
                    model, data, mujoco.mjtObj.mjOBJ_BODY, body, self.velocity, 0
                )
                velocities[k] = np.concatenate([self.velocity[3:], self.velocity[:3]])
        return forces, velocities

    def _balance(self) -> None:
        """Make the step's constraint forces those that give the acceleration MuJoCo integrated.

        MuJoCo's solver stops once an iteration improves its cost by less than its tolerance
        (option tolerance, 1e-8 by default): at small forces (a grazing approach, the tail of a
        soft contact) it stops after one iteration where the constraint force it reports,
        ``J^T efc_force``, falls short of ``M qacc - qfrc_smooth`` by up to the force itself,
        and the bodies move by qacc. The correction of the constraint forces that closes that
        residual in least squares, each row that cannot pull (`_pushing`) kept from pulling, is
        added to efc_force (and qfrc_constraint), so that the contact forces read from them
        (mj_contactForce) carry the momentum the step applied, within the cone.
        """
        mujoco, model, data = self.mujoco, self.model, self.data
        if not data.nefc:
            return
        residual = np.zeros(model.nv)
        mujoco.mj_mulM(model, data, residual, data.qacc)
        residual -= data.qfrc_smooth + data.qfrc_constraint
        if np.abs(residual).max() <= ROUNDING * np.abs(data.qfrc_constraint).max():
            return
        if mujoco.mj_isSparse(model):
            J = np.zeros((data.nefc, model.nv))
            mujoco.mju_sparse2dense(
                J, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind
            )
        else:
            J = data.efc_J.reshape(data.nefc, model.nv)
        lower = np.where(self._pushing(), -data.efc_force, -np.inf)
        bounds = (lower, np.full(data.nefc, np.inf))
        correction = scipy.optimize.lsq_linear(J.T, residual, bounds, method="bvls").x
        data.efc_force[:] += correction
        data.qfrc_constraint[:] += J.T @ correction

    def _pushing(self) -> np.ndarray:
        """Which constraint rows push only.

        Every row of a frictionless or pyramidal contact (the normal, or an edge of the
        pyramid), and the first (normal) row of an elliptic one.
        """
        data, kinds = self.data, self.mujoco.mjtConstraint
        pushing = data.efc_type != kinds.mjCNSTR_CONTACT_ELLIPTIC
        for contact in data.contact[: data.ncon]:
            pushing[contact.efc_address] = True
        return pushing

    def distances(self) -> np.ndarray:
        """mj_geomDistance of each pair's geoms, at the positions the last step started from.

        MuJoCo gives the smallest distance of two geoms: pairs of the same two bodies share it.
        """
        model, data, reach = self.model, self.data, self.reach
        distance = self.mujoco.mj_geomDistance
        return np.array([distance(model, data, a, b, reach, None) for a, b in self.pair_geoms])

    def close(self) -> None:
        """Nothing to free: the model and its data go with the scene."""


LAWS.register(MuJoCo())
