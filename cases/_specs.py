"""The parameters that the frictional scenes share: a body's mass, Newton's ``e``, Coulomb's ``mu``.

Each takes its default and its line of documentation, which says what the scene means by it.
"""

from __future__ import annotations

from lawbench.core.spec import Spec


def positive(name: str, default: float, doc: str, unit: str) -> Spec:
    """A real number above zero (a length, a mass, a speed)."""
    return Spec(name, default, doc, unit=unit, kind="float", low=0.0, low_open=True)


def positives(name: str, default: list[float], doc: str, unit: str) -> Spec:
    """A list of real numbers above zero (the lengths or masses of several bodies)."""
    return Spec(name, default, doc, unit=unit, kind="floats", low=0.0, low_open=True)


def mass(default: float, doc: str) -> Spec:
    """The ``mass`` of the scene's body, in kg."""
    return positive("mass", default, doc, "kg")


def restitution(
    default: float | list[float], doc: str = "Newton's restitution coefficient"
) -> Spec:
    """The restitution ``e`` in [0, 1]: one number, or a list (one per contact) for a list."""
    kind = "floats" if isinstance(default, list) else "float"
    return Spec("e", default, doc, kind=kind, low=0.0, high=1.0)


def friction(default: float | list[float], doc: str = "Coulomb friction coefficient") -> Spec:
    """Coulomb's ``mu`` >= 0: one number, or a list (one per contact) for a list."""
    kind = "floats" if isinstance(default, list) else "float"
    return Spec("mu", default, doc, kind=kind, low=0.0)
