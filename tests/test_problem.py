"""Validation of impact problems, case parameters and law options."""

import dataclasses
import re

import numpy as np
import pytest
import scipy.sparse

import lawbench
from lawbench import Contact, ImpactProblem, InvalidProblem


def two_balls(**changes):
    fields = {
        "M": np.diag([1.0, 2.0]),
        "Wn": np.array([[-1.0], [1.0]]),
        "v": np.array([1.0, 0.0]),
        "contacts": [Contact(e=0.5)],
    }
    fields.update(changes)
    return ImpactProblem(**fields)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"M": np.diag([1.0, -2.0])}, "M is not positive definite"),
        ({"M": np.array([[1.0, 0.5], [0.0, 1.0]])}, "M is not symmetric"),
        ({"M": np.eye(3)}, r"M has shape \(3, 3\)"),
        ({"Wn": np.ones((3, 1))}, r"Wn has shape \(3, 1\)"),
        ({"v": np.array([np.nan, 0.0])}, r"v\[0\] is not a number"),
        ({"v": np.array([1.0, np.inf])}, r"v\[1\] is infinite"),
        ({"contacts": [Contact(e=1.5)]}, r"contacts\[0\]\.e = 1\.5"),
        ({"contacts": [Contact(mu=-0.1)]}, r"contacts\[0\]\.mu = -0\.1"),
        ({"contacts": [Contact(stiffness=0.0)]}, r"contacts\[0\]\.stiffness = 0"),
        ({"contacts": [Contact(e_poisson=-0.2)]}, r"contacts\[0\]\.e_poisson"),
        ({"contacts": []}, "contacts is empty"),
        ({"gaps": np.array([-1.0])}, r"gaps\[0\] = -1"),
        ({"Wt": np.ones((2, 3))}, "Wt has shape"),
        ({"bodies": {"ball": (0, 5)}}, r"bodies\['ball'\]"),
        # Unset where a number is needed: the laws compared it with numbers (a TypeError).
        ({"contacts": [Contact(mu=None)]}, r"contacts\[0\]\.mu = None: must be a number"),
        # Integers beyond double precision: converting them raised an OverflowError.
        ({"contacts": [Contact(e=10**400)]}, r"contacts\[0\]\.e: an integer of 1329 bits"),
        ({"v": [10**400, 0.0]}, "v: not an array of numbers"),
        ({"M": [[10**400, 0.0], [0.0, 1.0]]}, "M: not an array of numbers"),
        # A sparse M of 1e12 columns: densified (a MemoryError) before its shape was read.
        ({"M": scipy.sparse.csr_array((2, 10**12))}, r"M has shape \(2, 1000000000000\)"),
    ],
)
def test_bad_fields_are_refused_by_name(changes, message):
    with pytest.raises(InvalidProblem, match=message):
        two_balls(**changes)


def test_many_contacts_are_checked_as_one_table_with_the_same_refusals():
    """Beyond eight distinct contacts the fields are read as one table: an unset mu there
    passed as a number."""
    m, mu = 10, [0.1] * 9 + [None]
    with pytest.raises(InvalidProblem, match=r"contacts\[9\]\.mu = None"):
        ImpactProblem.from_arrays(np.eye(m), np.eye(m), -np.ones(m), np.eye(m), mu=mu)
    unset = ImpactProblem.from_arrays(np.eye(m), np.eye(m), -np.ones(m), e_newton=[None] * m)
    assert unset.restitution("kinematic").tolist() == [1.0] * m


def test_invalid_problem_is_a_value_error():
    assert issubclass(InvalidProblem, ValueError)


def test_problem_arrays_are_read_only_and_laws_do_not_mutate():
    problem = two_balls()
    with pytest.raises(ValueError, match="read-only"):
        problem.v[0] = 3.0
    before = problem.v.copy()
    for law in lawbench.LAWS.values():
        try:
            law.resolve(problem)
        except lawbench.NotApplicable:
            continue  # an engine law refuses a problem whose scene declares no geometry
    assert np.array_equal(problem.v, before)


def test_restitution_overrides():
    contact = Contact(e=0.5, e_poisson=0.3)
    assert contact.restitution("kinematic") == 0.5
    assert contact.restitution("kinetic") == 0.3


def test_open_contacts_are_left_alone():
    """A contact with a positive gap is not part of the impact: zero impulse."""
    outcome = lawbench.solve("moreau", "three_ball_chain", gaps=[0.0, 0.01])
    np.testing.assert_allclose(outcome.v_plus, [0.0, 1.0, 0.0], atol=1e-14)
    assert outcome.Pn[1] == 0.0
    all_open = lawbench.solve("newton", "three_ball_chain", gaps=[0.1, 0.1])
    assert all_open.diagnostics["formulation"] == "no closed contact"
    np.testing.assert_array_equal(all_open.v_plus, [1.0, 0.0, 0.0])


def test_references_assume_closed_contacts():
    """With open gaps the rigid laws leave the chain alone; eq. (29) no longer describes it."""
    trial = lawbench.evaluate("newton", "three_ball_chain", gaps=[1.0, 1.0])
    result = lawbench.CHECKS["reference"](trial)
    assert result.passed is None
    assert "zero gaps" in result.detail


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"e": 1.5}, r"e\[0\] = 1\.5"),
        ({"masses": [1, -1, 1]}, r"masses\[1\] = -1"),
        ({"masses": [1, 0, 1]}, r"masses\[1\] = 0"),
        ({"velocities": [1, 0]}, "velocities has 2 values, expected 3"),
        ({"velocities": [float("nan"), 0, 0]}, r"velocities\[0\] = nan"),
        ({"velocities": "1,x,0"}, r"velocities\[1\] = 'x': not a number"),
        ({"e": [0.5, 0.5, 0.5]}, "e has 3 values, expected 1 or 2"),
        ({"stiffness_ratio": 0}, "stiffness_ratio = 0"),
        ({"colour": "red"}, "unknown parameter 'colour'.*known: masses"),
    ],
)
def test_bad_case_parameters_are_refused_by_name(params, message):
    with pytest.raises(InvalidProblem, match=message):
        lawbench.solve("newton", "three_ball_chain", **params)


def test_ball_chain_parameters():
    case = lawbench.CASES.get("ball_chain")
    params = case.parameters(n=4, velocities=[2.0])
    assert params["velocities"] == [2.0, 0.0, 0.0, 0.0]
    assert params["masses"] == [1.0] * 4
    assert case.build(n=4, wall=True).m == 4
    with pytest.raises(InvalidProblem, match="n = 1"):
        case.parameters(n=1)
    with pytest.raises(InvalidProblem, match="more than n = 2"):
        case.parameters(n=2, velocities=[1, 2, 3])
    with pytest.raises(InvalidProblem, match="wall = 'maybe'"):
        case.parameters(wall="maybe")


def test_bad_law_options_are_refused_by_name():
    with pytest.raises(InvalidProblem, match="unknown option 'speed' for law 'sequential'"):
        lawbench.solve("sequential", "three_ball_chain", {"speed": 1})
    with pytest.raises(InvalidProblem, match="order = 'random'"):
        lawbench.solve("sequential", "three_ball_chain", {"order": "random"})
    with pytest.raises(InvalidProblem, match="tol = 0"):
        lawbench.solve("moreau", "three_ball_chain", {"tol": 0})


def test_select_contacts_keeps_the_chosen_columns():
    problem = lawbench.CASES.get("three_ball_chain").build()
    only = problem.select_contacts(np.array([False, True]))
    assert only.m == 1
    np.testing.assert_array_equal(only.Wn[:, 0], problem.Wn[:, 1])
    assert dataclasses.replace(problem).m == 2


def test_a_contact_no_motion_can_push_along_its_normal_is_refused():
    """A double pendulum hanging straight down with its tip on the floor: the tip cannot move
    vertically (to first order), so the normal Delassus entry is rounding noise."""
    with pytest.raises(InvalidProblem, match="singular configuration"):
        lawbench.CASES.get("double_pendulum").build(angles=[1e-6, 0.0], omegas=[-1.0, 3.0])
    nearly = lawbench.CASES.get("double_pendulum").build(angles=[1e-3, 0.0], omegas=[-1.0, 3.0])
    assert nearly.delassus[0, 0] > 0


@pytest.mark.parametrize(
    ("M", "Wn", "Wt", "message"),
    [
        (np.eye(2) * 1e-200, [[-1e200], [1e200]], None, r"Wn\[:, 0\]: .* Wn overflows"),
        (np.eye(2), [[-1e-200], [1e-200]], None, r"Wn\[:, 0\]: .* Wn underflows"),
        (np.eye(2) * 1e-5, [[-1e150], [1e150]], [[1e154], [1e154]], r"Wt\[:, 0\]: .* overflows"),
    ],
    ids=["overflow", "underflow", "tangential"],
)
def test_a_delassus_matrix_beyond_double_precision_is_named_not_called_singular(M, Wn, Wt, message):
    """W = Wn.T M^-1 Wn of 2e400 or 2e-500 is no singular configuration: it names the field."""
    with pytest.raises(InvalidProblem, match=message):
        problem = ImpactProblem.from_arrays(M, Wn, [1e-150, 0.0], Wt=Wt, mu=0.5)
        problem.contact_delassus  # noqa: B018 - built on first read, where Wt overflows


@pytest.mark.parametrize(
    ("scale", "normal", "speed", "name"),
    [(1e-300, 1e150, 1e300, "Wn.T v"), (1e300, 1.0, 1e150, "M v"), (1.0, 1.0, 1e300, "v M v / 2")],
)
def test_a_velocity_whose_gap_rates_or_momentum_overflow_is_refused_by_name(
    scale, normal, speed, name
):
    """Gap rates of 1e450 read as a NaN un+ in the admissibility check: a solver failure."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]]) * scale
    with pytest.raises(InvalidProblem, match=re.escape(f"{name} is beyond double precision")):
        ImpactProblem.from_arrays(M, [[-normal], [normal]], [speed, speed / 2])


def test_a_jacobian_of_extreme_scale_is_judged_by_its_geometry():
    """Wn of 1e160 on masses of 1e300: W = 2e20, no contact singular (its squares overflow)."""
    problem = ImpactProblem.from_arrays(np.eye(2) * 1e300, [[-1e160], [1e160]], [1.0, 0.0])
    assert problem.delassus[0, 0] == pytest.approx(2e20)


def test_a_large_diagonal_mass_gives_the_dense_delassus_matrix():
    """Chains of more than SMALL balls take the reciprocal diagonal and a sparse product:
    G = Wn^T M^-1 Wn as the dense computation gives it, and M^-1 rhs likewise."""
    problem = lawbench.CASES.get("ball_chain").build(n=120, masses=list(np.linspace(1, 3, 120)))
    M, Wn = problem.M, problem.Wn
    np.testing.assert_allclose(problem.delassus, Wn.T @ np.linalg.solve(M, Wn), atol=1e-14)
    rhs = np.arange(120.0)
    np.testing.assert_allclose(problem.solve_mass(rhs), np.linalg.solve(M, rhs), rtol=1e-14)


def test_a_long_plastic_chain_sticks_at_the_momentum_average():
    """Brogliato 2010, remark after eq. (29): Moreau's law at e = 0 gives every ball of a free
    chain struck at one end the velocity of the centre of mass; 500 balls take the sparse
    Delassus product and the sparse exact solve on the active set."""
    outcome = lawbench.solve("moreau", "ball_chain", n=500, e=0.0)
    assert outcome.diagnostics["polished"]
    np.testing.assert_allclose(outcome.v_plus, np.full(500, 1 / 500), atol=1e-12)


def test_shared_coefficients_build_one_checked_contact_of_the_type_given():
    """Coefficients every contact shares build one contact, reused across problems; the value
    keeps the type it was given (1 and 1.0 are equal keys), and a bad one is refused each time.
    """
    M, Wn, v = np.eye(2), [[-1.0], [1.0]], [1.0, 0.0]
    first = ImpactProblem.from_arrays(M, Wn, v, e=1).contacts[0]
    again = ImpactProblem.from_arrays(M, Wn, v, e=1).contacts[0]
    as_float = ImpactProblem.from_arrays(M, Wn, v, e=1.0).contacts[0]
    assert first is again
    assert type(first.e) is int and type(as_float.e) is float
    for _ in range(2):
        with pytest.raises(InvalidProblem, match=r"contacts\[0\]\.e = 1\.5"):
            ImpactProblem.from_arrays(M, Wn, v, e=1.5)


@pytest.mark.parametrize(
    ("field", "value"),
    [("v_plus", np.array([np.nan, 0.0])), ("Pn", np.array([np.inf])), ("Pt", np.array([np.nan]))],
)
def test_a_law_never_returns_a_non_finite_answer(field, value):
    """The law protocol refuses a non-finite field of an outcome by name, whatever the law."""

    class Broken(lawbench.Law):
        name = "broken"
        summary = "returns a non-finite field"
        source = "none: a test of the protocol"
        tags = lawbench.Tags()

        def _resolve(self, problem, options):
            outcome = lawbench.Outcome.from_impulses(problem, np.zeros(1))
            return dataclasses.replace(outcome, **{field: value})

    # A tangential row (frictionless: mu = 0) gives Pt its one entry.
    problem = ImpactProblem.from_arrays(np.eye(2), [[-1.0], [1.0]], [1.0, 0.0], [[0.0], [1.0]])
    with pytest.raises(lawbench.SolverFailure, match=f"non-finite {field}"):
        Broken().resolve(problem)


def test_a_scene_whose_formulas_leave_double_precision_names_what_was_given():
    """radius = 1e-308 gives a straight shot's Jacobian a 0/0: the message names the radius."""
    given = r"radius = 1e-308, offset_side = 0.0, offset_height = 0.0"
    with pytest.raises(InvalidProblem, match=rf"billiard: {given}: Wt\[0, 0\] is not a"):
        lawbench.CASES["billiard"].build(radius=1e-308, offset_side=0.0, offset_height=0.0)
