"""The measurement sets against their sources' counts, and the self-consistency check.

Sources (each set's README under ``lawbench/measurements/data`` gives commit and licence):

- ellipse: ``Wang/Wang-Mason Ellipse/ellipse_uniform.mat`` of DAIRLab/ImpactModeling (Fazeli
  et al., ICRA 2017): 2000 bounces, 1718 of them without any quality flag; mass 36.4 g, axes
  70 x 50 mm (``AP Poisson/Compare Fish/compareModels.m``).
- cube: ``assets/contactnets_cube/0.pt`` to ``549.pt`` of DAIRLab/dair_pll (Pfrommer, Halm and
  Posa, CoRL 2020): 550 tosses, pre-impact centre speeds of about 1.4 to 1.7 m/s, a kinetic
  energy ratio T+/T- of the first impacts near 0.44 in an independent extraction.
- kharaz: ``tests/dem/DEM05/write_usr0.f`` of MFiX (Kharaz, Gorham and Salman 2001, as
  digitized by Di Renzo and Di Maio 2004): 8 points of tangential restitution, 7 of rebound
  spin, 9 of rebound angle.
"""

import math

import numpy as np
import pytest

from lawbench.core.errors import UnknownName
from lawbench.core.trial import make_trial
from lawbench.laws.engines._base import geometry_mismatch
from lawbench.measurements import MEASUREMENTS, MeasuredImpact, consistency, residuals
from lawbench.measurements.convert import ellipse as convert_ellipse
from lawbench.measurements.impacts import read_data, training_mask
from lawbench.measurements.sets import ellipse, kharaz


def test_the_registry_holds_the_three_sets_and_refuses_an_unknown_one():
    assert MEASUREMENTS.names() == ["cube", "ellipse", "kharaz"]
    with pytest.raises(UnknownName, match="known: cube, ellipse, kharaz"):
        MEASUREMENTS["ellipses"]


def test_the_ellipse_keeps_the_1718_unflagged_of_2000_bounces():
    data = read_data("ellipse")
    assert data["flags"].shape == (2000, 6)
    s = MEASUREMENTS["ellipse"]
    assert len(s) == 1718
    assert s.processing.kept == 1718 and s.processing.dropped == {"flagged by the source": 282}
    assert {i.problem.n for i in s.impacts} == {3} and {i.problem.m for i in s.impacts} == {1}


def test_the_ellipse_inertia_from_its_published_mass_and_axes():
    """I = m (a^2 + b^2) / 4 of a uniform 70 x 50 mm plate of 36.4 g; the spin changes the
    bounces measured imply, by least squares on the moment of the impulses, lie within 30 %."""
    assert ellipse.INERTIA == pytest.approx(0.0364 * (0.035**2 + 0.025**2) / 4)
    impacts = MEASUREMENTS["ellipse"].impacts
    dv = np.array([i.dv for i in impacts])
    arms = np.array([(i.problem.Wn[2, 0], i.problem.Wt[2, 0]) for i in impacts])
    moment = ellipse.MASS * (dv[:, 1] * arms[:, 0] + dv[:, 0] * arms[:, 1])
    implied = moment @ dv[:, 2] / (dv[:, 2] @ dv[:, 2])
    assert 0.7 * ellipse.INERTIA < implied < ellipse.INERTIA


@pytest.mark.parametrize(("name", "count"), [("cube", 348), ("ellipse", 1718)])
def test_every_impact_of_a_set_with_geometry_is_its_geometry_s(name, count):
    """The cube tosses carry the box at its measured pose on the table's plane through its lowest
    touching vertex; the ellipse bounces the ellipse at the angle of the source's contact, on the
    plate through its lowest point. Every kept impact's problem is its geometry's."""
    impacts = MEASUREMENTS.get(name).impacts
    assert len(impacts) == count
    for impact in impacts:
        assert geometry_mismatch(impact.problem.geometry, impact.problem) is None


@pytest.mark.parametrize("angle", [-1.5, -0.7, 0.0, 0.3, 1.2])
def test_the_ellipse_touches_at_its_lowest_point_and_the_conversion_finds_its_angle(angle):
    """The closed-form lowest point lies on the ellipse, below 10^4 of its points turned
    clockwise by ``angle``; the conversion's search gives the angle back from that point."""
    a, b = ellipse.SEMI_AXES
    phi = np.linspace(0.0, 2 * np.pi, 10_000)
    x, z = a * np.cos(phi), b * np.sin(phi)
    c, s = math.cos(angle), math.sin(angle)
    turned = np.column_stack([x * c + z * s, -x * s + z * c])
    point = np.array(ellipse.lowest_point(angle))
    assert np.abs(np.hypot(*(turned - point).T)).min() < 1e-5
    assert point[1] <= turned[:, 1].min() < point[1] + 1e-8
    found, off = convert_ellipse.contact_angle(point)
    assert found == pytest.approx(angle, abs=1e-8) and off < 1e-12


def test_the_ellipse_tangent_sign_is_the_one_its_velocities_choose():
    s = MEASUREMENTS["ellipse"]
    summary = consistency(s.impacts)
    assert summary.count == 1718 and summary.median < 0.03 and summary.p95 < 0.08
    raw_sign = [
        MeasuredImpact(
            ellipse.planar_problem(
                i.problem.M, i.problem.Wn[:, 0], i.problem.Wt[:, 0] * [1, 1, -1], i.problem.v
            ),
            i.v_after,
        )
        for i in s.impacts[:300]
    ]
    assert np.median(residuals(raw_sign)) > 5 * np.median(residuals(s.impacts[:300]))


def test_the_cube_tosses_give_first_impacts_like_the_independent_extraction():
    s = MEASUREMENTS["cube"]
    assert s.processing.kept + sum(s.processing.dropped.values()) == 550
    assert s.processing.kept == len(s) > 300
    speeds = [np.linalg.norm(i.problem.v[:3]) for i in s.impacts]
    assert 1.4 < np.median(speeds) < 1.7
    ratios = [i.problem.kinetic_energy(i.v_after) / i.problem.T_minus for i in s.impacts]
    assert 0.35 < np.median(ratios) < 0.5
    contacts = np.array([i.problem.m for i in s.impacts])
    assert (contacts == 1).mean() > 0.5 and (contacts == 2).sum() > 0
    summary = consistency(s.impacts)
    assert summary.median < 0.1 and summary.p95 < 0.2
    assert all(max(i.facts["fit_residuals_m"]) <= 1e-3 for i in s.impacts)


def test_the_kharaz_points_per_quantity_as_digitized():
    curves = kharaz.curves()
    assert {k: len(x) for k, (x, _) in curves.items()} == {
        "tangential_restitution": 8,
        "rebound_spin": 7,
        "rebound_angle": 9,
    }
    incidence, restitution = curves["tangential_restitution"]
    assert incidence[0] == pytest.approx(2.0275) and restitution[-1] == pytest.approx(0.9019)
    s = MEASUREMENTS["kharaz"]
    assert len(s) == 6 and s.processing.dropped == {
        "incidence outside the digitized spin points": 2
    }


def test_the_kharaz_readings_agree_with_each_other():
    """The spin a rigid impulse at the contact gives the tangential restitution (the impacts'
    residual), and the rebound angle tan(a+) = e_t tan(a-) / e_n with e_n = 0.98."""
    s = MEASUREMENTS["kharaz"]
    assert consistency(s.impacts).median < 0.01
    angle_at, angle = kharaz.curves()["rebound_angle"]
    for impact in s.impacts:
        rebound = math.degrees(math.atan2(impact.v_after[0], impact.v_after[1]))
        digitized = np.interp(impact.facts["incidence_deg"], angle_at, angle)
        assert rebound == pytest.approx(digitized, abs=1.5)


def test_the_split_is_stored_fixed_and_halves_each_set():
    assert np.array_equal(training_mask(101), training_mask(101))
    assert training_mask(101).sum() == 50
    for name in MEASUREMENTS:
        s = MEASUREMENTS[name]
        assert len(s.train) == len(s) // 2 and len(s.train) + len(s.test) == len(s)
        assert not {id(i) for i in s.train} & {id(i) for i in s.test}


def test_a_measured_impact_is_a_source_of_the_one_way_into_a_solve():
    impact = MEASUREMENTS["kharaz"].impacts[0]
    trial = make_trial("newton", impact)
    assert trial.problem is impact.problem and trial.facts["incidence_deg"] == 9.6304
