"""Balls on a line: the impact problem of a chain, shared by the chain scenes.

Coordinates are the ball velocities along the line. A contact is a pair ``(left, right)`` of
ball indices, the right ball being on the positive side of the left one, so the gap rate is
``v[right] - v[left]``; ``None`` in place of a ball is a fixed wall.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lawbench.core.problem import Contact, ImpactProblem
from lawbench.core.spec import Spec

Pair = tuple[int | None, int | None]
# Beyond this many contacts a chain's M and Wn are scipy.sparse: dense n x n storage and
# products would dominate its cost, and Moreau's law solves it sparse end to end.
SPARSE_CONTACTS = 256


def chain_problem(
    masses: Sequence[float],
    velocities: Sequence[float],
    pairs: Sequence[Pair],
    restitution: Sequence[float],
    stiffness: Sequence[float],
    exponents: Sequence[float],
    gaps: Sequence[float] | None = None,
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
    )


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
