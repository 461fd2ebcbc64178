"""What the chain scenes share: the problem of a chain, its parameters, two-contact chains.

Coordinates are the ball velocities along the line. A contact is a pair ``(left, right)`` of
ball indices, the right ball being on the positive side of the left one, so the gap rate is
``v[right] - v[left]``; ``None`` in place of a ball is a fixed wall.

This module builds the problems of every chain scene, with the geometry an engine builds of
them (`chain_geometry`: balls on free joints along x, walls as fixed planes), and the specs of
their parameters, and
holds the references of free chains, the ground truth of every chain scene (compliant
integration at the scene's stiffnesses) and the studies the chain scenes declare alike (as
data, `lawbench.studies.declared`), each run with every contact elastic and with every contact
plastic.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from lawbench.cases._geometry import geometry, plane, solid_sphere
from lawbench.checks.knobs import decades
from lawbench.core.case import Case, GroundTruth, Reference, exactly, per_item
from lawbench.core.geometry import ContactPair, Geometry, Joint
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec

Pair = tuple[int | None, int | None]
# Beyond this many contacts a chain's M and Wn are scipy.sparse: dense n x n storage and
# products would dominate its cost, and Moreau's law solves it sparse end to end.
SPARSE_CONTACTS = 256
# The longest chain that declares its geometry: an engine steps every ball, and the velocity
# map is dense (6 n x n).
GEOMETRY_BALLS = 64
# The radius of the balls of a chain scene that states none (m): the rigid laws' outcome does
# not depend on it.
BALL_RADIUS = 0.1


def chain_problem(
    masses: Sequence[float],
    velocities: Sequence[float],
    pairs: Sequence[Pair],
    restitution: Sequence[float],
    stiffness: Sequence[float],
    exponents: Sequence[float],
    gaps: Sequence[float] | None = None,
    radius: float | None = None,
) -> ImpactProblem:
    """Return the impact problem of balls on a line touching along ``pairs``.

    Parameters
    ----------
    masses, velocities : sequences of one float per ball
        Ball masses (kg) and velocities (m/s, positive to the right).
    pairs : sequence of m (left, right) pairs
        Ball indices, or None for a fixed wall on that side.
    restitution, stiffness, exponents : sequences of m floats
        Restitution coefficient, stiffness and force-indentation exponent of each contact.
    gaps : sequence of m floats, optional
        Initial gaps (m); zero by default.
    radius : float, optional
        The balls' radius (m) in the geometry an engine builds (`chain_geometry`); None
        declares no geometry.
    """
    M, Wn = _mass_and_normals(np.asarray(masses, dtype=float), pairs)
    springs = list(zip(restitution, stiffness, exponents, strict=True))
    # Contacts of equal coefficients share one (immutable) contact, built and checked once.
    shared = {
        spring: Contact(e=spring[0], stiffness=spring[1], exponent=spring[2])
        for spring in set(springs)
    }
    contacts = [shared[spring] for spring in springs]
    return ImpactProblem(
        M=M,
        Wn=Wn,
        v=np.asarray(velocities, dtype=float),
        contacts=contacts,
        bodies={f"ball {i + 1}": (i,) for i in range(len(masses))},
        gaps=None if gaps is None else np.asarray(gaps, dtype=float),
        geometry=None
        if radius is None or len(masses) > GEOMETRY_BALLS
        else chain_geometry(tuple(masses), tuple(pairs), tuple(restitution), radius),
    )


@functools.lru_cache(maxsize=64)
def chain_geometry(
    masses: tuple[float, ...],
    pairs: tuple[Pair, ...],
    restitution: tuple[float, ...],
    radius: float,
) -> Geometry | None:
    """Balls of ``radius`` touching along the x axis, on free joints, walls as fixed planes.

    The right ball of a pair lies ``2 radius`` to the right of its left ball; a wall is the
    plane tangent to its ball, its normal towards the ball. Generalized velocity i is ball i's
    velocity along x: the contacts are head-on, so the balls keep to the line. None when the
    pairs do not place every ball once on a line. Cached: a geometry is immutable, and the
    scenes build the same chain again and again.
    """
    x = _places(len(masses), pairs, 2 * radius)
    if x is None:
        return None
    balls = [
        solid_sphere(f"ball {i + 1}", mass, radius, (x[i], 0.0, 0.0))
        for i, mass in enumerate(masses)
    ]
    walls, contacts = [], []
    for j, ((left, right), e) in enumerate(zip(pairs, restitution, strict=True)):
        if left is not None and right is not None:
            a, b, point, normal = balls[right], balls[left], x[left] + radius, 1.0
        else:
            a = balls[right if left is None else left]
            normal = 1.0 if left is None else -1.0
            point = a.position[0] - normal * radius
            walls.append(plane(f"wall {j}", (point, 0.0, 0.0), (normal, 0.0, 0.0)))
            b = walls[-1]
        contacts.append(ContactPair(a.name, b.name, (point, 0.0, 0.0), (normal, 0.0, 0.0), e=e))
    joints = [Joint("free", ball.name) for ball in balls] + [Joint("fixed", w.name) for w in walls]
    return geometry([*balls, *walls], joints, contacts, [(i, 0) for i in range(len(balls))])


def _places(balls: int, pairs: Sequence[Pair], spacing: float) -> list[float] | None:
    """The balls' centres along x, ball 0 at 0, each pair's right ball ``spacing`` further.

    None when the pairs leave a ball unplaced or place one twice at different points.
    """
    x: dict[int, float] = {0: 0.0}
    between = [(left, right) for left, right in pairs if left is not None and right is not None]
    for _ in range(balls):
        for left, right in between:
            if left in x and right not in x:
                x[right] = x[left] + spacing
            elif right in x and left not in x:
                x[left] = x[right] - spacing
    if len(x) < balls:
        return None
    if any(abs(x[right] - x[left] - spacing) > 1e-9 * spacing for left, right in between):
        return None
    return [x[i] for i in range(balls)]


def _mass_and_normals(masses: np.ndarray, pairs: Sequence[Pair]) -> tuple[Any, Any]:
    """Diagonal mass matrix and normal Jacobian: arrays, or CSC beyond `SPARSE_CONTACTS`."""
    # Ball indices of each contact's left and right side; a wall (None) reads as NaN.
    ends = np.array(pairs, dtype=float).reshape(len(pairs), 2)
    ball = ~np.isnan(ends)
    rows = ends[ball].astype(int)
    columns = np.nonzero(ball)[0]
    signs = np.broadcast_to([-1.0, 1.0], ends.shape)[ball]
    shape = (len(masses), len(pairs))
    if len(pairs) <= SPARSE_CONTACTS:
        Wn = np.zeros(shape)
        Wn[rows, columns] = signs
        return np.diag(masses), Wn
    import scipy.sparse

    Wn = scipy.sparse.csc_array((signs, (rows, columns)), shape=shape)
    return scipy.sparse.diags_array(masses, format="csc"), Wn


def ball_velocities(balls: int) -> list[str]:
    """Coordinate names of a chain of ``balls`` balls."""
    return [f"v{i + 1} [m/s]" for i in range(balls)]


def masses_spec(default: list[float]) -> Spec:
    """The ``masses`` parameter of a chain scene."""
    return Spec(
        "masses",
        default,
        "ball masses, left to right",
        unit="kg",
        kind="floats",
        low=0.0,
        low_open=True,
    )


def velocities_spec(default: list[float], doc: str) -> Spec:
    """The ``velocities`` parameter of a chain scene (pre-impact ball velocities)."""
    return Spec("velocities", default, doc, unit="m/s", kind="floats")


def restitution_spec() -> Spec:
    """The ``e`` parameter: one restitution coefficient for all contacts, or one per contact."""
    return Spec(
        "e",
        [1.0],
        "restitution coefficient, one value or one per contact",
        kind="floats",
        low=0.0,
        high=1.0,
    )


def exponent_spec(kind: str = "float") -> Spec:
    """The ``exponent`` parameter: force-indentation exponent of the contacts.

    ``kind`` 'floats' makes it one value or one per contact.
    """
    return Spec(
        "exponent",
        1.5 if kind == "float" else [1.5],
        "force-indentation exponent (1 linear, 1.5 Hertz)",
        kind=kind,
        low=0.0,
        low_open=True,
    )


def stiffness_ratio_spec(doc: str) -> Spec:
    """The ``stiffness_ratio`` parameter (contact 0 has stiffness 1 N/m^exponent)."""
    return Spec("stiffness_ratio", 1.0, doc, low=0.0, low_open=True)


def gaps_spec(count: int) -> Spec:
    """The ``gaps`` parameter: initial gap of each contact, zero by default."""
    return Spec(
        "gaps",
        [0.0] * count,
        "initial gap of each contact (0: in contact)",
        unit="m",
        kind="floats",
        low=0.0,
    )


class TwoContactChain(Case):
    """Balls on a line with two contacts, contact 0 of stiffness 1 and contact 1 of the ratio.

    A subclass says which balls each contact joins (``pairs``, None for a fixed wall); the
    parameters ``masses``, ``velocities`` and ``gaps`` take one value per ball or contact, ``e``
    one value or one per contact.
    """

    pairs: ClassVar[tuple[Pair, Pair]]
    # The balls' radius in the geometry an engine builds (m).
    radius: ClassVar[float] = BALL_RADIUS

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
            radius=self.radius,
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
