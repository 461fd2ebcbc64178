"""Tosses of a cube onto a table (Pfrommer, Halm and Posa, ContactNets, CoRL 2020).

550 tosses of a cube of side 0.1048 m and 0.37 kg, tracked at 148 Hz; reused by Acosta, Yang
and Posa (RA-L 2022). Each toss is a trajectory: the impacts are its first impacts, extracted
by `lawbench.measurements.tosses` (free flight fitted on each side, the contacts the vertices
within 2 mm of the table). Coordinates are ``(v_centre, omega)`` in the world frame, z up,
with ``M = diag(m, m, m, I, I, I)`` and ``I = m s^2 / 6``, a uniform cube's (the source's
model file states 0.00081 kg m^2 instead).

The raw samples hold the angular velocity in the body frame (the source's state convention:
quaternion w, x, y, z; position; body-axes angular velocity; world-axes linear velocity). The
extraction does not read those columns: it fits the world-frame angular velocity to the
orientations, the frame the Jacobian's rows ``(e, r x e)`` need.

Geometry, for the engines: the cube a box at the measured pose, with a free joint, and the
table a fixed plane through the lowest touching vertex; contact j at touching vertex j, normal
z, tangents x and y. The generalized velocity is the cube's body velocity itself. A second
vertex of a compound impact lies up to 2 mm above the table there, and lands as the cube turns.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.spatial.transform import Rotation

from lawbench.core.geometry import Body, ContactPair, Geometry, Joint
from lawbench.measurements.impacts import (
    MEASUREMENTS,
    MeasuredImpact,
    MeasurementSet,
    Processing,
    Source,
    processing_from,
    read_data,
)
from lawbench.measurements.tosses import vertex_problem

NAME = "cube"
MASS = 0.37
SIDE = 0.1048
INERTIA = MASS * SIDE**2 / 6
# The cube's vertices in its own frame, from the centre.
VERTICES = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float) * (
    SIDE / 2
)
SOURCE = Source(
    paper=(
        "S. Pfrommer, M. Halm, M. Posa, ContactNets: learning discontinuous contact dynamics "
        "with smooth, implicit representations, CoRL 2020; reused by B. Acosta, W. Yang, "
        "M. Posa, Validating robotics simulators on real-world impacts, RA-L 2022"
    ),
    repository="https://github.com/DAIRLab/dair_pll",
    commit="523d372d8c2b50ea5ce77082d4f08879c753d963",
    path="assets/contactnets_cube/0.pt ... 549.pt (model: assets/contactnets_cube.urdf)",
    licence="BSD-3-Clause (the repository's LICENSE, Copyright 2022 DAIR Lab)",
)


def _load() -> tuple[list[MeasuredImpact], np.ndarray, Processing]:
    data = read_data(NAME)
    impacts = []
    for row, toss in enumerate(data["toss"]):
        rotation = Rotation.from_quat(data["quaternion"][row])
        offsets = rotation.apply(VERTICES[data["touching"][row]])
        position = data["position"][row]
        problem = dataclasses.replace(
            vertex_problem(MASS, INERTIA, offsets, data["v_before"][row]),
            geometry=_geometry(position, rotation, offsets),
        )
        facts = {
            "fit_residuals_m": tuple(data["fit_residuals"][row, :2]),
            "fit_residuals_rad": tuple(data["fit_residuals"][row, 2:]),
            "compound": bool(data["compound"][row]),
            "position": position,
        }
        impacts.append(MeasuredImpact(problem, data["v_after"][row], None, NAME, int(toss), facts))
    return impacts, data["train"], processing_from(data)


def _geometry(position: np.ndarray, rotation: Rotation, offsets: np.ndarray) -> Geometry:
    """The cube at ``position`` turned by ``rotation``, touching the table at ``offsets``.

    The pairs' coefficients are the problem's placeholders, ``e = 0`` and ``mu = 0``.
    """
    x, y, z, w = rotation.as_quat()
    cube = Body("cube", "box", (SIDE / 2,) * 3, MASS, (INERTIA,) * 3, tuple(position), (w, x, y, z))
    table = Body("table", "plane", (), position=(0.0, 0.0, position[2] + offsets[:, 2].min()))
    axes = [tuple(axis) for axis in np.eye(3)]
    pairs = tuple(
        ContactPair("cube", "table", tuple(position + r), axes[2], tuple(axes[:2]), 0.0, 0.0)
        for r in offsets
    )
    joints = (Joint("free", "cube"), Joint("fixed", "table"))
    to_bodies = np.vstack([np.eye(6), np.zeros((6, 6))])
    return Geometry((cube, table), joints, pairs, to_bodies, to_bodies.T)


CUBE = MEASUREMENTS.register(
    MeasurementSet(
        NAME,
        "first impacts of 550 cube tosses on a table, 148 Hz tracking",
        SOURCE,
        _load,
        facts={"mass": MASS, "side": SIDE, "inertia": INERTIA, "sampling_hz": 148.0},
    )
)
