"""Kharaz's oblique impacts of an alumina sphere on glass against the frictional laws.

Source: A. H. Kharaz, D. A. Gorham, A. D. Salman, "An experimental study of the elastic rebound
of spheres", Powder Technology 120 (2001) 281-291, as digitized in MFiX's test DEM05
(``tests/dem/DEM05/write_usr0.f``: tangential restitution, spin, rebound angle of the centre)
and in Kratos' test 4 of Chung and Ooi's benchmarks
(``applications/DEMApplication/tests/DEM3D_chung_ooi_tests/test4_data/paper_data/
benchmark4_graph3.dat``: rebound angle of the contact point); e = 0.98 and mu = 0.092 as DEM
benchmarks of this pair take them. The reversal of the contact point is Maw, Barber and
Fawcett's (Wear 38, 1976) signature of tangential compliance.
"""

import math

import numpy as np
import pandas as pd
import pytest

from lawbench.fitting import kharaz_curves as kc
from lawbench.measurements.sets import kharaz

RIGID = ("whittaker", "moreau", "darboux_keller", "brach")


def test_the_contact_point_points_as_digitized_agree_with_the_other_readings():
    """vt+ = e_t V sin a - R spin and vn+ = e_n V cos a give the digitized contact angle."""
    at, angle = kharaz.contact_curve()
    assert len(at) == 11 and angle[3] == pytest.approx(-8.5347, abs=1e-4)
    x, restitution = kharaz.curves()["tangential_restitution"]
    spin_at, spin = kharaz.curves()["rebound_spin"]
    setup = kharaz.SETUP
    inside = (x >= spin_at[0]) & (x <= spin_at[-1])
    for incidence, e_t in zip(x[inside], restitution[inside], strict=True):
        a = math.radians(incidence)
        vt = e_t * setup.speed * math.sin(a) - setup.radius * np.interp(incidence, spin_at, spin)
        vn = kharaz.NORMAL_RESTITUTION * setup.speed * math.cos(a)
        assert math.degrees(math.atan2(vt, vn)) == pytest.approx(
            np.interp(incidence, at, angle), abs=3.0
        )


def test_the_laws_compared_are_those_whose_tags_treat_one_frictional_planar_contact():
    laws = kc.frictional_laws()
    assert {*RIGID, "jia", "compliant"} <= set(laws)
    assert not {"newton", "poisson", "sequential"} & set(laws)
    assert kc.hertz_stiffness() == pytest.approx(4.197e9, rel=1e-3)


def test_in_the_sliding_range_the_rigid_laws_meet_the_measured_restitution_and_spin():
    """Per digitized point from 40 degrees (nominal): e_t within 0.01, spin within 10 %."""
    sliding = kc.digitized_incidences()[kc.range_of(kc.digitized_incidences()) == "sliding"]
    points = kc.errors(kc.curves(RIGID[:3], sliding))
    points = points[points["range"] == "sliding"]
    restitution = points[points["quantity"] == "tangential_restitution"]
    spin = points[points["quantity"] == "rebound_spin"]
    assert len(restitution) == 3 * 3 and len(spin) == 3 * 3
    assert restitution["error"].abs().max() < 0.01
    assert (spin["error"].abs() / spin["measured"]).max() < 0.10
    table = kc.rms(kc.curves(RIGID[:1], sliding))
    assert list(table.columns) == ["law", "quantity", "range", "rms", "points", "failed"]
    assert set(table["quantity"]) == set(kc.QUANTITIES) and (table["failed"] == 0).all()


def test_in_the_sticking_range_only_the_laws_with_tangential_springs_reverse():
    """Jia's law and the compliant contacts reverse the contact point; rigid laws end at rest."""
    at, _ = kharaz.contact_curve()
    sticking = at[kc.range_of(at) == "sticking"]
    table = kc.curves([*RIGID, "jia"], sticking)
    table = pd.concat([table, kc.law_curve("compliant", [20.0])], ignore_index=True)
    found = kc.reversal(table).set_index("law")
    assert found.loc[["jia", "compliant"], "reverses"].all()
    assert not found.loc[list(RIGID), "reverses"].any()
    rigid = table[table["law"].isin(RIGID)]
    assert rigid["tangential_restitution"].to_numpy() == pytest.approx(5 / 7)
    assert found.loc["jia", "lowest_angle"] == pytest.approx(-9.5, abs=1.0)


def test_a_failed_solve_is_recorded_at_its_point_and_the_curve_goes_on():
    table = kc.law_curve("no_such_law", [10.0, 50.0])
    assert len(table) == 2 and table["error"].str.startswith("UnknownName").all()
    assert table[list(kc.QUANTITIES)].isna().all().all()
    assert (kc.rms(table)["failed"] > 0).all()
    text = kc.summary(table)
    assert "Failed solves" in text and "no_such_law" in text


def test_pybullet_at_its_defaults_slides_with_the_product_of_the_two_bodies_coefficients():
    """The setup carries its geometry (the sphere on the anvil plane), so the engines step it.
    At its defaults Bullet combines the coefficients of the two bodies by their product
    (btManifoldResult's combined friction and restitution; PyBullet Quickstart Guide, the
    ``restitution`` and ``lateralFriction`` of ``changeDynamics``), and the scene's e = 0.98 and
    mu = 0.092 set on both act as e^2 and mu^2: at 45 degrees the sphere slides through the
    impact with Coulomb's impulse ``mu^2 (1 + e^2) m vn``, spin ``5/2 mu^2 (1 + e^2) vn / R`` =
    45.8 rad/s against the 502 rad/s that mu = 0.092 gives and the 595 and 453 measured at 39
    and 50 degrees."""
    pytest.importorskip("pybullet")
    assert "pybullet" in kc.frictional_laws()
    (row,) = kc.law_curve("pybullet", [45.0]).to_dict("records")
    mu, e = kc.FRICTION**2, kc.NORMAL_RESTITUTION**2
    vn = kharaz.SETUP.speed * math.cos(math.radians(45.0))
    assert row["rebound_spin"] == pytest.approx(
        2.5 * mu * (1 + e) * vn / kharaz.SETUP.radius, rel=1e-3
    )
    assert row["tangential_restitution"] == pytest.approx(1 - mu * (1 + e), rel=1e-3)
