"""The shared event integrator and the one budget mechanism every law spends from."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import lawbench
from lawbench.core.errors import BudgetExceeded, SolverFailure
from lawbench.core.guards import Budget
from lawbench.numerics.integrator import EventIntegrator


def harmonic(t: float, y: np.ndarray) -> np.ndarray:
    """y'' = -y: from (0, 1) the solution is (sin t, cos t)."""
    return np.array([y[1], -y[0]])


def test_an_event_is_located_to_rounding_just_past_its_zero():
    """sin t falls through zero at pi: the state returned lies just past it, on the new sign."""
    event = EventIntegrator(rtol=1e-12, atol=1e-14).to_event(
        harmonic, 0.0, np.array([0.0, 1.0]), lambda t, y: y[:1], direction=-1.0
    )
    assert event.fired == (0,)
    assert event.x == pytest.approx(math.pi, rel=1e-12)
    assert event.y[0] < 0 and abs(event.y[0]) < 1e-11


def test_direction_selects_the_change_of_sign():
    """cos t falls through zero at pi/2 and rises at 3 pi/2; +1 waits for the rise."""
    start = np.array([0.0, 1.0])
    integrator = EventIntegrator(rtol=1e-12, atol=1e-14)
    falling = integrator.to_event(harmonic, 0.0, start, lambda t, y: y[1:], direction=-1.0)
    rising = integrator.to_event(harmonic, 0.0, start, lambda t, y: y[1:], direction=1.0)
    either = integrator.to_event(harmonic, 0.0, start, lambda t, y: y[1:])
    assert falling.x == pytest.approx(math.pi / 2, rel=1e-12)
    assert rising.x == pytest.approx(3 * math.pi / 2, rel=1e-12)
    assert either.x == falling.x


def test_the_first_of_several_events_and_those_simultaneous_with_it():
    """Two functions cross at atan(1 / 0.999) and pi/4: pi/4 first, both within 1e-3."""
    start = np.array([0.0, 1.0])

    def events(t: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[1] - 0.999 * y[0], y[1] - y[0]])

    first = EventIntegrator(rtol=1e-12, atol=1e-14).to_event(harmonic, 0.0, start, events, -1.0)
    assert first.fired == (1,) and first.x == pytest.approx(math.pi / 4, rel=1e-12)
    both = EventIntegrator(rtol=1e-12, atol=1e-14, simultaneous=1e-3).to_event(
        harmonic, 0.0, start, events, -1.0
    )
    assert both.fired == (1, 0)


def test_stacked_event_functions_find_the_same_event_as_one_state_at_a_time():
    """cos t + 0.999 dips below zero for 0.09 around pi, just before sin t falls through zero
    there: the stacked calls (one a step, the step's samples at once) meet what one call a
    sample meets, at the same point and state."""

    def events(t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.stack([y[..., 0], y[..., 1] + 0.999], axis=-1)

    calls = []

    def counted(t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        calls.append(np.shape(y))
        return events(t, y)

    start = np.array([0.0, 1.0])
    one = EventIntegrator(rtol=1e-12, atol=1e-14, samples=4)
    stacked = EventIntegrator(rtol=1e-12, atol=1e-14, samples=4, stacked=True)
    expected = one.to_event(harmonic, 0.0, start, events, -1.0)
    found = stacked.to_event(harmonic, 0.0, start, counted, -1.0)
    assert expected.fired == (1,) and expected.x == pytest.approx(math.acos(-0.999), rel=1e-9)
    assert found.fired == expected.fired and found.x == expected.x
    assert np.array_equal(found.y, expected.y)
    assert (4, 2) in calls


def test_no_event_before_the_end_returns_the_end_and_every_step_is_seen():
    """No event before x_end: the state there, nothing fired; the steps seen are contiguous."""
    seen = []
    event = EventIntegrator().to_event(
        harmonic,
        0.0,
        np.array([0.0, 1.0]),
        lambda t, y: np.array([y[0] + 2.0]),
        x_end=10.0,
        on_step=lambda dense, t_old, t: seen.append((t_old, t)),
    )
    assert event.fired == () and event.x == 10.0
    np.testing.assert_allclose(event.y, [np.sin(10.0), np.cos(10.0)], rtol=1e-6)
    assert seen[0][0] == 0.0 and seen[-1][1] == 10.0
    assert all(a[1] == b[0] for a, b in itertools.pairwise(seen))


@pytest.mark.parametrize(
    ("limits", "option"),
    [({"max_steps": 3}, "max_steps"), ({"max_events": 2}, "max_events")],
)
def test_the_open_budget_bounds_steps_and_events(limits, option):
    """Steps and events are spent from the budget the solve opened; it names what ran out."""
    integrator = EventIntegrator(rtol=1e-12, atol=1e-14)
    with Budget("a law", **limits):
        with pytest.raises(BudgetExceeded, match=f"a law: .* budget ran out .*{option}") as info:
            y = np.array([0.0, 1.0])
            for _ in range(10):  # each event is a zero of sin t
                event = integrator.to_event(harmonic, 0.0, y, lambda t, y: y[:1])
                y = event.y
    assert info.value.budget == option and info.value.spent_s >= 0


def test_the_time_budget_stops_a_long_integration():
    """An integration that would take long stops at max_seconds, naming it."""
    with Budget("a law", max_seconds=1e-3):
        with pytest.raises(BudgetExceeded, match=r"time budget ran out \(0.001 s") as info:
            EventIntegrator(rtol=1e-13, atol=1e-15).to_event(
                harmonic, 0.0, np.array([0.0, 1.0]), lambda t, y: np.array([1.0]), x_end=1e9
            )
    assert info.value.budget == "max_seconds" and info.value.spent_s >= 1e-3


def test_every_law_has_a_time_budget():
    """Every registered law declares ``max_seconds`` (given by the law protocol)."""
    for law in lawbench.LAWS.values():
        assert "max_seconds" in [spec.name for spec in law.options], law.name


# A scene on which each law with a step budget steps: integrator steps, fixed-point steps of
# Coulomb's law, binary impacts, an engine's steps.
STEPPING = {
    "compliant": ("three_ball_chain", {}, {}),
    "lzb": ("three_ball_chain", {}, {}),
    "jia": ("two_balls_wall", {}, {}),
    "darboux_keller": None,
    "moreau": ("lamina", {}, {"friction": "coulomb", "method": "fixed_point"}),
    "sequential": ("two_balls_wall", {"e": 0.0}, {}),
    "drake": ("three_ball_chain", {}, {}),
    "mujoco": ("three_ball_chain", {}, {}),
    "pybullet": ("three_ball_chain", {}, {}),
}


@pytest.mark.parametrize("name", sorted(STEPPING))
def test_every_step_budget_is_spent_through_the_solve_budget(name):
    """``max_steps = 1`` stops each law that steps, with `BudgetExceeded` naming max_steps."""
    law = lawbench.LAWS.get(name)
    assert "max_steps" in [spec.name for spec in law.options]
    if STEPPING[name] is None:
        problem = turning_slip_problem()
        options = {}
    else:
        case, params, options = STEPPING[name]
        problem = lawbench.CASES.get(case).build(**params)
    with pytest.raises(BudgetExceeded, match=r"step budget ran out \(1 ") as info:
        law.resolve(problem, max_steps=1, **options)
    assert info.value.budget == "max_steps" and info.value.amount == 1


def test_the_laws_with_a_step_budget_are_all_tested():
    """A law that declares max_steps joins the table above."""
    declared = {
        law.name
        for law in lawbench.LAWS.values()
        if any(s.name == "max_steps" for s in law.options)
    }
    assert declared == set(STEPPING)


def turning_slip_problem() -> lawbench.ImpactProblem:
    """One spatial frictional contact whose slip direction turns (Darboux-Keller's ODE)."""
    rng = np.random.default_rng(1)
    A = rng.normal(size=(4, 4))
    Wn, v = rng.normal(size=(4, 1)), rng.normal(size=4)
    return lawbench.ImpactProblem(
        M=A @ A.T + 1.2 * np.eye(4),
        Wn=Wn,
        Wt=rng.normal(size=(4, 2)),
        v=-v if Wn[:, 0] @ v > 0 else v,
        contacts=[lawbench.Contact(e=0.5, mu=0.8)],
    )


def test_event_functions_that_leave_floating_point_are_a_solver_failure():
    """An event function that overflows has no sign: the solve fails and says where."""

    def overflowing(t: float, y: np.ndarray) -> np.ndarray:
        force = np.exp(800.0 * y[0])  # inf once sin t passes about 0.89
        return np.array([force - force])

    with Budget("a law"), np.errstate(over="ignore", invalid="ignore"):
        with pytest.raises(SolverFailure, match="a law: DOP853: event functions not finite"):
            EventIntegrator(rtol=1e-12, atol=1e-14).to_event(
                harmonic, 0.0, np.array([0.0, 1.0]), overflowing, x_end=3.0
            )


@pytest.mark.slow
def test_a_compliant_contact_whose_force_overflows_fails_with_the_reason():
    """Hertz's force at exponent 1e6 overflows in the billiard's contacts: exit 4, not 1."""
    with pytest.raises(SolverFailure, match="event functions not finite"):
        lawbench.solve("compliant", "billiard", exponent=1e6)
