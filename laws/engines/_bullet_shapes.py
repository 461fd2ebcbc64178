"""The collision shapes Bullet builds from a geometry's bodies, by their sizes.

Bullet's shapes (PyBullet Quickstart Guide, createCollisionShape) take a sphere's radius, a
box's half extents, and a capsule's or cylinder's radius and whole height; the geometry's sizes
are a radius and a half length. Bullet has no ellipsoid: it is the convex hull of points of its
surface (a GEOM_MESH of vertices).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

# Bullet has no ellipsoid: at the default settings it is the convex hull of points of its
# surface, on PARALLELS parallels (an odd number: the equator is one) of MERIDIANS points.
PARALLELS = 5
MERIDIANS = 128
# The arguments of createCollisionShape for each shape Bullet has, from the geometry's sizes.
SIZES = {
    "sphere": lambda size: {"radius": size[0]},
    "box": lambda size: {"halfExtents": list(size)},
    "capsule": lambda size: {"radius": size[0], "height": 2 * size[1]},
    "cylinder": lambda size: {"radius": size[0], "height": 2 * size[1]},
    "plane": lambda size: {},
}


def ellipsoid_points(size: Sequence[float]) -> list[list[float]]:
    """Points of the surface of the ellipsoid of semi-axes ``size``, for Bullet's convex hull.

    `MERIDIANS` points on each of `PARALLELS` parallels about the body's y axis, the equator
    (the body's x-z section) among them, and the two poles.
    """
    a, b, c = size
    points = [[0.0, -b, 0.0], [0.0, b, 0.0]]
    for latitude in np.linspace(-np.pi / 2, np.pi / 2, PARALLELS + 2)[1:-1]:
        for longitude in np.linspace(0.0, 2 * np.pi, MERIDIANS, endpoint=False):
            ring = math.cos(latitude)
            x, z = a * ring * math.cos(longitude), c * ring * math.sin(longitude)
            points.append([x, b * math.sin(latitude), z])
    return points
