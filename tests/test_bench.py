"""The benchmark command prints its figures (a smoke test: no time is asserted)."""

import pytest

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.studies.bench import report, start_up_command, subject


# A benchmark run end to end (about 13 s): a study of cost, not of correctness.
@pytest.mark.slow
def test_the_benchmark_prints_every_figure_with_its_peer():
    text = report(quick=True)
    assert text.startswith("lawbench bench on ")
    for line in ("one three-ball", "a batch of", "n-ball chain", "bytecode cached"):
        assert line in text
    integrating = [
        law.name for law in LAWS.values() if any(s.name == "max_events" for s in law.options)
    ]
    assert {"compliant", "jia", "lzb"} <= set(integrating)
    for law in integrating:
        assert f"{law}: time grows like n^" in text
    assert text.count("energy error") == 2 * len(integrating)
    assert "x clarabel direct" in text and "x numpy enumeration" in text


def test_the_bench_subjects_are_the_ones_laws_and_scenes_declare(monkeypatch):
    """The engine names no law or scene: each role goes to the first entry declaring it."""
    lcp = subject(LAWS, "lcp")
    assert "lcp" in LAWS[lcp].bench_roles
    law, scene = start_up_command()[1:]
    assert "start_up" in LAWS[law].bench_roles and "start_up" in CASES[scene].bench_roles
    monkeypatch.setattr(type(LAWS[lcp]), "bench_roles", ())
    with pytest.raises(InvalidProblem, match="no law declares the bench role 'lcp'"):
        subject(LAWS, "lcp")
