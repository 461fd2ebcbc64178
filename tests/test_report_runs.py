"""What the report runs: the studies, and the note on cells the quick report leaves out."""

from lawbench.studies.declared import STUDIES
from lawbench.views.report.runs import _left_to_full, _thinning


def test_the_cells_left_to_the_full_report_are_counted_and_named():
    study = STUDIES.get("three_ball_chain_grazing").preset("quick")
    laws, cases = ["newton", "mujoco", "compliant"], ["three_ball_chain"]
    cells = len(study.plan(laws, cases).jobs)
    # Newton's 2 restitutions x 3 speeds; one cell each for the engine and the compliant law.
    assert cells == 6 + 1 + 1
    left = _left_to_full(study, cells, laws, cases)
    assert left == 2 * 5
    assert _left_to_full(study, 6, ["newton"], cases) == 0
    (note,) = _thinning({study.name: (left, 1), "lamina_grazing": (0, 1)})
    assert "the first value" in note and f"{left} cells" in note
    assert f"`{study.name}`" in note and "lamina_grazing" not in note
    assert _thinning({study.name: (0, 1)}) == []
