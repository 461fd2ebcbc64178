"""Every registered law held to the common checks, one test per cell of `check_law`.

The pattern of scikit-learn's common estimator checks, on `lawbench.studies.conformance` (the same
cells `lawbench check LAW` prints): every check the law's tags make applicable, on every scene it
can treat (each named example; continuity and dispersion on the defaults) and on seeded random
chains. Every cell must end in a verdict a table may ship: *holds*, *refused* or *budget* (skipped
with the reason), or *law property* (a failure the law's findings predict, run as an expected
failure with the finding). A *numerical failure* or an *unexplained* verdict fails the test. Each
finding is also held to its witnesses, so a finding that stops holding is noticed.
"""

from functools import cache

import pytest

import lawbench
from lawbench.core.verdicts import Verdict
from lawbench.studies.conformance import cells, run_cell


@cache
def trial(law_name, case_name, example):
    """The trial, or the reason the law refuses the example (NotApplicable)."""
    case = lawbench.CASES.get(case_name)
    try:
        return lawbench.evaluate(law_name, case, **case.examples[example])
    except lawbench.NotApplicable as refusal:
        return str(refusal)


ALL_CELLS = [(law, cell) for law in lawbench.LAWS.values() for cell in cells(law)]


@pytest.mark.parametrize(("law", "cell"), ALL_CELLS, ids=[cell.id for _, cell in ALL_CELLS])
def test_common_check(law, cell):
    row = run_cell(law, cell)
    if row["verdict"] in (Verdict.REFUSED, Verdict.BUDGET):
        pytest.skip(f"{row['verdict']}: {row['detail']}")
    if row["verdict"] == Verdict.LAW_PROPERTY:
        pytest.xfail(row["claim"])
    assert row["verdict"] == Verdict.HOLDS, f"{row['verdict']}: {row['detail']}"


def witnesses():
    for law in lawbench.LAWS.values():
        for claim in law.findings:
            for case, example in claim.witnesses:
                yield pytest.param(
                    law.name,
                    claim,
                    case,
                    example,
                    id=f"{law.name}-{claim.check}-{case}-{example}".replace(" ", "_"),
                )


@pytest.mark.parametrize(("law", "claim", "case", "example"), list(witnesses()))
def test_every_finding_is_met_at_its_witnesses(law, claim, case, example):
    """A finding's witness fails the check, and the verdict names that finding."""
    assert claim.check in lawbench.CHECKS
    assert example in lawbench.CASES.get(case).examples
    result = lawbench.CHECKS[claim.check](trial(law, case, example))
    assert result.verdict == Verdict.LAW_PROPERTY, result.detail
    assert result.claim == claim


def first_scene(law_name):
    """The first case (by name) whose default example the law treats."""
    for case in lawbench.CASES.values():
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
    for claim in (*entry.findings, *entry.guarantees):
        assert claim.source and claim.reason and claim.region.text, (law, claim.check)


@pytest.mark.parametrize("case", lawbench.CASES.names())
def test_every_case_documents_coordinates_and_parameters(case):
    entry = lawbench.CASES.get(case)
    doc = __import__(type(entry).__module__, fromlist=["_"]).__doc__
    assert "coordinates" in doc.lower() and "Source" in doc, case
    for spec in entry.params:
        assert spec.doc, (case, spec.name)
    for ref in entry.references:
        assert ref.source and ref.law in lawbench.LAWS, (case, ref.name)
