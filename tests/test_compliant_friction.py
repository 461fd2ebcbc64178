"""Compliant contacts with tangential springs and Coulomb sliders (the frictional yardstick)."""

import dataclasses
import re

import numpy as np
import pytest

import lawbench
from lawbench.core.transforms import grazing
from lawbench.measurements import MEASUREMENTS
from lawbench.views import cli

FRICTIONAL = [case.name for case in lawbench.CASES.values() if case.requires.friction]
SINGLE_CONTACT = [name for name in FRICTIONAL if lawbench.CASES[name].build().m == 1]


def with_mu(problem, mu):
    """``problem`` with every contact's friction coefficient ``mu``."""
    contacts = tuple(dataclasses.replace(c, mu=mu) for c in problem.contacts)
    return dataclasses.replace(problem, contacts=contacts)


def relative(a, b, scale):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(scale).max())


def test_every_single_contact_frictional_scene_is_covered():
    assert {"falling_rod", "lamina", "double_pendulum", "sphere_wall"} <= set(SINGLE_CONTACT)
    assert {"bouncing_ball", "bouncing_pencil"} <= set(SINGLE_CONTACT)


@pytest.mark.parametrize("case", SINGLE_CONTACT)
def test_linear_springs_at_e_1_agree_with_jia(case):
    """Jia, IJRR 32(1) 2013: the contact point a massless particle held by a linear normal
    spring and tangential springs of stiffness k / eta0^2, sticking while the tangential
    spring force is below mu times the normal one. Integrated in time here and in the normal
    impulse by jia, the same springs must give the same outcome."""
    compliant = lawbench.evaluate("compliant", case, {"model": "kelvin_voigt", "tol": 1e-10}, e=1)
    jia = lawbench.solve("jia", case, {"tol": 1e-12}, e=1)
    v = compliant.problem.v
    assert relative(compliant.outcome.v_plus, jia.v_plus, v) <= 1e-6
    assert relative(compliant.outcome.Pt, jia.Pt, jia.Pn) <= 1e-6


@pytest.mark.parametrize("case", FRICTIONAL)
def test_every_frictional_scene_is_answered_at_its_defaults(case, capsys):
    """``lawbench solve compliant SCENE`` exits 0 on every frictional scene, with no energy
    created and every tangential impulse in its cone."""
    assert cli.main(["solve", "compliant", case]) == 0
    report = capsys.readouterr().out
    assert re.search(r"energy_gain\s+holds", report)
    assert re.search(r"friction_cone\s+holds", report)


@pytest.mark.parametrize("mu", [0.0, 1e-3, 1.0, 1000.0])
@pytest.mark.parametrize("case", FRICTIONAL)
def test_never_creates_energy_and_holds_the_cone(case, mu):
    """Brogliato 2010, compliant contacts: springs give back what they stored, dashpots and
    sliders only take; Coulomb's cone bounds the friction force at every instant, so the
    impulse too."""
    problem = with_mu(lawbench.CASES[case].build(), mu)
    trial = lawbench.evaluate("compliant", problem, {"tol": 1e-8})
    outcome = trial.outcome
    assert outcome.dT <= 1e-9 * outcome.T_minus
    checks = lawbench.run_checks(trial, checks=["energy_gain", "friction_cone"])
    assert str(checks["energy_gain"].verdict) == "holds"
    assert str(checks["friction_cone"].verdict) in ("holds", "refused")


@pytest.mark.parametrize("mu", [0.3, 1000.0])
@pytest.mark.parametrize("case", ["falling_rod", "lamina", "sphere_wall", "bouncing_pencil"])
def test_without_damping_only_the_sliders_take_energy(case, mu):
    """At e = 1 with linear springs the contact is springs and a slider: the kinetic energy
    lost is the sliders' work, to the tolerance. Even where friction never limits the
    compression, the slider slips as the cone closes with the normal force at the end, to
    release what the tangential spring still holds."""
    outcome = lawbench.solve("compliant", case, {"model": "kelvin_voigt"}, e=1, mu=mu)
    lost = outcome.T_minus - outcome.T_plus
    assert abs(lost - outcome.diagnostics["slip_work"]) <= 1e-9 * outcome.T_minus
    if outcome.diagnostics["slip_phases"] == 0:
        assert abs(lost) <= 1e-9 * outcome.T_minus
    else:
        assert lost > 0


def test_a_contact_that_opens_releases_its_springs():
    """The path's stored energy (normal and tangential springs) is zero once the contact has
    opened, whatever the tangential spring held."""
    outcome = lawbench.solve("compliant", "falling_rod", {"path": True, "model": "kelvin_voigt"})
    stored = outcome.path["stored_energy"]
    assert stored.max() > 0
    assert stored[-1].max() <= 1e-9 * stored.max()


def test_a_frictionless_contact_among_frictional_ones_has_no_tangential_force():
    """A body sliding along x on two walls, one smooth (mu = 0) and one rough (mu = 0.3): the
    smooth wall's tangential spring stuck, with no cone to bound it, and pushed back with
    |Pt| = 1.45 where mu Pn = 0. Every rigid law gives it no tangential impulse."""
    problem = lawbench.ImpactProblem.from_arrays(
        np.eye(3),
        [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        [1.0, -1.0, -1.0],
        [[1.0, 1.0], [0.0, 0.0], [0.0, 0.0]],
        e=1.0,
        mu=[0.0, 0.3],
    )
    trial = lawbench.evaluate("compliant", problem)
    assert trial.outcome.Pt[0] == 0.0
    assert lawbench.run_checks(trial)["friction_cone"].passed
    rigid = lawbench.solve("moreau", problem)
    np.testing.assert_allclose(trial.outcome.Pt, rigid.Pt, rtol=1e-6, atol=1e-8)


def test_several_spatial_contacts_at_once():
    """The billiard shot: cue-ball and ball-table contacts, both frictional, in 3D."""
    trial = lawbench.evaluate("compliant", "billiard", {"tol": 1e-8})
    assert trial.problem.m == 2 and trial.problem.d == 2
    assert "tangential springs" in trial.outcome.diagnostics["formulation"]
    checks = lawbench.run_checks(trial)
    assert {str(r.verdict) for r in checks.values()} <= {"holds", "refused"}


@pytest.mark.parametrize("e", [0.0, 1.0])
def test_a_grazing_slip_costs_no_more_steps_than_a_steep_one(e):
    """A rod that grazes the floor (approach 1e-12 m/s, its sliding kept) slides through the
    whole impact, so |Pt| = mu Pn (Coulomb, Brogliato 2010), and its stretch, on the cone,
    grows with the cone alone: the integration takes the steps of a 1e-4 m/s approach, not the
    thousands a slip 1e12 times faster than the cone's growth would force if its rounding
    entered the stretch."""
    steps = {}
    for speed in (1e-4, 1e-12):
        problem = grazing(lawbench.CASES["falling_rod"].build(e=e), speed)
        outcome = lawbench.LAWS["compliant"].resolve(problem)
        steps[speed] = outcome.diagnostics["steps"]
        mu = problem.contacts[0].mu
        np.testing.assert_allclose(np.abs(outcome.Pt), mu * outcome.Pn, rtol=1e-9)
    assert steps[1e-12] <= 2 * steps[1e-4]


def cube_corner(ratio):
    """Toss 50's first impact in the ContactNets cube set: one corner on the table, z up.

    A cube of 0.37 kg and side 0.1048 m (Pfrommer, Halm and Posa, CoRL 2020), the corner at
    ``r`` from its centre, coordinates ``(v_centre, omega)``; each Jacobian column is
    ``(e, r x e)``, as the set builds it, with e = 0.35, mu = 0.25, stiffness 1e6 and the
    tangential stiffness ratio ``ratio``.
    """
    r = np.array([0.00629, 0.00859, -0.0901])
    M = np.diag([0.37] * 3 + [6.773e-4] * 3)
    Wn, tx, ty = (np.concatenate([axis, np.cross(r, axis)]) for axis in np.eye(3)[[2, 0, 1]])
    v = np.array([0.398, -0.963, -1.044, 4.691, 2.156, -0.539])
    return lawbench.ImpactProblem.from_arrays(
        M,
        Wn[:, None],
        v,
        np.column_stack([tx, ty]),
        e=0.35,
        mu=0.25,
        stiffness=1e6,
        tangential_stiffness_ratio=ratio,
    )


@pytest.mark.parametrize("ratio", [0.25, 0.1])
def test_a_slip_stopping_on_an_unloading_cone_hands_back_to_its_stretch(ratio):
    """A stiff tangential spring keeps the cube corner's cone narrow, where a 3D slip follows
    its velocity. As the contact unloads, the cone shrinks and the slip slows to a stop: the
    friction force along the slip velocity would turn over at once there, so the slip hands
    back to the spring and slider first. The impact ends in a few hundred steps (it ran out of
    its 60 s budget chattering about zero slip), creates no energy, keeps the friction in its
    cone and the momentum the contact cannot change."""
    trial = lawbench.evaluate("compliant", cube_corner(ratio), {"tol": 1e-6})
    assert trial.outcome.diagnostics["steps"] <= 1500
    checks = lawbench.run_checks(trial, checks=["energy_gain", "friction_cone", "momentum"])
    assert {name: str(result.verdict) for name, result in checks.items()} == {
        "energy_gain": "holds",
        "friction_cone": "holds",
        "momentum": "holds",
    }


@pytest.mark.slow
@pytest.mark.parametrize("ratio", [0.05, 0.1, 0.25, 0.5, 2.0, 10.0])
def test_the_cube_corner_converges_with_tol_at_every_tangential_stiffness(ratio):
    """Across the tangential stiffness ratios a fit may try, the answer at tol is within tol
    (relative to the largest pre-impact velocity) of the answer at tol = 1e-11: the slip
    follows its velocity only where the stretch's lag is below tol^(1/2)."""
    problem = cube_corner(ratio)
    reference = lawbench.solve("compliant", problem, {"tol": 1e-11}).v_plus
    for tol in (1e-6, 1e-8):
        outcome = lawbench.solve("compliant", problem, {"tol": tol})
        assert relative(outcome.v_plus, reference, problem.v) <= tol


def test_a_slip_that_stops_at_a_graze_sticks_without_chattering():
    """The ContactNets cube's first impact of toss 473 (Pfrommer, Halm and Posa, CoRL 2020;
    the set as shipped), at e = 0.363, mu = 0.229 and tangential stiffness ratio 2: the slip
    speed falls to zero and the sticking stretch then stays on its cone to second order. Where
    the integration's own error carried it past the cone by 1e-12 of the radius, the contact
    restarted hundreds of times a second between a stick leaving its cone and a slip running
    backward, without advancing. The stretch now reaches its cone past the integration's
    tolerance: the impact ends in a few events, within 1e-7 (relative to the largest
    pre-impact velocity) of its answer at tol = 1e-10, and holds the checks."""
    impact = next(i for i in MEASUREMENTS.get("cube").impacts if i.index == 473)
    contact = dataclasses.replace(
        impact.problem.contacts[0], e=0.363, mu=0.229, tangential_stiffness_ratio=2.0
    )
    problem = dataclasses.replace(impact.problem, contacts=(contact,))
    trial = lawbench.evaluate("compliant", problem, {"tol": 1e-6, "max_seconds": 20.0})
    assert trial.outcome.diagnostics["events"] <= 20
    reference = lawbench.solve("compliant", problem, {"tol": 1e-10}).v_plus
    assert relative(trial.outcome.v_plus, reference, problem.v) <= 1e-7
    checks = lawbench.run_checks(trial, checks=["energy_gain", "friction_cone", "momentum"])
    assert {str(result.verdict) for result in checks.values()} == {"holds"}


def test_a_tangential_spring_beyond_double_precision_is_refused_by_name():
    """A force exponent of 5e-324 makes the tangential stiffness n k d^(n - 1) subnormal and
    its Coulomb bound infinite: scipy's integrator was handed a non-finite state."""
    with pytest.raises(lawbench.NotApplicable, match="tangential spring"):
        lawbench.solve("compliant", "billiard", exponent=5e-324)
