"""What a scene looks like, for the engines that build it: bodies, joints and contact pairs.

A scene that an engine can build declares a `Geometry` at the impact's configuration (every
contact point touching: the gaps of the problem are zero there) and attaches it to its
`ImpactProblem`. The rigid laws never read it; an engine law builds the bodies, joints and
contact pairs in its engine, sets the pre-impact state through the velocity map, steps, and
reads the state back through the map's inverse.

Conventions, in the world frame:

- A body's frame has its origin at the centre of mass and its axes along the principal axes of
  inertia; its pose is that origin's position and the unit quaternion ``(w, x, y, z)`` that
  turns the body frame into the world frame (Hamilton's convention, as MuJoCo writes it).
- Sizes are MuJoCo's: a sphere ``(radius,)``, a box its three half-extents, a capsule and a
  cylinder ``(radius, half-length)`` along the body's z axis, an ellipsoid its three
  semi-axes, a plane none: the plane through the body's position whose normal is the body's z
  axis. A plane is fixed (joint ``fixed``).
- The velocity of body k is six numbers, ``(vx, vy, vz, wx, wy, wz)``: the velocity of its
  centre of mass and its angular velocity, both in the world frame; the bodies' velocities are
  stacked in the order of ``bodies``. ``to_bodies`` (6 B, n) maps the scene's generalized
  velocity to them (the scene's kinematics at the frozen configuration) and ``to_generalized``
  (n, 6 B) reads a generalized velocity back from them: ``to_generalized @ to_bodies`` is the
  identity.
- Contact pair j is the problem's contact j: bodies ``a`` and ``b``, the contact point in the
  world, the unit normal from ``b`` into ``a`` (the gap rate is the normal component of the
  velocity of ``a``'s material point there minus ``b``'s) and the problem's tangents of that
  contact (none for a frictionless scene, one for a planar one, two for a spatial one), with the
  coefficients ``e`` and ``mu`` of the contact.

So the scene's problem is the geometry's linear algebra: ``M = B.T Mb B`` with ``B`` the map
``to_bodies`` and ``Mb`` the bodies' masses and world inertias, and the columns of ``Wn`` and
``Wt`` are ``B.T`` times the point Jacobians along the normal and the tangents
(`Geometry.mass_matrix`, `Geometry.jacobians`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem

# Shapes and the number of sizes each takes (MuJoCo's conventions).
SHAPES = {"sphere": 1, "box": 3, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "plane": 0}
# Joint kinds: a body's motion relative to the world.
JOINTS = ("free", "planar", "hinge", "slide", "fixed")
# Relative tolerance of the unit vectors, of the velocity map's inverse and joints, and of a
# problem's agreement with its geometry.
TOLERANCE = 1e-9


def _floats(label: str, value: Any, length: int | None = None) -> tuple[float, ...]:
    """``value`` as a tuple of finite floats (of ``length`` entries when given)."""
    try:
        numbers = tuple(map(float, value))
    except (TypeError, ValueError):
        raise InvalidProblem(f"{label} = {value!r}: not a list of numbers") from None
    if length is not None and len(numbers) != length:
        raise InvalidProblem(f"{label} has {len(numbers)} entries, expected {length}")
    if not all(map(math.isfinite, numbers)):
        raise InvalidProblem(f"{label} = {numbers}: must be finite numbers")
    return numbers


def _unit(label: str, value: Any, length: int = 3) -> tuple[float, ...]:
    """``value`` as a tuple of floats of norm 1 (to `TOLERANCE`)."""
    numbers = _floats(label, value, length)
    if abs(math.hypot(*numbers) - 1.0) > TOLERANCE:
        raise InvalidProblem(f"{label} = {numbers}: must have norm 1")
    return numbers


def cross(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    """The cross product of two 3-vectors (plain floats: cheaper than numpy's for one pair)."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a: Sequence[float], b: Sequence[float]) -> float:
    """The dot product of two vectors of plain floats."""
    return math.fsum(x * y for x, y in zip(a, b, strict=True))


def rotation_matrix(quaternion: Sequence[float]) -> np.ndarray:
    """The rotation matrix of a unit quaternion ``(w, x, y, z)`` (body frame to world)."""
    w, x, y, z = quaternion
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def turned(quaternion: Sequence[float], rotation: np.ndarray) -> tuple[float, ...]:
    """``quaternion`` turned further by the rotation vector ``rotation`` (world frame)."""
    angle = float(np.linalg.norm(rotation))
    if angle == 0.0:
        return tuple(quaternion)
    s = math.sin(angle / 2) / angle
    a = (math.cos(angle / 2), *(s * np.asarray(rotation)))
    b = quaternion
    product = (
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    )
    norm = math.hypot(*product)
    return tuple(c / norm for c in product)


@dataclass(frozen=True)
class Body:
    """A rigid body: its shape, mass, principal inertia and pose at the impact.

    Parameters
    ----------
    name : str
        Its name, unique in the geometry.
    shape : str
        One of `SHAPES`: sphere, box, capsule, cylinder, ellipsoid or plane.
    size : sequence of float
        The shape's sizes (module docstring), all positive.
    mass : float
        Mass (kg); positive for a body that moves, ignored for a fixed one.
    inertia : sequence of 3 floats
        Principal moments of inertia about the centre of mass (kg m^2), along the body's axes.
    position : sequence of 3 floats
        Position of the centre of mass (m).
    quaternion : sequence of 4 floats
        Unit quaternion ``(w, x, y, z)`` from the body frame to the world.

    Raises
    ------
    InvalidProblem
        Naming the body and the field, for an unknown shape or a bad number.
    """

    name: str
    shape: str
    size: tuple[float, ...]
    mass: float = 0.0
    inertia: tuple[float, float, float] = (0.0, 0.0, 0.0)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quaternion: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        label = f"body {self.name!r}"
        if self.shape not in SHAPES:
            raise InvalidProblem(
                f"{label}.shape = {self.shape!r}: must be one of {', '.join(SHAPES)}"
            )
        size = _floats(f"{label}.size", self.size, SHAPES[self.shape])
        if any(s <= 0 for s in size):
            raise InvalidProblem(f"{label}.size = {size}: must be positive")
        (mass,) = _floats(f"{label}.mass", [self.mass], 1)
        inertia = _floats(f"{label}.inertia", self.inertia, 3)
        if mass < 0 or min(inertia) < 0:
            raise InvalidProblem(f"{label}: mass {mass:g} and inertia {inertia} must be >= 0")
        for name, value in (
            ("size", size),
            ("mass", mass),
            ("inertia", inertia),
            ("position", _floats(f"{label}.position", self.position, 3)),
            ("quaternion", _unit(f"{label}.quaternion", self.quaternion, 4)),
        ):
            object.__setattr__(self, name, value)

    @property
    def rotation(self) -> np.ndarray:
        """The rotation matrix of the body's pose (body frame to world)."""
        return rotation_matrix(self.quaternion)

    @property
    def world_inertia(self) -> np.ndarray:
        """The inertia tensor about the centre of mass in world axes, ``R diag(I) R.T``."""
        R = self.rotation
        return R @ np.diag(self.inertia) @ R.T


@dataclass(frozen=True)
class Joint:
    """How a body moves relative to the world.

    Parameters
    ----------
    kind : str
        One of `JOINTS`: free (six degrees of freedom), planar (translation in the plane normal
        to ``axis``, rotation about ``axis``), hinge (rotation about ``axis`` through
        ``anchor``), slide (translation along ``axis``) or fixed.
    body : str
        The body it moves.
    axis : sequence of 3 floats
        Unit vector: the planar joint's normal, the hinge's or the slide's axis (world frame).
    anchor : sequence of 3 floats
        A point of the hinge's axis (world frame); the other kinds ignore it.
    """

    kind: str
    body: str
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    anchor: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        label = f"joint of {self.body!r}"
        if self.kind not in JOINTS:
            raise InvalidProblem(f"{label}.kind = {self.kind!r}: must be one of {JOINTS}")
        object.__setattr__(self, "axis", _unit(f"{label}.axis", self.axis))
        object.__setattr__(self, "anchor", _floats(f"{label}.anchor", self.anchor, 3))

    def motion_error(self, velocity: Sequence[float], position: Sequence[float]) -> float:
        """How far a body velocity ``(v, w)`` at ``position`` lies outside this joint's motions.

        The norm of the part of ``velocity`` the joint forbids, for a comparison with the norm
        of ``velocity`` itself.
        """
        v, w = velocity[:3], velocity[3:]
        axis = self.axis
        if self.kind == "free":
            return 0.0
        if self.kind == "fixed":
            return math.hypot(*velocity)
        if self.kind == "planar":
            return math.hypot(dot(v, axis), *cross(w, axis))
        if self.kind == "slide":
            return math.hypot(*cross(v, axis), *w)
        # hinge: the velocity of a rotation about the axis through the anchor
        arm = [p - c for p, c in zip(position, self.anchor, strict=True)]
        swept = cross(w, arm)
        return math.hypot(*cross(w, axis), *(x - y for x, y in zip(v, swept, strict=True)))


@dataclass(frozen=True)
class ContactPair:
    """Contact j of the problem, between bodies ``a`` and ``b``.

    Parameters
    ----------
    a, b : str
        The bodies; the normal points from ``b`` into ``a``.
    point : sequence of 3 floats
        The contact point at the impact (world frame).
    normal : sequence of 3 floats
        Unit normal from ``b`` into ``a``.
    tangents : sequence of 0, 1 or 2 unit vectors
        The problem's tangential directions of this contact (its columns of ``Wt``), orthogonal
        to the normal and to each other.
    e : float
        Restitution coefficient, in [0, 1].
    mu : float
        Coulomb friction coefficient, >= 0.
    """

    a: str
    b: str
    point: tuple[float, float, float]
    normal: tuple[float, float, float]
    tangents: tuple[tuple[float, float, float], ...] = ()
    e: float = 1.0
    mu: float = 0.0

    def __post_init__(self) -> None:
        label = f"pair {self.a!r}-{self.b!r}"
        if self.a == self.b:
            raise InvalidProblem(f"{label}: a body cannot touch itself")
        normal = _unit(f"{label}.normal", self.normal)
        tangents = tuple(_unit(f"{label}.tangents", t) for t in self.tangents)
        frame = (normal, *tangents)
        if len(tangents) > 2 or any(
            abs(dot(frame[i], frame[k])) > TOLERANCE for i in range(len(frame)) for k in range(i)
        ):
            raise InvalidProblem(
                f"{label}.tangents = {tangents}: at most two unit vectors, orthogonal to the "
                "normal and to each other"
            )
        (e, mu) = _floats(f"{label}.e, mu", [self.e, self.mu], 2)
        if not 0.0 <= e <= 1.0 or mu < 0.0:
            raise InvalidProblem(f"{label}: e = {e:g} must lie in [0, 1] and mu = {mu:g} >= 0")
        for name, value in (
            ("point", _floats(f"{label}.point", self.point, 3)),
            ("normal", normal),
            ("tangents", tangents),
            ("e", e),
            ("mu", mu),
        ):
            object.__setattr__(self, name, value)

    @property
    def directions(self) -> np.ndarray:
        """The normal, then the tangents, as rows (1 + d, 3)."""
        return np.array([self.normal, *self.tangents])


@dataclass(frozen=True, eq=False)
class Geometry:
    """The bodies, joints and contact pairs of a scene, and its velocity map.

    Parameters
    ----------
    bodies : sequence of Body
        Every body, fixed ones (walls, floors) included.
    joints : sequence of Joint
        Exactly one per body.
    pairs : sequence of ContactPair
        One per contact of the problem, in the problem's order; all with the same number of
        tangents.
    to_bodies : array (6 B, n)
        Generalized velocity -> the bodies' velocities (module docstring).
    to_generalized : array (n, 6 B)
        The bodies' velocities -> generalized velocity; ``to_generalized @ to_bodies = I``.

    Raises
    ------
    InvalidProblem
        Naming the field: a name given twice or unknown, a body without exactly one joint, a
        moving plane or a moving body without mass, maps of the wrong shape, maps that are not
        each other's inverse, or a map that moves a body against its joint.
    """

    bodies: tuple[Body, ...]
    joints: tuple[Joint, ...]
    pairs: tuple[ContactPair, ...]
    to_bodies: np.ndarray
    to_generalized: np.ndarray
    index: dict[str, int] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        bodies, joints, pairs = tuple(self.bodies), tuple(self.joints), tuple(self.pairs)
        index = {body.name: k for k, body in enumerate(bodies)}
        if len(index) != len(bodies):
            raise InvalidProblem("bodies: two bodies share a name")
        if not pairs:
            raise InvalidProblem("pairs is empty: a scene touches somewhere")
        for name, value in (("bodies", bodies), ("joints", joints), ("pairs", pairs)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "index", index)
        self._check_joints()
        self._check_pairs()
        self._check_maps()

    def _check_joints(self) -> None:
        moved = [joint.body for joint in self.joints]
        unknown = sorted(set(moved) - set(self.index))
        if unknown:
            raise InvalidProblem(f"joints: unknown body {unknown[0]!r}")
        for body in self.bodies:
            if moved.count(body.name) != 1:
                raise InvalidProblem(
                    f"joints: body {body.name!r} has {moved.count(body.name)} joints, expected 1"
                )
            kind = self.joint(body.name).kind
            if kind != "fixed" and (body.shape == "plane" or body.mass <= 0):
                raise InvalidProblem(
                    f"joints: body {body.name!r} moves ({kind}) and is a plane or has no mass"
                )

    def _check_pairs(self) -> None:
        for j, pair in enumerate(self.pairs):
            for body in (pair.a, pair.b):
                if body not in self.index:
                    raise InvalidProblem(f"pairs[{j}]: unknown body {body!r}")
            if not (self.moving(pair.a) or self.moving(pair.b)):
                raise InvalidProblem(f"pairs[{j}]: both bodies are fixed")
        if len({len(pair.tangents) for pair in self.pairs}) > 1:
            raise InvalidProblem("pairs: every pair has the same number of tangents")

    def _check_maps(self) -> None:
        count = 6 * len(self.bodies)
        B = _read_only("to_bodies", self.to_bodies)
        n = B.shape[1] if B.ndim == 2 else 0
        if B.shape != (count, n) or n < 1:
            raise InvalidProblem(f"to_bodies has shape {B.shape}, expected ({count}, n)")
        S = _read_only("to_generalized", self.to_generalized)
        if S.shape != (n, count):
            raise InvalidProblem(f"to_generalized has shape {S.shape}, expected ({n}, {count})")
        if np.abs(S @ B - np.eye(n)).max() > TOLERANCE * max(1.0, np.abs(S).max()):
            raise InvalidProblem("to_generalized @ to_bodies is not the identity")
        for k, body in enumerate(self.bodies):
            joint = self.joint(body.name)
            rows = B[6 * k : 6 * k + 6]
            if joint.kind == "free":
                continue
            for column in rows.T.tolist():
                scale = max(math.hypot(*column), 1.0)
                if joint.motion_error(column, body.position) > TOLERANCE * scale:
                    raise InvalidProblem(
                        f"to_bodies moves body {body.name!r} against its {joint.kind} joint"
                    )
        object.__setattr__(self, "to_bodies", B)
        object.__setattr__(self, "to_generalized", S)

    @property
    def n(self) -> int:
        """The number of generalized velocities."""
        return self.to_bodies.shape[1]

    @property
    def d(self) -> int:
        """Tangents per contact: 0 without friction, 1 planar, 2 spatial."""
        return len(self.pairs[0].tangents)

    def with_coefficients(self, e: Sequence[float], mu: Sequence[float]) -> Geometry:
        """The same geometry, its pair j of restitution ``e[j]`` and friction ``mu[j]``."""
        pairs = tuple(
            replace(pair, e=float(ej), mu=float(mj))
            for pair, ej, mj in zip(self.pairs, e, mu, strict=True)
        )
        return replace(self, pairs=pairs)

    def joint(self, body: str) -> Joint:
        """The joint of ``body``."""
        return next(joint for joint in self.joints if joint.body == body)

    def moving(self, body: str) -> bool:
        """Whether ``body`` moves (its joint is not ``fixed``)."""
        return self.joint(body).kind != "fixed"

    def body_velocities(self, v: np.ndarray) -> np.ndarray:
        """The bodies' velocities (B, 6) at generalized velocity ``v``."""
        return (self.to_bodies @ v).reshape(-1, 6)

    def generalized(self, velocities: np.ndarray) -> np.ndarray:
        """The generalized velocity read from the bodies' velocities (B, 6)."""
        return self.to_generalized @ np.ravel(velocities)

    def mass_matrix(self) -> np.ndarray:
        """``B.T Mb B``: the generalized mass matrix the bodies give (n, n)."""
        blocks = np.zeros((len(self.bodies) * 6, len(self.bodies) * 6))
        for k, body in enumerate(self.bodies):
            blocks[6 * k : 6 * k + 3, 6 * k : 6 * k + 3] = body.mass * np.eye(3)
            blocks[6 * k + 3 : 6 * k + 6, 6 * k + 3 : 6 * k + 6] = body.world_inertia
        B = self.to_bodies
        return B.T @ blocks @ B

    def point_rows(self, j: int) -> np.ndarray:
        """Rows (1 + d, 6 B): the velocity of pair j's point of ``a`` relative to ``b``'s.

        Along the normal, then the tangents: ``rows @ V`` for the stacked body velocities V.
        """
        pair = self.pairs[j]
        directions = pair.directions
        rows = np.zeros((len(directions), 6 * len(self.bodies)))
        for body, sign in ((pair.a, 1.0), (pair.b, -1.0)):
            k = self.index[body]
            arm = np.asarray(pair.point) - np.asarray(self.bodies[k].position)
            # d . (v + w x r) = d . v + w . (r x d)
            rows[:, 6 * k : 6 * k + 3] = sign * directions
            rows[:, 6 * k + 3 : 6 * k + 6] = sign * np.cross(arm, directions)
        return rows

    def jacobians(self) -> tuple[np.ndarray, np.ndarray | None]:
        """``Wn`` (n, m) and ``Wt`` (n, m d), or None without tangents, of the pairs."""
        rows = [self.point_rows(j) @ self.to_bodies for j in range(len(self.pairs))]
        Wn = np.column_stack([r[0] for r in rows])
        if self.d == 0:
            return Wn, None
        return Wn, np.column_stack([t for r in rows for t in r[1:]])

    def poses(self, displacement: np.ndarray) -> list[tuple[np.ndarray, tuple[float, ...]]]:
        """Each body's position and quaternion after a small generalized ``displacement``.

        The bodies move by ``to_bodies @ displacement``: translations exactly, rotations by
        that rotation vector (exact for a rotation about one axis, first order otherwise).
        """
        moves = self.body_velocities(displacement)
        return [
            (np.asarray(body.position) + move[:3], turned(body.quaternion, move[3:]))
            for body, move in zip(self.bodies, moves, strict=True)
        ]


def _read_only(label: str, value: Any) -> np.ndarray:
    """``value`` as a read-only array of finite floats."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidProblem(f"{label}: not an array of numbers") from None
    if not np.isfinite(array).all():
        raise InvalidProblem(f"{label}: must hold finite numbers")
    array.setflags(write=False)
    return array
