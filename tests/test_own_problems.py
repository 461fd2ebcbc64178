"""A problem of the user's own, built from arrays, goes through every public entry point."""

import numpy as np
import pytest

import lawbench
from lawbench.core.verdicts import Verdict


def two_balls_and_a_wall(e=0.9, mu=None):
    """Ball 1 (1 kg) on ball 2 (2 kg) on a wall, both moving left; contacts ball-ball, wall."""
    M = np.diag([1.0, 2.0])
    Wn = np.array([[-1.0, 0.0], [1.0, 1.0]])
    coefficients = {"e": e} if mu is None else {"e": e, "mu": mu}
    return lawbench.ImpactProblem.from_arrays(M, Wn, [-2.0, -1.0], **coefficients)


def test_from_arrays_broadcasts_scalars_and_takes_one_value_per_contact():
    problem = lawbench.ImpactProblem.from_arrays(
        np.eye(2), [[-1.0, 0.0], [1.0, 1.0]], [-2.0, -1.0], e=[0.5, 1.0], stiffness=3.0
    )
    assert [c.e for c in problem.contacts] == [0.5, 1.0]
    assert [c.stiffness for c in problem.contacts] == [3.0, 3.0]
    with pytest.raises(lawbench.InvalidProblem, match="e has 3 values, expected 1 or 2"):
        lawbench.ImpactProblem.from_arrays(
            np.eye(2), [[-1.0, 0.0], [1.0, 1.0]], [0, 0], e=[1, 1, 1]
        )
    with pytest.raises(lawbench.InvalidProblem, match="unknown contact coefficient 'restitution'"):
        lawbench.ImpactProblem.from_arrays(np.eye(1), [[1.0]], [-1.0], restitution=1.0)
    with pytest.raises(lawbench.InvalidProblem, match=r"contacts\[0\]\.e = 1\.5"):
        lawbench.ImpactProblem.from_arrays(np.eye(1), [[1.0]], [-1.0], e=1.5)


@pytest.mark.parametrize("law", lawbench.LAWS.names())
def test_every_law_that_treats_a_user_problem_solves_and_checks_it(law):
    problem = two_balls_and_a_wall()
    try:
        trial = lawbench.evaluate(law, problem)
    except lawbench.NotApplicable as refusal:
        assert law in str(refusal)
        return
    assert trial.case is None and trial.scene == "problem"
    assert np.array_equal(lawbench.solve(law, problem).v_plus, trial.outcome.v_plus)
    results = lawbench.run_checks(trial)
    assert set(results) == set(lawbench.checks.SINGLE_SOLVE)
    # No scene: the references do not apply; momentum is checked on the free directions.
    assert results["reference"].verdict == Verdict.REFUSED
    for result in results.values():
        assert result.verdict in (Verdict.HOLDS, Verdict.REFUSED, Verdict.LAW_PROPERTY), (
            result.name,
            result.detail,
        )


def test_momentum_of_a_free_chain_is_checked_without_a_scene():
    """Three free balls: the total momentum is conserved (W.T a = 0 for a = (1, 1, 1))."""
    problem = lawbench.ImpactProblem.from_arrays(
        np.diag([1.0, 2.0, 3.0]), [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]], [1.0, 0.0, -0.5]
    )
    result = lawbench.run_checks(lawbench.evaluate("moreau", problem))["momentum"]
    assert result.verdict == Verdict.HOLDS and result.value <= 1e-12


def test_scene_parameters_with_a_problem_are_an_error():
    with pytest.raises(lawbench.InvalidProblem, match="given with a problem"):
        lawbench.evaluate("newton", two_balls_and_a_wall(), e=0.5)


def test_a_law_finding_covers_a_user_problem_through_its_region():
    """Newton with a separating closed contact: the tensile impulse carries its verdict."""
    M, Wn = np.eye(3), [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]]
    problem = lawbench.ImpactProblem.from_arrays(M, Wn, [1.0, 0.0, 0.75], e=1.0)
    results = lawbench.run_checks(lawbench.evaluate("newton", problem))
    assert results["impulse_sign"].verdict == Verdict.LAW_PROPERTY
    assert "separates before the impact" in results["impulse_sign"].claim.region.text


def test_newtons_tensile_impulse_and_energy_gain_where_one_contact_lifts_another():
    """Both contacts approach, and an impulse at the first lifts the second (G_01 = 1 > 0):
    Newton's law holds the second at un+ = -e un- with a tensile impulse, and with e = (1, 0)
    that impulse adds to the energy (dT = sum Pn_j (1 - e_j) un-_j / 2 > 0). The law's theory,
    where the verdicts were a numerical failure and an unexplained gain (and ``lawbench
    solve`` refused the answer, exit 4)."""
    problem = lawbench.ImpactProblem.from_arrays(
        np.eye(2), [[1.0, 1.0], [0.0, 1.0]], [-1.0, 0.99], e=[1.0, 0.0]
    )
    results = lawbench.run_checks(lawbench.evaluate("newton", problem))
    for check in ("impulse_sign", "energy_gain"):
        assert results[check].passed is False
        assert results[check].verdict == Verdict.LAW_PROPERTY
        assert "lifts the other" in results[check].claim.region.text


@pytest.mark.parametrize("law", sorted(lawbench.LAWS.names()))
def test_a_separating_contact_is_treated_by_a_stated_rule(law):
    """Every law states how it treats a closed contact that separates before the impact, and
    the outcome names the contacts and the rule; a negative impulse carries its verdict."""
    M, Wn = np.eye(3), [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]]
    problem = lawbench.ImpactProblem.from_arrays(M, Wn, [1.0, 0.0, 0.75], e=1.0)
    try:
        trial = lawbench.evaluate(law, problem)
    except lawbench.NotApplicable:
        return
    assert trial.outcome.diagnostics["separating_contacts"] == [1]
    assert trial.outcome.diagnostics["separating_rule"]
    if (trial.outcome.Pn < 0).any():
        sign = lawbench.run_checks(trial)["impulse_sign"]
        assert sign.verdict in (Verdict.LAW_PROPERTY, Verdict.NUMERICAL_FAILURE)
        assert sign.claim is not None


def test_a_law_that_states_no_rule_refuses_separating_contacts():
    """A law without a rule for separating contacts says so instead of answering."""

    class Silent(type(lawbench.LAWS.get("newton"))):
        separating_rule = ""

    M, Wn = np.eye(3), [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]]
    problem = lawbench.ImpactProblem.from_arrays(M, Wn, [1.0, 0.0, 0.75], e=1.0)
    with pytest.raises(lawbench.NotApplicable, match=r"closed contacts \[1\] separate"):
        Silent().resolve(problem)
