"""Planar impacts of an ellipse dropped on a plate (Fazeli et al. 2017).

An ellipse of 70 x 50 mm and 36.4 g, tracked at 250 Hz; each bounce gives the state before
and after the impact and the ellipse's angle at the impact. Coordinates are ``(vx, vy, omega)``
of the centre, x along the plate and y up, with ``M = diag(m, m, I)`` and
``I = m (a^2 + b^2) / 4`` for semi-axes a = 35 mm, b = 25 mm (a uniform elliptical plate, the
convention of the source repository's ``AP Poisson/Compare Fish/compareModels.m``).

The set keeps the 1718 bounces of 2000 that the source flags as clean. The angle and the spin
count clockwise: with the source's rows read counterclockwise, the measured changes of spin
contradict the moment of the tangential impulse (relative residual of the impulse fit, in the
kinetic metric, median 0.18 over the kept bounces); read clockwise, the spin agrees (median
0.022). The mirror image changes the sign of the tangent row's angular entry only: the normal
row's, the contact point's horizontal offset, changes sign with the offset itself.

The contact is the ellipse's lowest point at the angle of the impact, and the plate the plane
through it. That angle is the one at which the source computed its contact rows: their contact
point is the lowest point of the 35 x 25 mm ellipse at some angle, to 0.12 um at most (median
0.3 nm), and the conversion ships that angle. The recorded angle of the state before the impact
differs from it by the spin times about 3.9 ms (median; correlation -0.95), a frame at 250 Hz:
its lowest point lies 0.28 mm (median) to 1.7 mm from the rows' contact, and the centre there
lies 2.2 mm (median) above touching the plate, from 11 mm below to 14 mm above. The set keeps
the contact the source states with each bounce (its rows ``n`` and ``d``): its rows are those
of the lowest point at the shipped angle, which moves the source's rows by at most 0.12 um,
where the recorded angle would move the contact by 0.28 mm (median), a pose not at contact
either.

Geometry, for the engines (`geometry`): the ellipse moves in the plane y = 0 of the world
(x along the plate, z up, a planar joint about y), its centre at height ``h`` above the plate,
the fixed plane z = 0, and the contact at its lowest point, normal z, tangent x. The
generalized ``(vx, vy, omega)`` are the world's ``(vx, vz, wy)``: seen with x to the right and
z up, a turn about +y is clockwise. The engines build the ellipse as an ellipsoid of semi-axes
(a, b, b), its plane of symmetry the plane of motion: its section there is the ellipse, and its
lowest point lies in that plane at every angle, so its contact with the plate is the elliptic
cylinder's. MuJoCo and Drake build their own ellipsoid; PyBullet, which has none, the convex
hull of points of its surface at its defaults and, tuned, a small sphere at the contact point
(as it does a box's corners).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from lawbench.core.geometry import Body, ContactPair, Geometry, Joint
from lawbench.core.problem import ImpactProblem
from lawbench.measurements.impacts import (
    MEASUREMENTS,
    MeasuredImpact,
    MeasurementSet,
    Processing,
    Source,
    planar_problem,
    processing_from,
    read_data,
)

NAME = "ellipse"
MASS = 36.4e-3
SEMI_AXES = (0.035, 0.025)
INERTIA = MASS * (SEMI_AXES[0] ** 2 + SEMI_AXES[1] ** 2) / 4
# The source's quality flags, in the order of its ``flags`` row.
FLAGS = ("sb", "en", "cl", "mc", "de", "ld")
SOURCE = Source(
    paper=(
        "N. Fazeli, E. Donlon, E. Drumwright, A. Rodriguez, Empirical evaluation of common "
        "contact models for planar impact, ICRA 2017; N. Fazeli, S. Zapolsky, E. Drumwright, "
        "A. Rodriguez, Fundamental limitations in performance and interpretability of common "
        "planar rigid-body contact models, CoRL 2017"
    ),
    repository="https://github.com/DAIRLab/ImpactModeling",
    commit="f6c28898845da6d48efdd6c1c696db2fb3716edf",
    path="Wang/Wang-Mason Ellipse/ellipse_uniform.mat",
    licence="BSD-3-Clause (the repository's LICENSE, Copyright 2020 DAIR Lab)",
)


def mass_matrix() -> np.ndarray:
    """``diag(m, m, I)`` of the ellipse."""
    return np.diag([MASS, MASS, INERTIA])


def lowest_point(angle: float) -> tuple[float, float]:
    """The ellipse's lowest point from its centre, ``(x, -h)``, at ``angle`` (rad, clockwise).

    At angle 0 the major axis lies along the plate. The point of parameter phi,
    ``(a cos phi cos t + b sin phi sin t, -a cos phi sin t + b sin phi cos t)``, is lowest at
    ``h = sqrt(a^2 sin^2 t + b^2 cos^2 t)`` and ``x = (a^2 - b^2) sin t cos t / h``.
    """
    a, b = SEMI_AXES
    s, c = math.sin(angle), math.cos(angle)
    h = math.sqrt((a * s) ** 2 + (b * c) ** 2)
    return (a * a - b * b) * s * c / h, -h


def geometry(angle: float) -> Geometry:
    """The ellipse at ``angle`` (rad, clockwise) on the plate, touching at its lowest point.

    The pair's coefficients are the problem's placeholders, ``e = 0`` and ``mu = 0``.
    """
    a, b = SEMI_AXES
    x, y = lowest_point(angle)
    turn = (math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0)
    inertia = (MASS * b * b / 4, INERTIA, MASS * a * a / 4)
    ellipse = Body("ellipse", "ellipsoid", (a, b, b), MASS, inertia, (0.0, 0.0, -y), turn)
    plate = Body("plate", "plane", ())
    pair = ContactPair("ellipse", "plate", (x, 0.0, 0.0), (0, 0, 1), ((1, 0, 0),), 0.0, 0.0)
    joints = (Joint("planar", "ellipse", (0, 1, 0)), Joint("fixed", "plate"))
    to_bodies = np.zeros((12, 3))
    to_bodies[[0, 2, 4], [0, 1, 2]] = 1.0
    return Geometry((ellipse, plate), joints, (pair,), to_bodies, to_bodies.T)


def impact_problem(angle: float, v: np.ndarray) -> ImpactProblem:
    """The bounce at ``angle`` with velocity ``v`` before: the rows of its geometry's contact."""
    shape = geometry(angle)
    Wn, Wt = shape.jacobians()
    problem = planar_problem(shape.mass_matrix(), Wn[:, 0], Wt[:, 0], v)
    return dataclasses.replace(problem, geometry=shape)


def _load() -> tuple[list[MeasuredImpact], np.ndarray, Processing]:
    data = read_data(NAME)
    kept = ~data["flags"].any(axis=1)
    impacts = [
        MeasuredImpact(
            impact_problem(float(data["angle"][i]), data["v_before"][i]),
            data["v_after"][i],
            None,
            NAME,
            int(i),
            {"angle": float(data["angle"][i])},
        )
        for i in np.flatnonzero(kept)
    ]
    return impacts, data["train"][kept], processing_from(data)


ELLIPSE = MEASUREMENTS.register(
    MeasurementSet(
        NAME,
        "planar impacts of a 70 x 50 mm ellipse on a plate, 250 Hz tracking",
        SOURCE,
        _load,
        facts={
            "mass": MASS,
            "semi_axes": SEMI_AXES,
            "inertia": INERTIA,
            "sampling_hz": 250.0,
            "published_fits": {"ICRA 2017": (0.057, 0.612), "CoRL 2017": (0.120, 0.537)},
            "published_fits_meaning": "(mu, e) of the authors' fits",
        },
    )
)
