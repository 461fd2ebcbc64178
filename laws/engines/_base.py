"""What the engine laws share: the stepping rule, from the scene's geometry to an `Outcome`.

An engine law builds the scene's `Geometry` in its engine once per problem, places the bodies
(at the geometry's poses, moved apart by the problem's gaps, the closed contacts overlapping by
`OVERLAP` of the smallest body so that the engine finds them), sets the pre-impact velocity, and
steps with step ``dt`` until the impact is over: no contact force for `QUIET_STEPS` steps in a
row and no pair approaching, within ``max_steps`` steps (the solve's `Budget`). A pair
approaches when the engine's own distance between its bodies shrank over the last step
(`Scene.distances`): at the configuration the bodies have reached, not at the impact's, so that a
soft contact that lets go while its bodies still overlap, and turn away from each other, ends
the impact. Gravity and every force but the contacts' are off during the impact.

At each step the engine reports its contact forces (`Scene.step`); each is mapped onto the
problem's contact whose pair it joins (the nearest declared point where two bodies touch at
several points), projected on that contact's normal and tangents, and integrated over the step:
``P_j += dt f . (n_j, t_j)``. The outcome is `Outcome.from_impulses` of those impulses, so its
velocity, impulses and energies agree with each other as every law's must; the engine's own
velocity at the end, read back through the geometry's map, is kept in the diagnostics
(``engine_v_plus``) with its distance from the outcome's in the kinetic metric
(``engine_velocity_gap``, relative to the pre-impact velocity): it measures what the projection
leaves out (a force off the problem's directions, a body leaving the plane it should keep to).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any, ClassVar

import numpy as np
import scipy.optimize

from lawbench.core.errors import SolverFailure
from lawbench.core.geometry import TOLERANCE, Body, ContactPair, Geometry
from lawbench.core.guards import current_budget, held
from lawbench.core.law import Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.laws._options import bound

# Steps in a row without contact force that end an impact (with no contact approaching).
QUIET_STEPS = 5
# A step's impulse below this fraction of the impact's impulse scale counts as no force.
QUIET = 1e-9
# A pair closing slower than this fraction of the fastest pre-impact approach is at rest.
APPROACH = 1e-6
# Closed contacts start this far into each other, relative to the smallest body: an engine finds
# a contact once its bodies touch or overlap, and bodies placed touching are apart by rounding
# as often as not (Bullet's sphere-sphere test then finds no contact at all).
OVERLAP = 1e-9
# The radius of the small spheres a box touches through where an engine builds it so, over the
# box's smallest half-extent.
CORNER_RADIUS = 1e-3
# The install command of the engines.
INSTALL = "pip install 'lawbench[engines]'"


def require(module: str) -> None:
    """Raise `ModuleNotFoundError` naming the install command unless ``module`` is installed.

    The module is found, not imported: an engine is imported on its first solve, so listing
    the laws stays cheap.
    """
    if module in sys.modules:
        found = sys.modules[module] is not None  # None: its import is blocked
    else:
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):
            found = False
    if not found:
        raise ModuleNotFoundError(
            f"No module named {module!r}; install it with {INSTALL}", name=module
        )


def whole(module: str) -> ModuleType:
    """Import ``module`` in one piece: a time bound that rings meanwhile rings as it ends.

    An engine's compiled bindings stopped half-way through their import fail every later import
    in the process ("already registered"), so a first solve's bound must not cut it
    (`lawbench.core.guards.held`).
    """
    with held():
        return importlib.import_module(module)


def quietly(module: str) -> ModuleType:
    """Import ``module`` `whole`, with the process's stderr (descriptor 2) closed to its writes.

    pybullet writes its build time there from C when imported, which would mix with lawbench's
    own messages on stderr.
    """
    sys.stderr.flush()
    try:
        saved = os.dup(2)
    except OSError:  # no stderr to keep clean
        return whole(module)
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        return whole(module)
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


@dataclass(frozen=True)
class Force:
    """One contact force an engine reports for one step.

    Attributes
    ----------
    first, second : str
        The geometry's names of the two bodies.
    point : array (3,)
        Where it acts (world frame).
    force : array (3,)
        The force on ``first`` (world frame, N), constant over the step.
    """

    first: str
    second: str
    point: np.ndarray
    force: np.ndarray


@dataclass(frozen=True)
class Start:
    """What an engine builds a scene from: the geometry placed at the impact, and how to step.

    Attributes
    ----------
    problem : ImpactProblem
        The impact: its geometry (bodies, joints, contact pairs) and its contacts, which carry
        what the geometry does not (their stiffness).
    poses : list of (array (3,), tuple of 4 floats)
        Each body's position and orientation quaternion (w, x, y, z), the gaps applied.
    velocities : array (B, 6)
        Each body's pre-impact velocity: centre of mass, then angular (world frame).
    settings : str
        'default' or 'tuned'.
    dt : float
        The engine's step (s).
    reach : float
        Distance beyond which a pair is not part of the impact (`Scene.distances`).
    """

    problem: ImpactProblem
    poses: list[tuple[np.ndarray, tuple[float, ...]]]
    velocities: np.ndarray
    settings: str
    dt: float
    reach: float

    @property
    def geometry(self) -> Geometry:
        """The scene's bodies, joints and contact pairs."""
        return self.problem.geometry

    @property
    def tuned(self) -> bool:
        """Whether the engine is set as rigid and faithful to e and mu as it allows."""
        return self.settings == "tuned"


class Scene(ABC):
    """A scene built in an engine, its bodies placed and moving at their pre-impact velocity."""

    @abstractmethod
    def step(self) -> tuple[list[Force], np.ndarray]:
        """Advance one step.

        Returns the contact forces of the step, and the bodies' velocities (B, 6) after it
        (centre of mass and angular velocity, world frame, in the geometry's order).
        """

    @abstractmethod
    def distances(self) -> np.ndarray:
        """The engine's signed distance of each pair's bodies near its point (m,).

        At most the scene's reach (`Start.reach`): farther, a pair is not part of the
        impact.
        """

    @abstractmethod
    def close(self) -> None:
        """Free what the engine holds."""


def engine_options(steps: dict[str, float], default: str, tuned: str) -> tuple[Spec, ...]:
    """The options of an engine law: ``settings``, ``dt`` and ``max_steps``.

    ``steps`` are the settings' own steps; ``default`` and ``tuned`` say what each setting is.
    """
    own = ", ".join(f"{name} {step:g} s" for name, step in steps.items())
    return (
        Spec(
            "settings",
            "default",
            f"default: {default}; tuned: {tuned}",
            kind="str",
            choices=("default", "tuned"),
        ),
        Spec(
            "dt",
            0.0,
            f"the engine's step, the accuracy knob; 0 takes the settings' own: {own}",
            unit="s",
            low=0.0,
            high=0.01,
        ),
        bound("max_steps", 100_000, "bound on the engine's steps"),
    )


class EngineLaw(Law):
    """A rigid-body engine as an impact law: the scene built in it and stepped through.

    A subclass names its engine's settings and builds its `Scene` (`_open`).
    """

    # The finest step: 10 us. At 10 us and 1 us MuJoCo's answers on the three-ball chain and the
    # rocking block agree to 1e-4 (0.7 s a solve against 6 to 9 s), Bullet's to 1e-4, Drake's
    # discrete solver's to about 1e-2.
    tags = Tags(
        friction=True, several_contacts=True, spatial=True, accuracy_knob="dt", finest_knob=1e-5
    )
    engine = True
    # The engine resolves time itself: it receives the gaps and moves the bodies apart by them.
    follows_gaps = True
    # The engine reads lengths, times and its settings in SI units.
    scale_free = False
    fitted = ("e", "mu")
    # The step of each setting when ``dt`` is 0.
    steps: ClassVar[dict[str, float]]
    # The contact force law's name in the diagnostics, per setting.
    settings_words: ClassVar[dict[str, str]]

    def refusal(self, problem: ImpactProblem) -> str | None:
        """Why the engine cannot build ``problem``: no geometry, or not the problem's own.

        A batch of problems carries none.
        """
        if getattr(problem, "geometry", None) is None:
            return "the scene declares no geometry"
        mismatch = geometry_mismatch(problem.geometry, problem)
        if mismatch:
            return f"{mismatch}: the problem was changed after its scene built it"
        return super().refusal(problem)

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        geometry = problem.geometry
        settings = options["settings"]
        dt = options["dt"] or self.steps[settings]
        poses = geometry.poses(_displacement(problem, geometry))
        velocities = geometry.body_velocities(problem.v)
        # Pairs farther apart than the largest gap and body cannot close within the impact.
        reach = float(problem.gaps.max()) + max(max(b.size, default=0.0) for b in geometry.bodies)
        scene = self._open(Start(problem, poses, velocities, settings, dt, reach))
        try:
            P, steps, engine_v = _step_through(scene, problem, geometry, dt)
        finally:
            scene.close()
        d = problem.d
        outcome = Outcome.from_impulses(problem, P[:, 0], P[:, 1:].ravel() if d else None)
        gap = problem.kinetic_energy(engine_v - outcome.v_plus) / max(problem.T_minus, 1e-300)
        outcome.diagnostics.update(
            formulation=f"{self.settings_words[settings]}, stepped at dt = {dt:g} s",
            steps=steps,
            dt=dt,
            impact_time=steps * dt,
            engine_v_plus=engine_v.tolist(),
            engine_velocity_gap=float(np.sqrt(gap)),
        )
        return outcome

    @abstractmethod
    def _open(self, start: Start) -> Scene:
        """Build the scene in the engine at ``start``'s poses, moving at its velocities.

        Raises
        ------
        NotApplicable
            For a shape, joint or set of coefficients the engine cannot build.
        """


# The least restitution an engine's damping is given: e = 0 needs an infinite damping.
LEAST_RESTITUTION = 1e-3


def damping_for(e: float, released: Callable[[float], float], high: float) -> float:
    """The damping parameter in ``[0, high]`` whose contact ``released`` leaves at ``e``.

    ``released`` maps the parameter to the restitution of one contact released at zero force
    (decreasing from 1 at 0). An ``e`` below `LEAST_RESTITUTION` (0 included, which no finite
    damping reaches) is given that of `LEAST_RESTITUTION`.
    """
    if e >= 1.0:
        return 0.0
    target = max(e, LEAST_RESTITUTION)
    return scipy.optimize.brentq(lambda x: released(x) - target, 0.0, high, xtol=1e-14)


def plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors of the plane normal to ``normal``, ``(first, second, normal)`` direct."""
    first = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(first) < 0.5:
        first = np.cross(normal, [0.0, 1.0, 0.0])
    first /= np.linalg.norm(first)
    return first, np.cross(normal, first)


def corner(body: Body, pair: ContactPair) -> tuple[float, np.ndarray]:
    """Radius and centre (body frame) of a small sphere of ``body`` touching at ``pair``'s point.

    It touches there along the pair's normal; its radius is `CORNER_RADIUS` of the body's
    smallest size.
    """
    radius = CORNER_RADIUS * min(body.size)
    inward = np.asarray(pair.normal) * (1.0 if body.name == pair.a else -1.0)
    centre = np.asarray(pair.point) + radius * inward - np.asarray(body.position)
    return radius, body.rotation.T @ centre


def geometry_mismatch(geometry: Geometry, problem: ImpactProblem) -> str | None:
    """Why ``problem`` is not ``geometry``'s (None when it is).

    Its M, Wn and Wt must be the geometry's (`Geometry.mass_matrix`, `Geometry.jacobians`) to
    the geometry's tolerance relative to their largest entries, and its contacts' ``e``
    (Newton's, the kinematic coefficient) and ``mu`` the pairs'. A problem changed after its
    scene built it (other units, a duplicated contact, other coefficients) no longer is.
    """
    if problem.n != geometry.n or problem.m != len(geometry.pairs):
        return (
            f"the problem has {problem.n} coordinates and {problem.m} contacts, its geometry "
            f"{geometry.n} and {len(geometry.pairs)}"
        )
    Wn, Wt = geometry.jacobians()
    if (problem.Wt is None) != (Wt is None):
        return "the problem's tangential Jacobian and its geometry's tangents disagree"
    given = {"M": problem.M, "Wn": problem.Wn, "Wt": problem.Wt}
    for name, mine in (("M", geometry.mass_matrix()), ("Wn", Wn), ("Wt", Wt)):
        if mine is None:
            continue
        theirs = np.asarray(given[name].toarray() if problem.sparse else given[name])
        if np.abs(theirs - mine).max() > TOLERANCE * np.abs(mine).max():
            return f"the problem's {name} is not its geometry's"
    e, mu = problem.restitution("kinematic"), problem.mu
    for j, pair in enumerate(geometry.pairs):
        if abs(e[j] - pair.e) > TOLERANCE or abs(mu[j] - pair.mu) > TOLERANCE:
            return f"contact {j}'s coefficients are not its geometry's pair {j}'s"
    return None


def _displacement(problem: ImpactProblem, geometry: Geometry) -> np.ndarray:
    """The generalized displacement that opens the problem's gaps, ``Wn.T dq = gaps``.

    A closed contact's gap is taken as `OVERLAP` times the smallest body size below zero, so
    that the engine finds it at the first step. The least displacement in the kinetic metric,
    ``dq = M^-1 Wn G^-1 gaps`` (least squares where the contacts are dependent).
    """
    length = min(min(body.size) for body in geometry.bodies if body.size)
    gaps = np.where(problem.closed, -OVERLAP * length, problem.gaps)
    G = np.asarray(problem.delassus)
    x = np.linalg.lstsq(G, gaps, rcond=None)[0]
    return problem.solve_mass(problem.Wn @ x)


def _step_through(
    scene: Scene, problem: ImpactProblem, geometry: Geometry, dt: float
) -> tuple[np.ndarray, int, np.ndarray]:
    """Step ``scene`` to the end of the impact: impulses (m, 1 + d), steps, engine velocity.

    Raises
    ------
    BudgetExceeded
        After ``max_steps`` steps (or ``max_seconds``) with the impact still going on.
    """
    directions = [pair.directions for pair in geometry.pairs]
    un = np.abs(problem.un)
    speed = float(un.max()) or float(np.abs(problem.v).max()) or 1.0
    # The impulse that stops the fastest contact alone: the scale of the impact's impulses.
    scale = float((un / np.diag(np.asarray(problem.delassus))).max()) or 1.0
    P = np.zeros((problem.m, 1 + problem.d))
    budget, quiet, steps, distances = current_budget(), 0, 0, scene.distances()
    while True:
        budget.step("engine steps", f"{quiet} quiet steps, at t = {steps * dt:.3g} s")
        forces, velocities = scene.step()
        steps += 1
        impulse = np.zeros_like(P)
        for force in forces:
            j, sign = pair_of(geometry, force)
            impulse[j] += sign * dt * (directions[j] @ force.force)
        P += impulse
        quiet = quiet + 1 if np.abs(impulse).max(initial=0.0) <= QUIET * scale else 0
        previous, distances = distances, scene.distances()
        closing = float((previous - distances).max(initial=0.0)) / dt
        if quiet >= QUIET_STEPS and closing <= APPROACH * speed:
            return P, steps, geometry.generalized(velocities)


def pair_of(geometry: Geometry, force: Force) -> tuple[int, float]:
    """The pair a reported force belongs to, and +1 or -1 for a force on its ``a`` or ``b``.

    Among the pairs of the force's two bodies, the one whose declared point is nearest.
    """
    best, sign, distance = -1, 0.0, np.inf
    for j, pair in enumerate(geometry.pairs):
        if {pair.a, pair.b} != {force.first, force.second}:
            continue
        gap = float(np.linalg.norm(np.asarray(pair.point) - force.point))
        if gap < distance:
            best, sign, distance = j, (1.0 if pair.a == force.first else -1.0), gap
    if best < 0:
        raise SolverFailure(
            f"the engine reports a contact between {force.first!r} and {force.second!r}, "
            "which the geometry declares no pair of"
        )
    return best, sign
