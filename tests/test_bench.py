"""The benchmark command prints its figures (a smoke test: no time is asserted)."""

from lawbench.bench import report


def test_the_benchmark_prints_every_figure_with_its_peer():
    text = report(quick=True)
    assert text.startswith("lawbench bench on ")
    for line in ("one three-ball Moreau impact", "a batch of", "n-ball chain", "start-up"):
        assert line in text
    for law in ("lzb", "compliant"):
        assert f"{law}: time grows like n^" in text
    assert text.count("energy error") == 4
    assert "x clarabel direct" in text and "x numpy enumeration" in text
