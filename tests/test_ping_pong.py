"""The ping-pong stack: Jia, Mason and Erdmann's theorems, and the talk's two-ball example."""

import dataclasses

import numpy as np
import pytest
from scipy.optimize import least_squares

import lawbench
from lawbench.core.problem import ImpactProblem

CASE = lawbench.CASES.get("ping_pong")
LAWS = ("jia", "lzb")


def _with_stiffness_scaled(problem: ImpactProblem, factor: float) -> ImpactProblem:
    contacts = [dataclasses.replace(c, stiffness=c.stiffness * factor) for c in problem.contacts]
    return dataclasses.replace(problem, contacts=contacts)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("factor", [1e-3, 1e4])
def test_outcome_depends_on_the_stiffness_ratio_not_the_stiffness(law, factor):
    """Jia, Mason, Erdmann (IJRR 2013), Theorem 2 of Jia's 2012 talk, first statement.

    Both springs scaled by one factor: the same post-impact velocities.
    """
    problem = CASE.build()
    base = lawbench.solve(law, problem).v_plus
    scaled = lawbench.solve(law, _with_stiffness_scaled(problem, factor)).v_plus
    np.testing.assert_allclose(scaled, base, rtol=1e-7, atol=1e-9)


def test_the_stiffness_ratio_does_change_the_outcome():
    """The counterpart of Theorem 2: k2/k1 itself matters (Jia's talk, two-ball collision)."""
    at_3 = lawbench.solve("jia", "ping_pong").v_plus
    at_1 = lawbench.solve("jia", "ping_pong", stiffness_ratio=1.0).v_plus
    assert np.abs(at_3 - at_1).max() > 0.05


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("scale", [0.00023 / 2.7e-3, 1e3])
def test_scaling_both_masses_changes_nothing(law, scale):
    """Theorem 2 (Jia 2012 talk; Jia, Mason, Erdmann 2013), second statement.

    Among the scales: the talk's extracted 0.00023 kg against a 2.7 g table-tennis ball.
    """
    base = lawbench.solve(law, "ping_pong").v_plus
    masses = [2.7e-3 * scale] * 2
    scaled = lawbench.solve(law, "ping_pong", masses=masses).v_plus
    np.testing.assert_allclose(scaled, base, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("v0", [0.1, 3.0, 40.0])
def test_post_over_pre_velocity_ratios_are_constant_in_v0(law, v0):
    """Theorem 2 (Jia 2012 talk; Jia, Mason, Erdmann 2013), third statement: linearity."""
    at_1 = lawbench.solve(law, "ping_pong").v_plus
    at_v0 = lawbench.solve(law, "ping_pong", velocities=[-v0, -v0]).v_plus
    np.testing.assert_allclose(at_v0 / v0, at_1, rtol=1e-7, atol=1e-9)


def _two_ball_example(m2: float, ratio: float) -> np.ndarray:
    return lawbench.solve(
        "jia",
        "ping_pong",
        masses=[1.0, m2],
        velocities=[-1.0, 0.0],
        e=[1.0],
        stiffness_ratio=ratio,
    ).v_plus


PRINTED = np.array([0.94, 0.30])


def test_two_ball_example_energy_pins_the_lower_mass():
    """Jia's talk, two-ball example (m1 = 1, v0 = 1, e1 = e2 = 1, printed v1 = 0.94, v2 = 0.30).

    Elastic springs keep the energy, so m2 = (1 - v1^2) / v2^2 whatever k2/k1; the readings
    m2 = 2/3 and m2 = 2 of the garbled slide cannot give the printed velocities.
    """
    low = (1 - 0.945**2) / 0.305**2
    high = (1 - 0.935**2) / 0.295**2
    assert 1.1 < low < (1 - 0.94**2) / 0.3**2 < high < 1.5
    for m2, ratio in ((2 / 3, 1.0), (2.0, 3.0)):
        v = _two_ball_example(m2, ratio)
        assert v[0] ** 2 + m2 * v[1] ** 2 == pytest.approx(1.0, abs=1e-8)
        assert np.abs(v - PRINTED).max() > 0.05


def test_two_ball_example_is_decoded_by_a_search():
    """Jia's talk, two-ball example: jia gives v1 = 0.94, v2 = 0.30 at m2 = 1.2933, k2/k1 = 4.627.

    Least squares over (m2, log k2/k1) from a start of the coarse scan described in the
    scene's docstring.
    """

    def residual(x: np.ndarray) -> np.ndarray:
        return _two_ball_example(x[0], float(np.exp(x[1]))) - PRINTED

    fit = least_squares(residual, [1.4, np.log(5.0)], diff_step=1e-6, bounds=([0.1, -4], [5, 4]))
    assert np.abs(fit.fun).max() < 1e-8
    assert fit.x[0] == pytest.approx((1 - 0.94**2) / 0.3**2, rel=1e-6)
    assert np.exp(fit.x[1]) == pytest.approx(4.627, abs=2e-3)


def test_measured_coefficients_outcomes_of_the_study_laws():
    """v1+/v0 and v2+/v0 at e1 = 0.950043, e2 = 0.846529, k2/k1 = 3 (Jia 2012 talk).

    The laws differ (jia and lzb close to each other, sequential far from both), but none gains
    energy and the upper ball always leaves at least as fast as the lower one.
    """
    outcomes = {
        law: lawbench.solve(law, "ping_pong") for law in ("jia", "lzb", "compliant", "sequential")
    }
    for outcome in outcomes.values():
        assert outcome.T_plus <= outcome.T_minus * (1 + 1e-9)
        assert outcome.v_plus[0] >= outcome.v_plus[1] - 1e-9
    jia, lzb = outcomes["jia"].v_plus, outcomes["lzb"].v_plus
    assert np.abs(jia - lzb).max() < 0.05
