"""Continuity in the initial data, kinetic angles and energy dispersion."""

import dataclasses

import numpy as np
import pytest

import lawbench
from lawbench.checks.continuity import jumps
from lawbench.checks.dispersion import dispersion_index
from lawbench.checks.gaps import resolve_with_gaps
from lawbench.core.mechanics import energy_shares, kinetic_angles

# Both contacts approach, so either can close first.
HEAD_ON = {"velocities": [1.0, 0.0, -1.0], "e": [0.5]}


def gapped(problem, first, size):
    gaps = np.full(problem.m, size)
    gaps[first] = 0.0
    return dataclasses.replace(problem, gaps=gaps)


@pytest.mark.parametrize("law", ["newton", "poisson", "moreau"])
def test_rigid_laws_tend_to_binary_impacts_in_the_closing_order(law):
    """Brogliato 2010, 'kinetic angle and continuity' (Paoli): on the three-ball chain the
    angle between the contacts is 120 degrees, so under vanishing gaps a rigid law meets the
    contacts one at a time: binary impacts in the closing order. The two orders disagree and
    neither is the simultaneous outcome: discontinuous.
    """
    trial = lawbench.evaluate(law, "three_ball_chain", **HEAD_ON)
    order = {0: "left_to_right", 1: "right_to_left"}
    ends = {}
    for first in (0, 1):
        binary = lawbench.solve(
            "sequential", "three_ball_chain", {"order": order[first]}, **HEAD_ON
        ).v_plus
        for size in (1e-2, 1e-4, 1e-6):
            moved = resolve_with_gaps(trial.law, gapped(trial.problem, first, size), {})
            np.testing.assert_allclose(moved.v_plus, binary, atol=1e-12)
        ends[first] = binary
    simultaneous = trial.outcome.v_plus
    assert np.abs(ends[0] - ends[1]).max() > 0.05
    assert min(np.abs(end - simultaneous).max() for end in ends.values()) > 0.05
    result = lawbench.CHECKS["continuity"](trial)
    assert result.passed is False
    assert "120.0 deg" in result.detail


def test_compliant_contacts_are_continuous_in_the_gaps():
    """Compliant contacts resolve time inside the impact: as the gaps shrink the outcome
    converges to the zero-gap one (PHYSICS_NOTES, 'Continuity')."""
    trial = lawbench.evaluate("compliant", "three_ball_chain", **HEAD_ON)
    found = jumps(trial, (1e-2, 1e-4, 1e-6))
    assert found["gaps"][0] > found["gaps"][1] > found["gaps"][2]
    assert found["gaps"][2] < 1e-4
    assert lawbench.CHECKS["continuity"](trial).passed is True


@pytest.mark.parametrize("law", ["moreau", "lzb", "compliant"])
def test_velocity_perturbations_at_zero_gaps_are_continuous(law):
    trial = lawbench.evaluate(law, "three_ball_chain", **HEAD_ON)
    found = jumps(trial, (1e-2, 1e-4, 1e-6))
    assert found["velocities"][2] < 1e-5
    assert found["velocities"][0] > found["velocities"][2]


@pytest.mark.parametrize("masses", [(1.0, 1.0), (0.2, 3.0), (5.0, 0.5)])
def test_kinetic_angle_of_two_balls_on_a_wall(masses):
    """Brogliato 2010, eq. (26): cos(theta_12) = -sqrt(m1 / (m1 + m2))."""
    problem = lawbench.CASES.get("two_balls_wall").build(masses=list(masses))
    m1, m2 = masses
    expected = np.degrees(np.arccos(-np.sqrt(m1 / (m1 + m2))))
    assert kinetic_angles(problem)[0, 1] == pytest.approx(expected, abs=1e-10)


def test_dispersion_between_the_two_limits():
    """Three equal balls, (1, 0, 0): sequential impacts give the textbook non-dispersive
    outcome (all energy in ball 3), Moreau at e = 1 the dispersive (-1/3, 2/3, 2/3), and the
    compliant model moves from the first to the second as the stiffness ratio goes from 0 to
    infinity (Brogliato 2010, 'Three-ball chain with linear springs').
    """
    problem = lawbench.CASES.get("three_ball_chain").build()
    sequential = energy_shares(problem, lawbench.solve("sequential", "three_ball_chain").v_plus)
    assert dispersion_index(sequential) == pytest.approx(0.0, abs=1e-12)
    moreau = energy_shares(problem, lawbench.solve("moreau", "three_ball_chain").v_plus)
    np.testing.assert_allclose(list(moreau.values()), [1 / 9, 4 / 9, 4 / 9], atol=1e-12)
    indices = [
        dispersion_index(
            energy_shares(
                problem,
                lawbench.solve(
                    "compliant",
                    "three_ball_chain",
                    {"model": "hertz"},
                    exponent=1,
                    stiffness_ratio=ratio,
                ).v_plus,
            )
        )
        for ratio in (1e-4, 1e-2, 1.0, 1e2, 1e4)
    ]
    assert indices[0] < 1e-3
    assert indices[-1] == pytest.approx(dispersion_index(moreau), abs=1e-3)
    assert indices[0] < indices[2] < indices[-1]


def test_dispersion_check_compares_with_the_compliant_model():
    sequential = lawbench.CHECKS["dispersion"](lawbench.evaluate("sequential", "three_ball_chain"))
    moreau = lawbench.CHECKS["dispersion"](lawbench.evaluate("moreau", "three_ball_chain"))
    assert sequential.passed is True
    assert moreau.passed is False
    assert "index" in moreau.detail


@pytest.mark.parametrize(("width", "height"), [(0.5, 1.0), (1.0, 1.0), (1.0, 2**0.5), (2.0, 1.0)])
def test_kinetic_angle_of_the_rocking_block(width, height):
    """Brogliato 2010, the rocking block: constraints h1,2 = y - (l/2) cos(theta) -+ (L/2)
    sin(theta), l the height and L the width, orthogonal in the kinetic metric iff l = sqrt(2) L.
    With I = m (l^2 + L^2) / 12 their angle is cos(theta_12) = (l^2 - 2 L^2) / (l^2 + 4 L^2).
    """
    problem = lawbench.CASES.get("rocking_block").build(width=width, height=height, mu=0.0)
    cosine = (height**2 - 2 * width**2) / (height**2 + 4 * width**2)
    assert kinetic_angles(problem)[0, 1] == pytest.approx(np.degrees(np.arccos(cosine)), abs=1e-9)


def test_a_cell_pays_for_its_perturbed_solves_once(monkeypatch):
    """The continuity check and the jumps measure of one cell share the perturbed solves; a
    new trial, or other sizes, solves again."""
    trial = lawbench.evaluate("newton", "three_ball_chain")
    law = type(trial.law)
    calls = []
    resolve = law.resolve
    monkeypatch.setattr(
        law, "resolve", lambda self, *a, **k: calls.append(1) or resolve(self, *a, **k)
    )
    first = jumps(trial, (1e-2, 1e-4))
    solved = len(calls)
    assert solved > 0
    assert jumps(trial, (1e-2, 1e-4)) is first
    assert len(calls) == solved
    jumps(trial, (1e-2,))
    jumps(lawbench.evaluate("newton", "three_ball_chain"), (1e-2, 1e-4))
    assert len(calls) > solved + solved // 2


def test_a_perturbed_solve_has_a_budget_in_proportion_to_the_original(monkeypatch):
    """A perturbed problem is the size of the original: its solve gets PERTURBED_RATIO times the
    original's wall time, within [PERTURBED_FLOOR_S, PERTURBED_SECONDS]."""
    from lawbench.checks import continuity

    trial = lawbench.evaluate("newton", "three_ball_chain")
    law = type(trial.law)
    limits = []
    resolve = law.resolve
    monkeypatch.setattr(
        law,
        "resolve",
        lambda self, *a, **k: limits.append(k.get("max_seconds")) or resolve(self, *a, **k),
    )
    for spent, expected in ((1e-4, continuity.PERTURBED_FLOOR_S), (0.1, 2.0), (10.0, 5.0)):
        trial.outcome.diagnostics["wall_time_s"] = spent
        limits.clear()
        continuity._jumps(trial, (1e-2,))
        assert limits and all(limit == pytest.approx(expected) for limit in limits)


def test_a_ground_truth_and_a_tightest_knob_naming_the_same_options_are_solved_once(
    monkeypatch,
):
    """Re-solves are kept under the law's complete options: {'tol': 1e-12} and every option
    spelled out at those values are one answer."""
    from lawbench.checks import measures, solved

    problem = lawbench.CASES.get("three_ball_chain").build()
    law = lawbench.LAWS.get("compliant")
    calls = []
    resolve = type(law).resolve
    monkeypatch.setattr(
        type(law), "resolve", lambda self, *a, **k: calls.append(1) or resolve(self, *a, **k)
    )
    monkeypatch.setattr(solved, "_SOLVED", {})
    short = measures._solve("compliant", {"tol": 1e-9}, problem)
    spelled = measures._solve("compliant", law.option_values({"tol": 1e-9}), problem)
    assert len(calls) == 1 and np.array_equal(short, spelled)


def test_the_ground_truth_s_model_measured_against_itself_is_not_solved_again(monkeypatch):
    """The compliant law at the ground truth's options is its own truth: its model error is 0
    from its own answer, with no second solve; its numerical error still solves the tighter
    knob."""
    from lawbench.checks import measures, solved
    from lawbench.core.trial import make_trial

    trial = make_trial("compliant", "three_ball_chain", options={"max_seconds": 30.0})
    law = type(trial.law)
    calls = []
    resolve = law.resolve
    monkeypatch.setattr(
        law, "resolve", lambda self, *a, **k: calls.append(1) or resolve(self, *a, **k)
    )
    monkeypatch.setattr(solved, "_SOLVED", {})
    assert measures.model_error(trial) == 0.0 and not calls
    assert 0.0 < measures.numerical_error(trial) < 1e-6 and len(calls) == 1
