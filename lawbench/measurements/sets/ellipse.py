"""Planar impacts of an ellipse dropped on a plate (Fazeli et al. 2017).

An ellipse of 70 x 50 mm and 36.4 g, tracked at 250 Hz; each bounce gives the state before
and after the impact and the contact's normal and tangent rows. Coordinates are
``(vx, vy, omega)`` of the centre, with ``M = diag(m, m, I)`` and ``I = m (a^2 + b^2) / 4``
for semi-axes a = 35 mm, b = 25 mm (a uniform elliptical plate, the convention of the source
repository's ``AP Poisson/Compare Fish/compareModels.m``).

The set keeps the 1718 bounces of 2000 that the source flags as clean. The tangent row's
angular entry is stored with its sign reversed from the raw file: with the raw sign, the
measured changes of spin contradict the moment of the tangential impulse (relative residual
of the impulse fit, in the kinetic metric, median 0.18 over the kept bounces); reversed,
the spin agrees (median 0.022). The reversed sign is the row of the contact point's tangential
velocity when the angle and spin count clockwise, which the normal row cannot show: its
angular entry, the contact point's horizontal offset, changes sign with the mirror image.
The data's README gives the figures as the conversion measured them.
"""

from __future__ import annotations

import numpy as np

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


def _load() -> tuple[list[MeasuredImpact], np.ndarray, Processing]:
    data = read_data(NAME)
    M = mass_matrix()
    kept = ~data["flags"].any(axis=1)
    impacts = [
        MeasuredImpact(
            planar_problem(M, data["normal"][i], data["tangent"][i], data["v_before"][i]),
            data["v_after"][i],
            None,
            NAME,
            int(i),
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
