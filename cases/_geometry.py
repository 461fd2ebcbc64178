"""The bodies the scenes are made of, as an engine builds them (`lawbench.core.geometry`).

A uniform solid sphere, a uniform box and a fixed plane, each at its pose at the impact, and
the velocity map of a scene whose generalized velocities are components of its bodies'
velocities (the chains, the sphere, the planar block): ``to_bodies`` picks them and its
transpose reads them back.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from lawbench.core.geometry import Body, ContactPair, Geometry, Joint


def solid_sphere(name: str, mass: float, radius: float, position: Sequence[float]) -> Body:
    """A uniform solid sphere: inertia ``2 mass radius^2 / 5`` about every axis."""
    inertia = 0.4 * mass * radius**2
    return Body(name, "sphere", (radius,), mass, (inertia,) * 3, tuple(position))


def solid_box(name: str, mass: float, half: Sequence[float], position: Sequence[float]) -> Body:
    """A uniform box of half-extents ``half``, its edges along the world axes."""
    a, b, c = (2.0 * h for h in half)
    inertia = (
        mass * (b * b + c * c) / 12,
        mass * (a * a + c * c) / 12,
        mass * (a * a + b * b) / 12,
    )
    return Body(name, "box", tuple(half), mass, inertia, tuple(position))


def plane(name: str, point: Sequence[float], normal: Sequence[float]) -> Body:
    """A fixed plane through ``point`` whose normal (its body's z axis) is ``normal``."""
    return Body(name, "plane", (), position=tuple(point), quaternion=z_onto(normal))


def z_onto(direction: Sequence[float]) -> tuple[float, float, float, float]:
    """The unit quaternion ``(w, x, y, z)`` of the shortest rotation taking z onto ``direction``."""
    norm = math.hypot(*direction)
    x, y, z = (c / norm for c in direction)
    if z < -1.0 + 1e-12:
        return (0.0, 1.0, 0.0, 0.0)  # half a turn about x
    # The axis z x d, of length sin(angle), and w = 1 + cos(angle): halved by the norm.
    w = 1.0 + z
    norm = math.sqrt(w * w + x * x + y * y)
    return (w / norm, -y / norm, x / norm, 0.0)


def picked(bodies: Sequence[Body], components: Sequence[tuple[int, int]]) -> np.ndarray:
    """``to_bodies`` of generalized velocities that are components of the bodies' velocities.

    ``components[i]`` is ``(body, component)``: generalized velocity i is component 0-5
    (``vx, vy, vz, wx, wy, wz``) of that body's velocity. The map's columns are orthonormal,
    so its transpose reads the generalized velocity back.
    """
    B = np.zeros((6 * len(bodies), len(components)))
    for i, (body, component) in enumerate(components):
        B[6 * body + component, i] = 1.0
    return B


def geometry(
    bodies: Sequence[Body],
    joints: Sequence[Joint],
    pairs: Sequence[ContactPair],
    components: Sequence[tuple[int, int]],
) -> Geometry:
    """The geometry whose generalized velocities are the ``components`` (`picked`)."""
    B = picked(bodies, components)
    return Geometry(tuple(bodies), tuple(joints), tuple(pairs), B, B.T)
