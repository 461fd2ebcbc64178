"""The lamina on an anvil against Lubarda's relations between the three coefficients.

Source of every expected value: B. Brogliato, *An introduction to impact dynamics* (lectures,
2010), the lamina colliding an anvil with friction, after V.A. Lubarda (J. Appl. Mech., 2010):
``ep = (f0 + f h0) / (f0 - f h0) en``, ``e*^2 = ep en``, ``en < e* < ep`` (eq. 12), the tangential
impulse (eq. 14) and the case of large friction ``f h0 / f0 >= 1`` (plastic impact).
"""

import dataclasses
import itertools
import math

import numpy as np
import pytest

import lawbench
from lawbench import Contact

TERMINATIONS = ("newton", "poisson", "energetic")
LAMINA = lawbench.CASES.get("lamina")
LAW = lawbench.LAWS.get("darboux_keller")


def solve(termination, contact=None, **params):
    problem = LAMINA.build(**params)
    if contact is not None:
        problem = dataclasses.replace(problem, contacts=[contact])
    return LAW.resolve(problem, termination=termination)


def lubarda(f0, h0, mu, e_star):
    """(en, ep) reproducing the energetic coefficient e*: e*^2 = ep en, ep / en = 1 / r."""
    r = (abs(f0) - mu * abs(h0)) / (abs(f0) + mu * abs(h0))
    return e_star * math.sqrt(r), e_star / math.sqrt(r)


def rebound_grid():
    for f0, h0, mu, e in itertools.product(
        [1.0, 2.0, -1.5], [0.5, 1.5, -1.0], [0.1, 0.3, 0.6], [0.2, 0.5, 0.8]
    ):
        if abs(f0) - mu * abs(h0) <= 0 or lubarda(f0, h0, mu, e)[1] > 1:
            continue  # plastic, or Poisson's coefficient out of [0, 1]
        yield pytest.param(f0, h0, mu, e, id=f"f0={f0:g}-h0={h0:g}-mu={mu:g}-e={e:g}")


@pytest.mark.parametrize(("f0", "h0", "mu", "e"), list(rebound_grid()))
def test_three_terminations_agree_under_lubardas_relations(f0, h0, mu, e):
    """Lubarda's relations make Newton, Poisson and Stronge give one outcome; en < e* < ep."""
    en, ep = lubarda(f0, h0, mu, e)
    assert en < e < ep
    contact = Contact(e_newton=en, e_poisson=ep, e_energy=e, mu=mu)
    omega = -2.0 * math.copysign(1.0, f0)
    params = {"f0": f0, "h0": h0, "mu": mu, "omega": omega, "inertia": 0.7}
    outcomes = [solve(t, contact, **params) for t in TERMINATIONS]
    for other in outcomes[1:]:
        np.testing.assert_allclose(other.v_plus, outcomes[0].v_plus, rtol=0, atol=1e-9)
        np.testing.assert_allclose(other.Pn, outcomes[0].Pn, rtol=0, atol=1e-9)
        np.testing.assert_allclose(other.Pt, outcomes[0].Pt, rtol=0, atol=1e-9)
    # Newton's rule itself: omega+ = -en omega-.
    np.testing.assert_allclose(outcomes[0].v_plus, [-en * omega], rtol=0, atol=1e-12)
    assert outcomes[0].diagnostics["phases"] == [
        "slip",
        "end of compression",
        "slip reversal",
        "end of impact",
    ]


def stick_grid():
    for f0, h0, mu in [(1.0, 1.0, 1.0), (1.0, 2.0, 0.6), (-0.5, 1.0, 0.8), (2.0, -1.0, 3.0)]:
        for e in [0.0, 0.5, 1.0]:
            yield pytest.param(f0, h0, mu, e, id=f"f0={f0:g}-h0={h0:g}-mu={mu:g}-e={e:g}")


@pytest.mark.parametrize(("f0", "h0", "mu", "e"), list(stick_grid()))
@pytest.mark.parametrize("termination", TERMINATIONS)
def test_large_friction_makes_the_impact_plastic(f0, h0, mu, e, termination):
    """mu |h0| / |f0| >= 1: no expansion phase, omega+ = 0, Pn = I |omega-| / (|f0| + mu |h0|)."""
    assert mu * abs(h0) / abs(f0) >= 1
    omega = 3.0 * -math.copysign(1.0, f0)
    outcome = solve(termination, f0=f0, h0=h0, mu=mu, e=e, omega=omega, inertia=2.0)
    assert abs(outcome.v_plus[0]) <= 1e-12
    expected = 2.0 * abs(omega) / (abs(f0) + mu * abs(h0))
    np.testing.assert_allclose(outcome.Pn, [expected], rtol=1e-12)
    assert "stick" in outcome.diagnostics["phases"]


def test_tangential_impulse_follows_equation_14():
    """Eq. (14): Pt = f Pn, then f (2 Pc - Pn); the ratio Pt / Pn = f (1 - ep) / (1 + ep)."""
    mu, ep = 0.4, 0.7
    outcome = LAW.resolve(
        dataclasses.replace(LAMINA.build(mu=mu), contacts=[Contact(e=ep, mu=mu)]),
        termination="poisson",
        path=True,
    )
    Pn, Pt = outcome.path["Pn"], outcome.path["Pt"][:, 0]
    Pc = outcome.diagnostics["compression_impulse"]
    # Default lamina: f0 > 0, omega < 0, h0 > 0: the contact slips backwards, friction is +.
    np.testing.assert_allclose(Pt, mu * np.minimum(Pn, 2 * Pc - Pn), rtol=0, atol=1e-14)
    assert outcome.Pt[0] / outcome.Pn[0] == pytest.approx(mu * (1 - ep) / (1 + ep), rel=1e-12)


def test_mirrored_arms_mirror_the_outcome():
    """Reversing f0, h0 and omega reverses omega+; contact velocities and impulses stay."""
    base = solve("energetic")
    mirrored = solve("energetic", f0=-1.0, h0=-0.5, omega=1.0)
    np.testing.assert_allclose(mirrored.v_plus, -base.v_plus, rtol=1e-14)
    np.testing.assert_allclose(mirrored.Pn, base.Pn, rtol=1e-14)
    np.testing.assert_allclose(mirrored.Pt, base.Pt, rtol=1e-14)


def test_energetic_coefficient_for_a_newton_coefficient_can_exceed_one():
    """PHYSICS_NOTES: reproducing en needs e* = en / sqrt(r), above 1 when en^2 > r.

    At f0 = 1, h0 = 1, mu = 0.5 (r = 1/3) Newton's termination with en = 0.8 releases in
    restitution more normal work than compression stored: -W_r / W_c = e*^2 = 1.92. Kinetic
    energy still decreases (en < 1), yet no e* in [0, 1] gives this outcome: even e* = 1 ends
    at |omega+| = sqrt(r) |omega-| < en |omega-|.
    """
    f0, h0, mu, en = 1.0, 1.0, 0.5, 0.8
    r = (f0 - mu * h0) / (f0 + mu * h0)
    newton = solve("newton", Contact(e=en, mu=mu), f0=f0, h0=h0, mu=mu)
    d = newton.diagnostics
    implied = math.sqrt(-d["work_restitution"] / d["work_compression"])
    assert implied == pytest.approx(en / math.sqrt(r), rel=1e-12)
    assert implied > 1
    assert newton.dT < 0
    elastic = solve("energetic", Contact(e=1.0, mu=mu), f0=f0, h0=h0, mu=mu)
    assert abs(elastic.v_plus[0]) == pytest.approx(math.sqrt(r), rel=1e-12)
    assert abs(elastic.v_plus[0]) < abs(newton.v_plus[0])


def test_scene_matrices_and_requirements():
    problem = LAMINA.build(inertia=3.0, omega=-2.0, f0=0.4, h0=-0.2, e=0.3, mu=0.7)
    np.testing.assert_array_equal(problem.M, [[3.0]])
    np.testing.assert_array_equal(problem.Wn, [[0.4]])
    np.testing.assert_array_equal(problem.Wt, [[-0.2]])
    assert problem.un[0] == pytest.approx(-0.8) and problem.ut[0] == pytest.approx(0.4)
    assert (problem.contacts[0].e, problem.contacts[0].mu) == (0.3, 0.7)
    assert LAMINA.requires.friction and not LAMINA.requires.several_contacts
    with pytest.raises(lawbench.InvalidProblem, match="inertia"):
        LAMINA.build(inertia=0.0)


@pytest.mark.parametrize("example", list(LAMINA.examples))
def test_every_example_matches_a_reference_for_every_termination(example):
    for termination in TERMINATIONS:
        trial = lawbench.evaluate(
            "darboux_keller", "lamina", {"termination": termination}, **LAMINA.examples[example]
        )
        result = lawbench.CHECKS["reference"](trial)
        assert result.passed, result.detail
