"""Scale-free solves: a problem of extreme masses or speeds gets the answer of its unit twin.

Newton's, Poisson's, Moreau's and Whittaker's laws, Brach's, the sequential, Darboux-Keller's,
the energetic and Jia's laws read masses and velocities only through ratios (their source
equations are homogeneous: multiplying every mass by ``a`` and every velocity by ``b``
multiplies the impulses by ``a b`` and the post-impact velocities by ``b``, with the stiffness
ratios unchanged). So a problem with masses of 1e-308 kg must give the post-impact velocities
of the same problem with masses of 1 kg, and its impulses scaled.
"""

import dataclasses

import numpy as np
import pytest

import lawbench
from lawbench.core.metric import UNIT_BAND
from lawbench.core.problem import ImpactProblem

SCALED_LAWS = [name for name in lawbench.LAWS.names() if lawbench.LAWS.get(name).scale_free]
SCENES = ("three_ball_chain", "two_balls_wall", "rocking_block", "billiard", "lamina")
# (lightest or heaviest diagonal mass entry, fastest speed) the problem is scaled to: masses
# near the smallest normal double and far beyond 1, tiny and large speeds.
EXTREMES = (
    ("lightest", 1e-307, 1.0),
    ("heaviest", 1e300, 1.0),
    ("heaviest", 1.0, 1e-150),
    ("lightest", 1e-200, 1e100),
    ("heaviest", 2.0**-1000, 2.0**40),
)


def scaled(problem, mass, velocity):
    """The problem with every mass times ``mass`` and every velocity times ``velocity``.

    A stiffness (N/m^exponent) scaled as a mass over a length^(exponent - 1) keeps the
    compression times and the stiffness ratios: the same physics in other units.
    """
    contacts = [
        dataclasses.replace(c, stiffness=c.stiffness * mass / velocity ** (c.exponent - 1.0))
        for c in problem.contacts
    ]
    return ImpactProblem(
        problem.M * mass, problem.Wn, problem.v * velocity, contacts, problem.Wt, problem.bodies
    )


def pairs():
    for scene in SCENES:
        problem = lawbench.CASES.get(scene).build()
        for name in SCALED_LAWS:
            law = lawbench.LAWS.get(name)
            if law.tags.covers(lawbench.CASES.get(scene).requires) and not law.refusal(problem):
                yield name, scene


@pytest.mark.parametrize(("law", "scene"), list(pairs()))
@pytest.mark.parametrize(("which", "extreme", "speed"), EXTREMES)
def test_extreme_scales_give_the_unit_answer_scaled(law, scene, which, extreme, speed):
    """Homogeneity of the laws' equations: v+ scales as v-, impulses as M v-.

    Brogliato 2010, eqs. (16)-(17) and (29), and every law's source: each is linear in the
    impulses and velocities with masses entering through M^-1 only.
    """
    problem = lawbench.CASES.get(scene).build()
    try:
        unit = lawbench.LAWS.get(law).resolve(problem)
    except lawbench.LawbenchError as exc:
        pytest.skip(f"the unit problem is not answered: {exc}")
    masses = np.abs(problem.M.diagonal())
    mass = extreme / (masses.min() if which == "lightest" else masses.max())
    velocity = speed / np.abs(problem.v).max()
    outcome = lawbench.LAWS.get(law).resolve(scaled(problem, mass, velocity))
    assert "units" in outcome.diagnostics
    np.testing.assert_allclose(outcome.v_plus / velocity, unit.v_plus, rtol=1e-9, atol=1e-9)
    impulse = mass * velocity
    np.testing.assert_allclose(outcome.Pn / impulse, unit.Pn, rtol=1e-9, atol=1e-9)
    if unit.Pt.size:
        np.testing.assert_allclose(outcome.Pt / impulse, unit.Pt, rtol=1e-9, atol=1e-9)


def test_a_problem_near_unit_scale_is_solved_as_given():
    """Inside the band no number is rescaled: the answer is bit for bit the plain solve's."""
    problem = lawbench.CASES.get("three_ball_chain").build(masses=[1e-6, 2e-6, 3e-6])
    assert problem.units == (1.0, 1.0, 1.0)
    outcome = lawbench.LAWS.get("poisson").resolve(problem)
    assert "units" not in outcome.diagnostics
    far = lawbench.CASES.get("three_ball_chain").build(masses=[UNIT_BAND * 4] * 3)
    assert far.units[0] == UNIT_BAND * 4


def test_numbers_that_cannot_be_scaled_back_are_refused():
    """An energy unit below the smallest double cannot carry an answer back: refused, named."""
    problem = lawbench.CASES.get("three_ball_chain").build(velocities=[1e-300, 0.0, 0.0])
    with pytest.raises(lawbench.InvalidProblem, match=r"M .* and v .* beyond double precision"):
        lawbench.LAWS.get("newton").resolve(problem)


def test_a_law_that_reads_a_damping_refuses_what_overflows_its_own_units():
    """Compliant contact integrates in the problem's units; 1/M beyond 1e308 is refused."""
    problem = lawbench.CASES.get("three_ball_chain").build(masses=[1e-308] * 3)
    with pytest.raises(lawbench.NotApplicable, match="overflow"):
        lawbench.LAWS.get("compliant").resolve(problem)


def test_masses_at_the_largest_double_take_the_largest_power_of_two_as_unit():
    """Masses of 1.7e308 kg round to 2^1024 kg, which no double holds: the unit is 2^1023."""
    chain = lawbench.CASES.get("three_ball_chain")
    problem = chain.build(masses=[1.7e308] * 3, velocities=[1e-3, 0.0, 0.0])
    assert problem.units[0] == 2.0**1023
    outcome = lawbench.LAWS.get("newton").resolve(problem)
    np.testing.assert_allclose(outcome.v_plus, [-1e-3 / 3, 2e-3 / 3, 2e-3 / 3], rtol=1e-12)


def test_an_answer_that_overflows_in_the_problems_units_names_the_units():
    """W = 2e-200 in the solving mass unit, impulses of 1e400 in the problem's own."""
    problem = ImpactProblem.from_arrays(np.eye(2) * 1e300, [[-1e-100], [1e-100]], [1.0, 0.0])
    with pytest.raises(lawbench.InvalidProblem, match=r"Pn, found in units .* leaves double"):
        lawbench.LAWS.get("newton").resolve(problem)


@pytest.mark.parametrize("light", [1e-20, 1e-200, 1e-308])
def test_a_light_body_beside_heavy_ones_is_no_singular_configuration(light):
    """Masses (light, 1, 1) in the three-ball chain: each contact is judged on its own bodies.

    Newton's law at e = 1 (Brogliato 2010, eq. 29 with unequal masses): the light ball
    bounces back at -v and the heavy ones stay at rest, to within ``light`` (kg/kg).
    """
    problem = lawbench.CASES.get("three_ball_chain").build(masses=[light, 1.0, 1.0])
    outcome = lawbench.LAWS.get("newton").resolve(problem)
    np.testing.assert_allclose(outcome.v_plus, [-1.0, 0.0, 0.0], atol=1e-12)


def test_a_batch_of_extreme_scale_gets_the_scaled_answers():
    """The vectorized path holds in the problems' own units; an extreme batch goes one by one."""
    problem = lawbench.CASES.get("three_ball_chain").build()
    M = np.stack([problem.M, problem.M * 1e-307])
    v = np.stack([problem.v, problem.v])
    batch = lawbench.ProblemBatch(M, np.stack([problem.Wn] * 2), v, {"e": 1.0})
    assert not batch.in_own_units
    outcomes = lawbench.LAWS.get("newton").resolve_batch(batch)
    np.testing.assert_allclose(outcomes.v_plus[1], outcomes.v_plus[0], atol=1e-12)
    np.testing.assert_allclose(outcomes.Pn[1] / 1e-307, outcomes.Pn[0], rtol=1e-9)
