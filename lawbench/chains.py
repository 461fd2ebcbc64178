"""Balls on a line: the impact problem of a chain, shared by the chain scenes.

Coordinates are the ball velocities along the line. A contact is a pair ``(left, right)`` of
ball indices, the right ball being on the positive side of the left one, so the gap rate is
``v[right] - v[left]``; ``None`` in place of a ball is a fixed wall.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lawbench.problem import Contact, ImpactProblem
from lawbench.spec import Spec

Pair = tuple[int | None, int | None]


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
    masses, velocities : sequences of n floats
        Ball masses (kg) and velocities (m/s, positive to the right).
    pairs : sequence of m (left, right) pairs
        Ball indices, or None for a fixed wall on that side.
    restitution, stiffness, exponents : sequences of m floats
        Restitution coefficient, stiffness and force-indentation exponent of each contact.
    gaps : sequence of m floats, optional
        Initial gaps (m); zero by default.
    """
    n = len(masses)
    Wn = np.zeros((n, len(pairs)))
    for j, (left, right) in enumerate(pairs):
        if left is not None:
            Wn[left, j] = -1.0
        if right is not None:
            Wn[right, j] = 1.0
    contacts = [
        Contact(e=e, stiffness=k, exponent=n)
        for e, k, n in zip(restitution, stiffness, exponents, strict=True)
    ]
    return ImpactProblem(
        M=np.diag(np.asarray(masses, dtype=float)),
        Wn=Wn,
        v=np.asarray(velocities, dtype=float),
        contacts=contacts,
        bodies={f"ball {i + 1}": (i,) for i in range(n)},
        gaps=None if gaps is None else np.asarray(gaps, dtype=float),
    )


def ball_velocities(n: int) -> list[str]:
    """Coordinate names of n balls."""
    return [f"v{i + 1} [m/s]" for i in range(n)]


def masses_spec(default: list[float]) -> Spec:
    """The ``masses`` parameter of a chain scene."""
    return Spec("masses", default, "ball masses, left to right", "kg", "floats", 0.0, low_open=True)


def velocities_spec(default: list[float], doc: str) -> Spec:
    """The ``velocities`` parameter of a chain scene (pre-impact ball velocities)."""
    return Spec("velocities", default, doc, "m/s", "floats")


def restitution_spec() -> Spec:
    """The ``e`` parameter: one restitution coefficient for all contacts, or one per contact."""
    return Spec(
        "e", [1.0], "restitution coefficient, one value or one per contact", "", "floats", 0.0, 1.0
    )


def exponent_spec(kind: str = "float") -> Spec:
    """The ``exponent`` parameter: force-indentation exponent of the contacts.

    ``kind`` 'floats' makes it one value or one per contact.
    """
    return Spec(
        "exponent",
        1.5 if kind == "float" else [1.5],
        "force-indentation exponent (1 linear, 1.5 Hertz)",
        "",
        kind,
        0.0,
        low_open=True,
    )


def stiffness_ratio_spec(doc: str) -> Spec:
    """The ``stiffness_ratio`` parameter (contact 0 has stiffness 1 N/m^exponent)."""
    return Spec("stiffness_ratio", 1.0, doc, "", "float", 0.0, low_open=True)


def gaps_spec(count: int) -> Spec:
    """The ``gaps`` parameter: initial gap of each contact, zero by default."""
    return Spec(
        "gaps", [0.0] * count, "initial gap of each contact (0: in contact)", "m", "floats", 0.0
    )
