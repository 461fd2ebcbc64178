"""The report's section "Against measurements", on a tiny set made by a law itself."""

import dataclasses

import numpy as np
import pytest

from lawbench.core.law import LAWS
from lawbench.core.verdicts import Verdict
from lawbench.fitting.measured import evenly, measured_study, predict
from lawbench.measurements import MEASUREMENTS, MeasurementSet, Processing
from lawbench.views.report import QUICK, build, measured
from lawbench.views.report.marks import Mark
from lawbench.views.report.page import Figure, Table
from lawbench.views.report.runs import Context

ELLIPSE = MEASUREMENTS.get("ellipse")
LAWS_STUDIED = ("newton", "whittaker")


@pytest.fixture(scope="module")
def tiny():
    """Eight ellipse impacts whose velocity after is Whittaker's at e = 0.6, mu = 0.3."""
    impacts = evenly(ELLIPSE.impacts, 8)
    velocities, failures = predict(LAWS.get("whittaker"), impacts, {"e": 0.6, "mu": 0.3}, {})
    assert not failures
    made = [dataclasses.replace(i, v_after=v) for i, v in zip(impacts, velocities, strict=True)]
    mask = np.arange(len(made)) % 2 == 0
    processing = Processing("made by a law", len(made), {})
    return MeasurementSet(
        "tiny", "impacts made by a law", ELLIPSE.source, lambda: (made, mask, processing)
    )


@pytest.fixture(scope="module")
def study(tiny):
    return measured_study(tiny, LAWS_STUDIED, quick=True)


def test_the_ranking_marks_each_answer_and_names_each_refusal(study, tiny):
    blocks = measured.set_blocks(study, tiny)
    table = next(b for b in blocks if isinstance(b, Table))
    rows = table.frame.set_index("law")
    assert isinstance(rows.loc["whittaker", "median error"], Mark)
    assert rows.loc["whittaker", "median error"].verdict == Verdict.HOLDS
    # A frictionless law refuses every impact measured with friction, and says why.
    refused = rows.loc["newton", "median error"]
    assert refused.verdict == Verdict.REFUSED
    assert "friction" in refused.reason
    assert rows.index[0] == "whittaker"  # the law that made the impacts ranks first
    figure = next(b for b in blocks if isinstance(b, Figure))
    assert set(figure.data["quantity"]) == {
        "normal contact velocity",
        "tangential contact velocity",
        "angular velocity",
    }
    # A law's own answers: predicted equals measured.
    assert np.allclose(figure.data["predicted"], figure.data["measured"], atol=1e-4)


def test_the_first_screen_links_the_section_and_the_page_shows_it(
    study, tiny, tmp_path, monkeypatch
):
    found = measured.Found(quick=True, studies={"tiny": study}, sets={"tiny": tiny})
    monkeypatch.setattr(measured, "results", lambda ctx: found)
    config = dataclasses.replace(
        QUICK, workers=1, executor="serial", laws=LAWS_STUDIED, cases=(), studies=()
    )
    out = build.build(tmp_path / "report", config)
    page = (out / "index.html").read_text()
    top = page.split("<ol>", 1)[0]
    assert '<table id="answer"' in top and "closest to measurement" in top
    assert '<a href="#measured">tiny</a>' in top and "<code>whittaker</code>" in top
    assert '<h3 id="measured">Against measurements</h3>' in page
    assert (out / "measured_tiny.csv").exists()
    assert (out / "measured_tiny_scatter.svg").exists()
    assert "Kharaz" in page  # the curves' absence is said, not hidden


def test_the_studies_run_in_workers_on_the_sets_asked_for(tmp_path):
    config = dataclasses.replace(
        QUICK, workers=1, laws=("whittaker", "newton"), measurements=("kharaz", "unknown")
    )
    found = measured.results(Context(config, tmp_path))
    assert list(found.studies) == ["kharaz"]
    assert any("unknown" in note for note in found.notes)
    study = found.studies["kharaz"]
    assert study.table.iloc[0]["law"] == "whittaker"
    assert set(found.kharaz["law"]) == {"whittaker"}  # the frictional laws asked for


def test_the_quick_report_leaves_the_engines_fits_to_the_full_one():
    """Each set's tasks hold every engine alone in the full report and none in the quick one:
    tuned, an engine steps each trial of a fit for up to tenths of a second."""
    engines = {name for name in LAWS.names() if LAWS.get(name).engine}
    for name in ("ellipse", "cube", "kharaz"):
        chosen = MEASUREMENTS.get(name)
        quick = {law for _, laws, _ in measured.tasks(chosen, LAWS.names(), True) for law in laws}
        full = [laws for _, laws, _ in measured.tasks(chosen, LAWS.names(), False)]
        assert quick and not quick & engines
        assert all([engine] in full for engine in engines)
