"""The chain scenes against the equations of Brogliato's lectures.

Source of every expected value: B. Brogliato, *An introduction to impact dynamics* (lectures,
2010), equations (27), (28), (29) and the remarks after (29); the textbook Newton's cradle.
"""

import itertools

import numpy as np
import pytest

import lawbench

E_VALUES = [0.0, 0.5, 1.0]


def eq29(v, e1, e2):
    """Brogliato 2010, eq. (29), typed from the lecture: equal masses, Newton at both contacts."""
    v1, v2, v3 = v
    return np.array(
        [
            ((1 - 2 * e1) * v1 + (1 - e2 + 2 * e1) * v2 + (1 + e2) * v3) / 3,
            ((1 + e1) * v1 + (1 - e2 - e1) * v2 + (1 + e2) * v3) / 3,
            ((1 + e1) * v1 + (1 + 2 * e2 - e1) * v2 + (1 - 2 * e2) * v3) / 3,
        ]
    )


@pytest.mark.parametrize("e1,e2", [(e, e) for e in E_VALUES] + [(0.3, 0.9), (1.0, 0.2)])
@pytest.mark.parametrize("velocities", [(1, 0, 0), (2, -1, 0.5), (0.3, 0.1, -2)])
def test_newton_matches_equation_29(e1, e2, velocities):
    """Newton's law on three equal balls is eq. (29) for any e per contact and velocities."""
    outcome = lawbench.solve("newton", "three_ball_chain", velocities=velocities, e=[e1, e2])
    np.testing.assert_allclose(outcome.v_plus, eq29(velocities, e1, e2), rtol=0, atol=1e-14)


def test_moreau_three_balls_elastic_and_plastic():
    """Moreau at e=1 gives (-1/3, 2/3, 2/3); at e=0 all balls move at 1/3 (lectures after 29)."""
    elastic = lawbench.solve("moreau", "three_ball_chain", e=1)
    np.testing.assert_allclose(elastic.v_plus, [-1 / 3, 2 / 3, 2 / 3], atol=1e-12)
    plastic = lawbench.solve("moreau", "three_ball_chain", e=0)
    np.testing.assert_allclose(plastic.v_plus, [1 / 3] * 3, atol=1e-12)


def test_sequential_newtons_cradle():
    """Left to right with e=1 the first ball stops and the last leaves: (0, 0, 1)."""
    outcome = lawbench.solve("sequential", "three_ball_chain", {"order": "left_to_right"}, e=1)
    np.testing.assert_allclose(outcome.v_plus, [0, 0, 1], atol=1e-15)
    assert [s["contact"] for s in outcome.diagnostics["sequence"]] == [0, 1]


def eq27(m1, m2, e1, e2, q1, q2):
    """Brogliato 2010, eq. (27): wall impact of ball 2, then ball impact (m = m1/m2)."""
    m = m1 / m2
    return np.array(
        [
            (m - e1) / (1 + m) * q1 - e2 * (1 + e1) / (1 + m) * q2,
            m * (1 + e1) / (1 + m) * q1 - e2 * (1 - e1 * m) / (1 + m) * q2,
        ]
    )


def eq28(m1, m2, e1, e2, q1, q2):
    """Brogliato 2010, eq. (28): balls, wall, balls (m = m1/m2)."""
    m = m1 / m2
    a = (m - e1) / (1 + m) * q1 + (1 + e1) / (1 + m) * q2
    b = m * (1 + e1) / (1 + m) * q1 + (1 - e1 * m) / (1 + m) * q2
    return np.array(
        [
            (m - e1) / (1 + m) * a - e2 * (1 + e1) / (1 + m) * b,
            m * (1 + e1) / (1 + m) * a - e2 * (1 - e1 * m) / (1 + m) * b,
        ]
    )


def states(outcome):
    return outcome.path["v"]


MASSES = [(1.0, 1.0), (0.2, 1.0), (3.0, 1.0), (1.0, 7.0)]
RESTITUTION = [(1.0, 1.0), (0.5, 0.8), (0.0, 0.6), (0.9, 0.0)]


@pytest.mark.parametrize(("masses", "e"), list(itertools.product(MASSES, RESTITUTION)))
def test_two_balls_wall_sequences_follow_equations_27_and_28(masses, e):
    """Both contacts approaching, velocities (-2, -1): the states after the first binary
    impacts are eq. (27) (wall first) and eq. (28) (balls, wall, balls), for any masses and e.
    """
    velocities = [-2.0, -1.0]
    args = (*masses, *e, *velocities)
    orders = {"right_to_left": ([1, 0], 2, eq27), "left_to_right": ([0, 1, 0], 3, eq28)}
    for order, (first_contacts, state, equation) in orders.items():
        outcome = lawbench.solve(
            "sequential",
            "two_balls_wall",
            {"order": order, "path": True},
            masses=masses,
            velocities=velocities,
            e=e,
        )
        contacts = [s["contact"] for s in outcome.diagnostics["sequence"]]
        assert contacts[: len(first_contacts)] == first_contacts
        np.testing.assert_allclose(states(outcome)[state], equation(*args), rtol=1e-13, atol=1e-13)


def test_the_two_orders_end_differently():
    """Sequences of binary impacts depend on their order (lectures: (27) and (28) differ)."""
    params = {"velocities": [-2.0, -1.0], "e": [0.5, 0.8]}
    ends = [
        lawbench.solve("sequential", "two_balls_wall", {"order": order}, **params).v_plus
        for order in ("right_to_left", "left_to_right")
    ]
    assert np.abs(ends[0] - ends[1]).max() > 1e-2


@pytest.mark.parametrize("order", ["left_to_right", "right_to_left", "fastest_first"])
def test_sequential_ends_with_no_contact_approaching(order):
    outcome = lawbench.solve(
        "sequential",
        "ball_chain",
        {"order": order},
        n=8,
        wall=True,
        velocities=[3, -1, 2, 0, 1, -2, 1, 0.5],
        e=0.7,
    )
    problem = lawbench.CASES.get("ball_chain").build(
        n=8, wall=True, velocities=[3, -1, 2, 0, 1, -2, 1, 0.5], e=0.7
    )
    assert (problem.Wn.T @ outcome.v_plus >= -1e-12 * 3).all()
    assert outcome.diagnostics["impacts"] == len(outcome.diagnostics["sequence"])


def test_sequential_reports_an_endless_sequence():
    """Two balls falling on a wall with e=0 need ever more impacts: a clear SolverFailure."""
    with pytest.raises(
        lawbench.SolverFailure,
        match=r"step budget ran out \(5 binary impacts; contacts still approach",
    ):
        lawbench.solve("sequential", "two_balls_wall", {"max_steps": 5}, e=0)


def test_sequential_geometric_sequence_ends():
    """The same scene with the default bound ends: the sequence converges geometrically."""
    outcome = lawbench.solve("sequential", "two_balls_wall", e=0)
    np.testing.assert_allclose(outcome.v_plus, [0, 0], atol=1e-11)
    assert 5 < outcome.diagnostics["impacts"] < 200


@pytest.mark.parametrize("wall", [False, True])
def test_plastic_moreau_on_long_chains(wall):
    """Moreau at e=0: a chain moves with its centre of mass, or rests against the wall."""
    rng = np.random.default_rng(3)
    n = 40
    masses = 10 ** rng.uniform(-1, 1, n)
    velocities = np.sort(rng.uniform(0, 1, n))[::-1]
    outcome = lawbench.solve(
        "moreau",
        "ball_chain",
        n=n,
        masses=masses.tolist(),
        velocities=velocities.tolist(),
        e=0,
        wall=wall,
    )
    expected = 0.0 if wall else masses @ velocities / masses.sum()
    np.testing.assert_allclose(outcome.v_plus, expected, atol=1e-10)
