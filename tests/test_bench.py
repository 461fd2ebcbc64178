"""The benchmark command prints its figures (a smoke test: no time is asserted)."""

from lawbench.bench import report
from lawbench.law import LAWS


def test_the_benchmark_prints_every_figure_with_its_peer():
    text = report(quick=True)
    assert text.startswith("lawbench bench on ")
    for line in ("one three-ball", "a batch of", "n-ball chain", "bytecode cached"):
        assert line in text
    integrating = [law.name for law in LAWS if any(s.name == "max_events" for s in law.options)]
    assert {"compliant", "jia", "lzb"} <= set(integrating)
    for law in integrating:
        assert f"{law}: time grows like n^" in text
    assert text.count("energy error") == 2 * len(integrating)
    assert "x clarabel direct" in text and "x numpy enumeration" in text
