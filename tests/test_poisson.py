"""Poisson's law on redundant contacts (Pfeiffer and Glocker 1996, ch. 7).

With dependent normals the compression impulse is shared among the redundant contacts in a way
the law leaves open. The outcome is unique when their coefficients are equal; when they differ
it depends on the split, and the law refuses rather than let the order of the contacts decide.
"""

import itertools

import numpy as np
import pytest

import lawbench


def one_body(Wn: list[float], e: list[float]) -> lawbench.ImpactProblem:
    return lawbench.ImpactProblem.from_arrays(np.eye(1), [Wn], v=[1.0], e=e)


@pytest.mark.parametrize("order", [(0, 1), (1, 0)])
def test_redundant_contacts_with_different_coefficients_are_refused_in_any_order(order):
    Wn, e = np.array([-1.0, -2.0])[list(order)], np.array([0.2, 0.9])[list(order)]
    with pytest.raises(lawbench.NotApplicable, match="redundant"):
        lawbench.solve("poisson", one_body(Wn.tolist(), e.tolist()))


def test_redundant_contacts_with_one_coefficient_have_one_answer():
    """One coefficient e on one body: v+ = -e v- whatever the split (the law equals Newton's)."""
    answers = {
        round(float(lawbench.solve("poisson", one_body(list(Wn), [0.5, 0.5])).v_plus[0]), 12)
        for Wn in itertools.permutations([-1.0, -2.0])
    }
    assert answers == {-0.5}


def test_a_contact_given_twice_is_solved_as_once():
    once = lawbench.solve("poisson", "two_balls_wall", e=[0.4, 0.7])
    from lawbench.core.transforms import apply

    doubled = apply("duplicated=0", lawbench.CASES["two_balls_wall"].build(e=[0.4, 0.7]))
    np.testing.assert_allclose(lawbench.solve("poisson", doubled).v_plus, once.v_plus, atol=1e-12)
