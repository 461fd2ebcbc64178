"""Contact Jacobians of rigid bodies, shared by the scenes with friction.

A planar body has coordinates (x, y, theta) of its centre of mass; a spatial body (vx, vy, vz,
wx, wy, wz) with the angular velocity in the world frame. A contact point at ``r`` from the
centre of mass with unit normal ``normal`` (pointing from the obstacle into the body, so the
gap rate is ``normal @ velocity_of_point``) and unit tangents gives one Jacobian column per
direction: the velocity of the point along that direction, per unit generalized velocity.
"""

from __future__ import annotations

import numpy as np


def planar_column(r: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Column of a planar body: point velocity along ``direction`` = col @ (vx, vy, omega)."""
    rx, ry = r
    dx, dy = direction
    # Point velocity v + omega x r = (vx - omega ry, vy + omega rx).
    return np.array([dx, dy, rx * dy - ry * dx])


def spatial_column(r: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Column of a spatial body: point velocity along ``direction`` = col @ (v, omega)."""
    # d . (v + omega x r) = d . v + omega . (r x d).
    return np.concatenate([direction, np.cross(r, direction)])


def planar_tangent(normal: np.ndarray) -> np.ndarray:
    """The planar tangent: the normal turned by -90 degrees (x along the floor for n = y)."""
    return np.array([normal[1], -normal[0]])
