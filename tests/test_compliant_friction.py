"""Compliant contacts with tangential springs and Coulomb sliders (the frictional yardstick)."""

import dataclasses
import re

import numpy as np
import pytest

import lawbench
from lawbench.core.transforms import grazing
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
