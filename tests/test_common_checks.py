"""Every registered law on every case it applies to, every example, every single-solve check.

(``continuity`` and ``dispersion`` solve the case again; their own tests cover them.)

The pattern of scikit-learn's common estimator checks: the case's requirements and the law's
capabilities decide what runs; a check that does not apply is skipped with its reason; a known
defect of a law is listed in the law's ``findings`` with the reason and runs as a strict
expected failure, so a finding that stops holding is noticed.
"""

from functools import cache

import pytest

import lawbench
from lawbench.checks import SINGLE_SOLVE


@cache
def trial(law_name, case_name, example):
    """The trial, or the reason the law refuses the example (NotApplicable)."""
    case = lawbench.CASES.get(case_name)
    try:
        return lawbench.evaluate(law_name, case, **case.examples[example])
    except lawbench.NotApplicable as refusal:
        return str(refusal)


def combinations():
    for law in lawbench.LAWS:
        for case in lawbench.CASES:
            if not case.requires.met_by(law.capabilities):
                continue
            for example in case.examples:
                for check in SINGLE_SOLVE:
                    key = (case.name, example, check)
                    marks = []
                    if key in law.findings:
                        marks = [pytest.mark.xfail(reason=law.findings[key], strict=True)]
                    yield pytest.param(
                        law.name,
                        case.name,
                        example,
                        check,
                        id=f"{law.name}-{case.name}-{example}-{check}".replace(" ", "_"),
                        marks=marks,
                    )


@pytest.mark.parametrize(("law", "case", "example", "check"), list(combinations()))
def test_common_check(law, case, example, check):
    solved = trial(law, case, example)
    if isinstance(solved, str):
        pytest.skip(f"the law does not apply: {solved}")
    result = lawbench.CHECKS[check](solved)
    if result.passed is None:
        pytest.skip(result.detail)
    assert result.passed, result.detail


def test_every_finding_names_a_real_case_example_and_check():
    for law in lawbench.LAWS:
        for case, example, check in law.findings:
            assert example in lawbench.CASES.get(case).examples, (law.name, case, example)
            assert check in lawbench.CHECKS, (law.name, check)


def first_scene(law_name):
    """The first case (by name) whose default example the law treats."""
    for case in lawbench.CASES:
        solved = trial(law_name, case.name, "default")
        if not isinstance(solved, str):
            return solved
    raise AssertionError(f"{law_name} treats no scene")


@pytest.mark.parametrize("law", lawbench.LAWS.names())
def test_every_law_fills_the_outcome_fields(law):
    """Like scipy.optimize's result: the same fields, filled, for every method."""
    solved = first_scene(law)
    problem, outcome = solved.problem, solved.outcome
    assert outcome.v_plus.shape == (problem.n,)
    assert outcome.Pn.shape == (problem.m,)
    assert outcome.Pt.shape == (problem.m * problem.d,)
    assert outcome.status in ("ok", "ambiguous")
    assert isinstance(outcome.diagnostics["formulation"], str)
    assert outcome.diagnostics["wall_time_s"] >= 0
    assert set(outcome.diagnostics["options"]) == {s.name for s in lawbench.LAWS.get(law).options}
    assert outcome.T_minus == pytest.approx(0.5 * problem.v @ problem.M @ problem.v)


@pytest.mark.parametrize("law", lawbench.LAWS.names())
def test_every_law_states_its_source_and_conventions(law):
    entry = lawbench.LAWS.get(law)
    module_doc = type(entry).__module__
    doc = __import__(module_doc, fromlist=["_"]).__doc__
    assert entry.source and entry.summary
    assert "Source" in doc and "onvention" in doc, law


@pytest.mark.parametrize("case", lawbench.CASES.names())
def test_every_case_documents_coordinates_and_parameters(case):
    entry = lawbench.CASES.get(case)
    doc = __import__(type(entry).__module__, fromlist=["_"]).__doc__
    assert "coordinates" in doc.lower() and "Source" in doc, case
    for spec in entry.params:
        assert spec.doc, (case, spec.name)
    for ref in entry.references:
        assert ref.source and ref.law in lawbench.LAWS, (case, ref.name)
