"""Oblique impacts of an alumina sphere on a glass anvil (Kharaz, Gorham and Salman 2001).

A 5 mm alumina sphere (density 3960 kg/m^3) strikes a thick glass anvil at 3.9 m/s, without
spin, at incidences from near-normal to grazing. Only points digitized from the paper's figures
are public; those shipped here are the readings in NETL MFiX's test ``tests/dem/DEM05``
(taken there from Di Renzo and Di Maio's reproduction of Kharaz's figures, Chem. Eng. Sci.
59, 2004): the tangential restitution of the centre ``vx+ / vx-`` (8 points), the rebound spin
(7 points, rad/s) and the rebound angle of the centre from the normal (9 points, degrees),
each against the incidence angle from the normal (degrees). The rebound angle of the contact
point, ``atan(vt+ / vn+)`` with ``vt+`` the contact point's tangential velocity after the
impact (negative: it moves back against the approach), is Kharaz's figure as digitized in
Kratos Multiphysics' test 4 of Chung and Ooi's benchmarks (11 points, `contact_curve`,
`CONTACT_SOURCE`): it falls to about -8.5 degrees at 20 degrees of incidence, the reversal
that tangential compliance gives (Maw, Barber and Fawcett 1976).

The set is the setup and the curves (`SETUP`, `curves`), and also measured impacts, one at
each incidence of the tangential restitution where the spin was digitized around it: the spin
is interpolated linearly in incidence, and the normal rebound takes ``e_n = 0.98``, the value
DEM benchmarks use for this pair (the digitized points do not give it). Planar coordinates are
``(vx, vy, omega)`` of the centre, x along the approach's tangential direction, y the anvil's
normal, omega counterclockwise; the contact point lies at ``(0, -R)``, so friction spins the
sphere clockwise and the rebound spin is stored negative.

Geometry, for the engines (`Setup.geometry`): the sphere moves in the plane z = 0 (a planar
joint), the anvil is the fixed plane y = 0, and the contact is at the origin, normal y,
tangent x.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from lawbench.core.geometry import Body, ContactPair, Geometry, Joint
from lawbench.measurements import impacts as measured

NAME = "kharaz"
# The quantities digitized, as (incidence key, value key) in the data file.
QUANTITIES = {
    "tangential_restitution": ("incidence_et", "et"),
    "rebound_spin": ("incidence_spin", "spin"),
    "rebound_angle": ("incidence_angle", "rebound_angle"),
}
# The unit quaternion (w, x, y, z) of a quarter turn about -x: it takes the anvil plane's own
# normal, its body's z axis, onto the world's y.
ANVIL_TURN = (math.sqrt(0.5), -math.sqrt(0.5), 0.0, 0.0)
# The normal restitution of alumina on glass that DEM benchmarks use for this experiment.
NORMAL_RESTITUTION = 0.98
SOURCE = measured.Source(
    paper=(
        "A. H. Kharaz, D. A. Gorham, A. D. Salman, An experimental study of the elastic "
        "rebound of spheres, Powder Technology 120 (2001) 281-291; points as digitized by "
        "A. Di Renzo, F. P. Di Maio, Chem. Eng. Sci. 59 (2004) 525-541"
    ),
    repository="https://github.com/soufiane92/MFiX-21.3.2 (a copy of NETL MFiX 21.3.2)",
    commit="e8a0d92f47910deaf2a20b1365aeb1af2adc2c5f",
    path="tests/dem/DEM05/write_usr0.f",
    licence=(
        "MFiX is public-domain software of the U.S. DOE's NETL; the copy read states no "
        "licence file of its own"
    ),
)

# The contact point's rebound angle, from a second repository.
CONTACT = ("incidence_contact", "contact_angle")
CONTACT_SOURCE = measured.Source(
    paper=(
        "A. H. Kharaz, D. A. Gorham, A. D. Salman, Powder Technology 120 (2001) 281-291; "
        "points as digitized for Y. C. Chung, J. Y. Ooi, Benchmark tests for verifying discrete "
        "element modelling codes at particle impact level, Granular Matter 13 (2011) 643-656, "
        "test 4"
    ),
    repository="https://github.com/KratosMultiphysics/Kratos",
    commit="f678879c5465efeaae8328b72b3fea70897e4721",
    path=(
        "applications/DEMApplication/tests/DEM3D_chung_ooi_tests/test4_data/paper_data/"
        "benchmark4_graph3.dat (block #Experiment)"
    ),
    licence=(
        "Kratos Multiphysics licence (BSD style with an advertising clause, license.txt); "
        "only the measured numbers are kept"
    ),
)


@dataclass(frozen=True)
class Setup:
    """The measured setup: a sphere without initial spin striking a fixed plane.

    Attributes
    ----------
    radius : float
        Sphere radius (m).
    density : float
        Alumina's density (kg/m^3).
    speed : float
        Impact speed (m/s).
    """

    radius: float = 2.5e-3
    density: float = 3960.0
    speed: float = 3.9

    @property
    def mass(self) -> float:
        """The sphere's mass (kg)."""
        return self.density * 4.0 / 3.0 * math.pi * self.radius**3

    @property
    def inertia(self) -> float:
        """The solid sphere's moment of inertia about its centre, ``2 m R^2 / 5``."""
        return 0.4 * self.mass * self.radius**2

    def mass_matrix(self) -> np.ndarray:
        """``diag(m, m, I)`` in the planar coordinates ``(vx, vy, omega)``."""
        return np.diag([self.mass, self.mass, self.inertia])

    def velocity_before(self, incidence: float) -> np.ndarray:
        """The velocity before an impact at ``incidence`` degrees from the normal."""
        angle = math.radians(incidence)
        return np.array([self.speed * math.sin(angle), -self.speed * math.cos(angle), 0.0])

    def geometry(self, e: float = 0.0, mu: float = 0.0) -> Geometry:
        """The sphere touching the anvil at the origin, the contact of coefficients e and mu.

        ``to_bodies`` picks ``(vx, vy, omega)`` from the sphere's velocity ``(v, w)``.
        """
        sphere = Body(
            "sphere", "sphere", (self.radius,), self.mass, (self.inertia,) * 3, (0, self.radius, 0)
        )
        anvil = Body("anvil", "plane", (), quaternion=ANVIL_TURN)
        pair = ContactPair("sphere", "anvil", (0, 0, 0), (0, 1, 0), ((1, 0, 0),), e, mu)
        joints = (Joint("planar", "sphere", (0, 0, 1)), Joint("fixed", "anvil"))
        to_bodies = np.zeros((12, 3))
        to_bodies[[0, 1, 5], [0, 1, 2]] = 1.0
        return Geometry((sphere, anvil), joints, (pair,), to_bodies, to_bodies.T)

    def impact(
        self, incidence: float, restitution: float, spin: float, index: int
    ) -> measured.MeasuredImpact:
        """The measured impact at ``incidence`` (degrees from the normal).

        Rebuilt from the centre's tangential restitution and the rebound spin's magnitude
        (rad/s), with ``NORMAL_RESTITUTION`` for the normal rebound; the contact point is
        ``(0, -R)``.
        """
        v = self.velocity_before(incidence)
        after = np.array([restitution * v[0], -NORMAL_RESTITUTION * v[1], -spin])
        normal = np.array([0.0, 1.0, 0.0])
        tangent = np.array([1.0, 0.0, self.radius])
        problem = measured.planar_problem(self.mass_matrix(), normal, tangent, v)
        problem = dataclasses.replace(problem, geometry=self.geometry())
        facts = {"incidence_deg": incidence, "normal_restitution": NORMAL_RESTITUTION}
        return measured.MeasuredImpact(problem, after, None, NAME, index, facts)


SETUP = Setup()


def curves() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The digitized points per quantity: ``(incidence in degrees, value)``."""
    data = measured.read_data(NAME)
    return {name: (data[x], data[y]) for name, (x, y) in QUANTITIES.items()}


def contact_curve() -> tuple[np.ndarray, np.ndarray]:
    """The contact point's rebound angle: ``(incidence in degrees, angle in degrees)``.

    The angle is ``atan(vt+ / vn+)`` from the anvil's normal, ``vt+`` the tangential velocity
    of the sphere's point of contact after the impact, positive along the approach.
    """
    data = measured.read_data(NAME)
    return data[CONTACT[0]], data[CONTACT[1]]


def _load() -> tuple[list[measured.MeasuredImpact], np.ndarray, measured.Processing]:
    data = measured.read_data(NAME)
    low, high = data["incidence_spin"][0], data["incidence_spin"][-1]
    impacts = []
    for rank, (incidence, restitution) in enumerate(
        zip(data["incidence_et"], data["et"], strict=True)
    ):
        if low <= incidence <= high:
            spin = float(np.interp(incidence, data["incidence_spin"], data["spin"]))
            impacts.append(SETUP.impact(float(incidence), float(restitution), spin, rank))
    return impacts, data["train"], measured.processing_from(data)


KHARAZ = measured.MEASUREMENTS.register(
    measured.MeasurementSet(
        NAME,
        "oblique impacts of a 5 mm alumina sphere on glass at 3.9 m/s, digitized curves",
        SOURCE,
        _load,
        facts={
            "radius": SETUP.radius,
            "density": SETUP.density,
            "speed": SETUP.speed,
            "mass": SETUP.mass,
            "inertia": SETUP.inertia,
            "normal_restitution": NORMAL_RESTITUTION,
            "dem_friction": 0.092,
        },
    )
)
