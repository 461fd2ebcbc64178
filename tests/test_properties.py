"""Properties every law's answer keeps on random small impacts.

- The unit of mass, velocity and time: scaling the masses, the velocities and the contacts'
  stiffness scales the post-impact velocities with the velocities alone.
- The order of contacts and of bodies: permuting either permutes the answer.
- A vanishing friction coefficient: mu = 1e-8 gives the frictionless answer to 1e-6.
- An answer labelled ok never breaks what its law guarantees (``Law.guarantees``, read through
  `lawbench.run_checks`).

Each problem is drawn from a seed: one to three degrees of freedom with diagonal masses, one or
two contacts with random normals, restitution in [0.2, 1] and, where friction is drawn, a planar
tangential direction per contact. A law that refuses a problem (`Law.refusal`, `NotApplicable`)
or fails within its budget is not held to the property there: refusing is its right, and a
failure is never an ok answer. The integrating laws (those with an accuracy knob) are the slow
profile.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import lawbench
from lawbench.core.errors import NotApplicable, SolverFailure

EXAMPLES = settings(max_examples=200, deadline=None, derandomize=True)
OPTIONS = {"max_seconds": 5}
# Relative agreement of two answers that the law's theory says are equal.
AGREE = 1e-6
SEEDS = st.integers(0, 2**32 - 1)
# Laws whose answer depends on the order of contacts by design, and the option that makes the
# order a property of the velocities instead: sequential impacts sweep the contacts by index
# unless told to strike the fastest approaching one first (Brogliato, An introduction to
# impact dynamics, 2010, eqs. (27)-(28): the outcome of a chain depends on the sequence).
ORDER_FREE = {"sequential": {"order": "fastest_first"}}


def _laws(frictional: bool = False) -> list:
    """Every registered law (with friction only: those that treat it), integrating ones slow."""
    return [
        pytest.param(name, marks=pytest.mark.slow) if law.tags.accuracy_knob == "tol" else name
        for name, law in lawbench.LAWS.items()
        if law.tags.friction or not frictional
    ]


LAWS = _laws()


def _draw(seed: int, frictional: bool, mass=1.0, speed=1.0, stiffness=1.0, mu=None) -> dict:
    """The arrays of a random problem from ``seed``, scaled by the given units."""
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(1, 4)), int(rng.integers(1, 3))
    arrays = {
        "M": mass * np.diag(rng.uniform(0.5, 2.0, n)),
        "Wn": rng.normal(size=(n, m)),
        "v": speed * rng.normal(size=n),
        "e": rng.uniform(0.2, 1.0, m),
        "stiffness": stiffness * rng.uniform(0.5, 2.0, m),
    }
    if frictional:
        arrays["Wt"] = rng.normal(size=(n, m))
        arrays["mu"] = rng.uniform(0.05, 1.0, m) if mu is None else np.full(m, mu)
    return arrays


def _problem(arrays: dict) -> lawbench.ImpactProblem:
    coefficients = {k: list(arrays[k]) for k in ("e", "stiffness", "mu") if k in arrays}
    return lawbench.ImpactProblem.from_arrays(
        arrays["M"], arrays["Wn"], arrays["v"], arrays.get("Wt"), **coefficients
    )


def _v_plus(law: str, arrays: dict, options: dict | None = None) -> np.ndarray | None:
    """The law's post-impact velocities, or None where it refuses or fails."""
    problem = _problem(arrays)
    if lawbench.LAWS[law].refusal(problem) is not None:
        return None
    try:
        return np.asarray(lawbench.solve(law, problem, {**OPTIONS, **(options or {})}).v_plus)
    except (NotApplicable, SolverFailure):
        return None


def _agree(a: np.ndarray, b: np.ndarray, speed: float) -> None:
    np.testing.assert_allclose(a, b, rtol=AGREE, atol=AGREE * speed)


@pytest.mark.parametrize("frictional", [False, True])
@pytest.mark.parametrize("law", LAWS)
@EXAMPLES
@given(seed=SEEDS, units=st.sampled_from([(1e-2, 3.0, 1e3), (50.0, 0.1, 1e-2), (4.0, 7.0, 1.0)]))
def test_answers_scale_with_the_units(law, frictional, seed, units):
    mass, speed, stiffness = units
    base = _v_plus(law, _draw(seed, frictional))
    scaled = _v_plus(law, _draw(seed, frictional, mass, speed, stiffness))
    if base is not None and scaled is not None:
        _agree(scaled, speed * base, speed * float(np.abs(base).max(initial=1.0)))


def _permuted(arrays: dict, rng: np.random.Generator) -> tuple[dict, np.ndarray]:
    """``arrays`` with contacts and bodies permuted, and the bodies' permutation."""
    n, m = arrays["Wn"].shape
    bodies, contacts = rng.permutation(n), rng.permutation(m)
    out = {
        "M": arrays["M"][np.ix_(bodies, bodies)],
        "Wn": arrays["Wn"][np.ix_(bodies, contacts)],
        "v": arrays["v"][bodies],
    }
    for key in ("e", "stiffness", "mu"):
        if key in arrays:
            out[key] = arrays[key][contacts]
    if "Wt" in arrays:
        out["Wt"] = arrays["Wt"][np.ix_(bodies, contacts)]
    return out, bodies


@pytest.mark.parametrize("frictional", [False, True])
@pytest.mark.parametrize("law", LAWS)
@EXAMPLES
@given(seed=SEEDS)
def test_permuting_contacts_and_bodies_permutes_the_answer(law, frictional, seed):
    arrays = _draw(seed, frictional)
    permuted, bodies = _permuted(arrays, np.random.default_rng(seed + 1))
    options = ORDER_FREE.get(law)
    base, other = _v_plus(law, arrays, options), _v_plus(law, permuted, options)
    if base is not None and other is not None:
        _agree(other, base[bodies], float(np.abs(arrays["v"]).max()))


@pytest.mark.parametrize("law", _laws(frictional=True))
@EXAMPLES
@given(seed=SEEDS)
def test_a_vanishing_mu_gives_the_frictionless_answer(law, seed):
    frictionless = _v_plus(law, _draw(seed, True, mu=0.0))
    tiny = _v_plus(law, _draw(seed, True, mu=1e-8))
    if frictionless is not None and tiny is not None:
        _agree(tiny, frictionless, float(np.abs(frictionless).max(initial=1.0)))


@pytest.mark.parametrize("frictional", [False, True])
@pytest.mark.parametrize("law", LAWS)
@EXAMPLES
@given(seed=SEEDS)
def test_an_ok_answer_keeps_what_its_law_guarantees(law, frictional, seed):
    problem = _problem(_draw(seed, frictional))
    checks = [claim.check for claim in lawbench.LAWS[law].guarantees]
    if lawbench.LAWS[law].refusal(problem) is not None or not checks:
        return
    try:
        trial = lawbench.evaluate(law, problem, OPTIONS)
    except (NotApplicable, SolverFailure):
        return
    if trial.outcome.status != "ok":
        return
    for name, result in lawbench.run_checks(trial, checks=checks).items():
        assert result.verdict != lawbench.Verdict.NUMERICAL_FAILURE, (name, result)
