"""The comparison report: its sections, files, captions, verdicts, and the page in a browser.

Most tests read one small report (the closed-form and single-contact laws on a few scenes,
small grids) written once into a temporary folder; the slow tests run every law, and the true
quick mode end to end.
"""

import dataclasses
import math
import re
import subprocess
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import lawbench
from lawbench.guard import Guard
from lawbench.report import QUICK, write_report
from lawbench.report.extremes import (
    UNACCEPTABLE,
    Cell,
    duplicated,
    grazing,
    verdict,
)
from lawbench.report.page import Figure, Section, Table, write_page
from lawbench.report.plots import figure
from lawbench.report.tradeoff import knob_values, pareto

SECTIONS = ("summary", "outcomes", "tradeoff", "stability", "paradoxes", "dispersion", "inside")
CLOSED_FORM = ("newton", "poisson", "sequential", "moreau")
DECADE_AXES = ("stiffness ratio", "mass ratio", "grazing speed", "chain length")
ROUNDING = 1e-12
CHROMIUM = Path("/usr/bin/chromium")

# The closed-form laws and one single-contact law on the scenes every section needs.
SMALL = dataclasses.replace(
    QUICK,
    laws=(*CLOSED_FORM, "darboux_keller"),
    cases=("three_ball_chain", "two_balls_wall", "ball_chain", "falling_rod", "double_pendulum"),
    tradeoff_cases=("three_ball_chain", "falling_rod"),
    knob_values=(1e-4, 1e-8),
    repeats=1,
    stiffness_ratios=(1e-8, 1.0, 1e8),
    mass_ratios=(1e-6, 1e-3, 1e3, 1e6),
    grazing_speeds=(1e-6, 1e-12),
    chain_lengths=(20,),
    map_points=3,
    share_ratios=(1e-3, 1e3),
    jump_sizes=(1e-2, 1e-6),
)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    return write_report(tmp_path_factory.mktemp("report") / "small", config=SMALL)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The true quick report, every law and scene, and its wall time."""
    start = time.perf_counter()
    out = write_report(tmp_path_factory.mktemp("report") / "quick", mode="quick")
    return out, time.perf_counter() - start


def figures_of(page: str) -> list[str]:
    return re.findall(r'<img src="([^"]+)\.png"', page)


# The guard: answers, errors and time-outs.


def test_the_guard_returns_answers_and_errors_and_stops_a_task_over_its_budget():
    with Guard(workers=1, budget_s=30.0) as guard:
        slow = guard.submit(time.sleep, 60, budget=2.0)
        failing = guard.submit(math.sqrt, -1.0)
        fine = guard.submit(math.sqrt, 4.0)
        start = time.monotonic()
        assert guard.result(slow).status == "time-out"
        assert time.monotonic() - start < 20
        error = guard.result(failing)
        assert (error.status, error.error_class) == ("error", "ValueError")
        assert guard.result(fine).value == 2.0


# The problems of the stability grid.


@pytest.mark.parametrize("case", ["three_ball_chain", "falling_rod", "sphere_wall"])
def test_grazing_scales_every_gap_rate_and_keeps_what_the_contacts_do_not_see(case):
    problem = lawbench.CASES.get(case).build()
    made = grazing(problem, 1e-9)
    fastest = -problem.un.min()
    # Gap rates at rest stay at rest up to the rounding of the velocities they subtract.
    rounding = 1e-15 * np.abs(problem.v).max()
    np.testing.assert_allclose(made.un, problem.un * 1e-9 / fastest, rtol=1e-6, atol=rounding)
    # The change is M^-1 Wn x: invisible to every w with Wn.T w = 0 in the kinetic metric.
    _, _, vt = np.linalg.svd(problem.Wn.T)
    hidden = vt[problem.m :]
    np.testing.assert_allclose(hidden @ problem.M @ made.v, hidden @ problem.M @ problem.v)


@pytest.mark.parametrize("law", ["newton", "moreau", "poisson"])
def test_a_contact_given_twice_changes_no_outcome(law):
    """The same constraint twice is the same set of admissible velocities.

    Moreau's law projects on the tangent cone (Brogliato 2010, eqs. 16-17), Newton's solves
    ``Wn.T v+ = -e Wn.T v-``, Poisson's two complementarity problems: none of these sets
    changes when a column of Wn is repeated, so the post-impact velocity stays.
    """
    problem = lawbench.CASES.get("three_ball_chain").build(e=[0.5])
    twice = duplicated(problem)
    assert twice.m == problem.m + 1
    solver = lawbench.LAWS.get(law)
    once, again = solver.resolve(problem), solver.resolve(twice)
    np.testing.assert_allclose(again.v_plus, once.v_plus, atol=1e-9)
    np.testing.assert_allclose(again.Pn[0] + again.Pn[-1], once.Pn[0], atol=1e-9)


def _record(v_plus, Pn, **fields):
    return {"v_plus": list(v_plus), "Pn": list(Pn), "Pt": [], "error_class": "", **fields}


def test_verdicts_tell_the_kinds_of_failure_apart():
    case = lawbench.CASES.get("three_ball_chain")
    problem = case.build(e=[1.0])
    law = lawbench.LAWS.get("newton")
    outcome = law.resolve(problem)
    axes = case.momentum_axes(case.parameters())
    cell = Cell("newton", "mass ratio", case.name, 1.0, 1.0)

    def judge(record):
        return verdict(cell, record, problem, axes, law, budget=10.0)["verdict"]

    right = _record(outcome.v_plus, outcome.Pn, dT=outcome.dT, wall_time_s=0.0)
    assert judge(right) == "ok"
    assert judge({**right, "wall_time_s": 11.0}) == "time-out"
    assert judge({"error_class": "TimeOut", "error_message": "stopped"}) == "time-out"
    assert judge({"error_class": "NotApplicable", "error_message": "no"}) == "clear error"
    message = "newton: non-finite v_plus [nan 0. 0.]"
    assert judge({"error_class": "SolverFailure", "error_message": message}) == "NaN"
    assert judge({"error_class": "ZeroDivisionError", "error_message": "x"}) == "unexpected error"
    assert judge(_record([np.nan, 0, 0], outcome.Pn)) == "NaN"
    slower = _record(outcome.v_plus * 0.9, outcome.Pn, dT=-0.1)
    assert judge(slower) == "conservation broken"
    separating = case.build(velocities=[1.0, 0.0, 0.75], e=[1.0])
    tensile = law.resolve(separating)  # a finding of Newton's law: a tensile impulse
    record = _record(tensile.v_plus, tensile.Pn, dT=tensile.dT)
    assert verdict(cell, record, separating, axes, law, 10.0)["verdict"] == "check failed"


# Helpers of the speed/accuracy study.


def test_the_pareto_front_keeps_the_points_nothing_beats():
    cost = np.array([1.0, 2.0, 3.0, 2.5])
    error = np.array([1e-2, 1e-4, 1e-6, 1e-3])
    assert pareto(cost, error).tolist() == [True, True, True, False]


def test_accuracy_knobs_are_swept_within_their_specs():
    for law in lawbench.LAWS:
        knob, values = knob_values(law, (1.0, 1e-3, 1e-6, 1e-9))
        if law.tags.accuracy_knob is None:
            assert values == [None]
            continue
        spec = next(s for s in law.options if s.name == knob)
        assert values, law.name
        for value in values:
            spec.coerce(value)


# The page writer.


def test_the_page_writes_every_file_and_the_rerun_command(tmp_path):
    fig, axes = figure(1, 1)
    axes[0, 0].plot([1, 2], [3, 4])
    data = pd.DataFrame({"x": [1, 2], "y": [3, 4]})
    table = pd.DataFrame({"id": ["row-1"], "text": ["see [row](#row-1) and `code`"]})
    section = Section(
        "first",
        "First",
        [
            "A paragraph.",
            Table("t", "A table.", table, anchors="id"),
            Figure("f", "A figure.", fig, data),
        ],
    )
    write_page(tmp_path, "Title", ["Intro."], [section], "lawbench report --quick --out X")
    for name in ("t.csv", "f.png", "f.svg", "f.csv", "index.html", "report.md"):
        assert (tmp_path / name).stat().st_size > 0, name
    page = (tmp_path / "index.html").read_text()
    assert 'id="row-1"' in page and 'href="#row-1"' in page and "<code>code</code>" in page
    assert "Rerun: <code>lawbench report --quick --out X</code>" in page
    assert '<a id="row-1"></a>' in (tmp_path / "report.md").read_text()


# The small report.


def test_every_section_is_in_both_pages(report):
    page, markdown = (report / "index.html").read_text(), (report / "report.md").read_text()
    for anchor in SECTIONS:
        assert f'<h2 id="{anchor}">' in page, anchor
        assert f'<a id="{anchor}"></a>' in markdown, anchor
    assert "This section failed" not in page


def test_every_figure_has_png_svg_csv_and_a_caption_with_the_rerun_command(report):
    page = (report / "index.html").read_text()
    names = figures_of(page)
    expected = {"stability_errors", "paradoxes_falling_rod", "paradoxes_double_pendulum"}
    expected |= {f"tradeoff_{c}" for c in SMALL.tradeoff_cases}
    expected |= {f"shares_{c}" for c in ("three_ball_chain", "two_balls_wall")}
    expected |= {f"stability_{law}" for law in SMALL.laws}
    assert expected <= set(names)
    for name in names:
        for ext in ("png", "svg", "csv"):
            assert (report / f"{name}.{ext}").stat().st_size > 0, (name, ext)
    captions = re.findall(r"<figcaption>(.*?)</figcaption>", page, flags=re.S)
    assert len(captions) == len(names)
    rerun = f"lawbench report --quick --out {report}"
    for caption in captions:
        assert f"Rerun: <code>{rerun}</code>" in caption, caption


def test_every_table_is_written_as_csv(report):
    page = (report / "index.html").read_text()
    tables = re.findall(r'Table: <a href="([^"]+\.csv)">', page)
    assert {"comparison.csv", "findings.csv", "stability_summary.csv"} <= set(tables)
    for name in tables:
        assert (report / name).is_file(), name
    rows = pd.read_csv(report / "comparison.csv")
    assert set(rows["law"]) == set(SMALL.laws)


def test_the_summary_matrix_marks_and_links_the_findings(report):
    findings = pd.read_csv(report / "findings.csv")
    rows = pd.read_csv(report / "comparison.csv").set_index(["law", "case"])
    page = (report / "index.html").read_text()
    observed = findings[findings["in this run"].str.startswith("met on ")]
    assert len(observed) > 0, "no finding of the selected laws is at a scene's defaults"
    for finding in observed.itertuples():
        for case in finding._5.removeprefix("met on ").split(", "):
            assert rows.loc[(finding.law, case), finding.check] == "law property"
        assert f'href="#{finding.finding}"' in page
        assert f'<tr id="{finding.finding}">' in page


def _stability(report: Path) -> pd.DataFrame:
    laws = pd.read_csv(report / "stability_summary.csv")["law"]
    return pd.concat([pd.read_csv(report / f"stability_{law}.csv") for law in laws])


def _listed(cells: pd.DataFrame) -> str:
    """One line per cell, with its reproducer, for an assertion message."""
    return "\n".join(
        f"{c.law} {c.axis} {c.value:g} (e={c.e}): {c.verdict} {c.detail}; {c.reproducer}"
        for c in cells.itertuples()
    )


def test_the_stability_grid_has_no_nan_and_no_time_out(report):
    cells = _stability(report)
    bad = cells[cells["verdict"].isin(UNACCEPTABLE)]
    assert bad.empty, _listed(bad)


def test_closed_form_laws_conserve_to_rounding_across_all_decades(report):
    cells = _stability(report)
    cells = cells[cells["law"].isin(CLOSED_FORM) & cells["axis"].isin(DECADE_AXES)]
    assert set(cells["law"]) == set(CLOSED_FORM)
    answered = cells[cells["momentum_error"].notna()]
    assert len(answered) > len(cells) / 2
    worst = answered.loc[:, ["momentum_error", "energy_error"]].max(axis=1)
    bad = answered[worst > ROUNDING]
    assert bad.empty, _listed(bad)


def test_the_speed_accuracy_study_has_a_point_for_every_law_on_the_chain(report):
    points = pd.read_csv(report / "tradeoff_three_ball_chain.csv")
    scene = lawbench.CASES.get("three_ball_chain")
    able = {name for name in SMALL.laws if lawbench.LAWS.get(name).tags.covers(scene.requires)}
    measured = points[points["error"].notna()]
    assert set(measured["law"]) == able
    assert (measured["wall_time_s"] > 0).all()


@pytest.mark.skipif(
    not CHROMIUM.exists(), reason="needs /usr/bin/chromium (Debian package chromium)"
)
def test_the_page_renders_in_chromium_with_every_figure_loaded(report, tmp_path):
    probe = report / "probe.html"
    script = (
        "<script>window.addEventListener('load', () => {"
        "const images = Array.from(document.images);"
        "const broken = images.filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src);"
        "document.body.setAttribute('data-images', images.length);"
        "document.body.setAttribute('data-broken', broken.join(' '));});</script>"
    )
    probe.write_text((report / "index.html").read_text().replace("</body>", script + "</body>"))
    command = [
        str(CHROMIUM),
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--allow-file-access-from-files",
        "--virtual-time-budget=20000",
    ]
    dom = subprocess.run(
        [*command, "--dump-dom", probe.as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    images = int(re.search(r'data-images="(\d+)"', dom)[1])
    assert images == len(figures_of((report / "index.html").read_text())) > 0
    assert 'data-broken=""' in dom, re.search(r'data-broken="([^"]*)"', dom)[1]
    for anchor in SECTIONS:
        assert f'id="{anchor}"' in dom, anchor
    shot = tmp_path / "page.png"
    subprocess.run(
        [*command, f"--screenshot={shot}", "--window-size=1280,2000", probe.as_uri()],
        capture_output=True,
        timeout=120,
        check=True,
    )
    assert shot.stat().st_size > 10_000
    probe.unlink()


# Slow: the true quick mode, every law and scene.


@pytest.mark.slow
def test_the_quick_report_end_to_end(quick):
    out, seconds = quick
    print(f"quick report: {seconds:.1f} s wall time")
    page = (out / "index.html").read_text()
    for anchor in SECTIONS:
        assert f'<h2 id="{anchor}">' in page, anchor
    assert "This section failed" not in page
    for name in figures_of(page):
        for ext in ("png", "svg", "csv"):
            assert (out / f"{name}.{ext}").stat().st_size > 0, (name, ext)
    for scene in ("three_ball_chain", "lamina", "bead_column"):
        if scene in lawbench.CASES:
            assert f"tradeoff_{scene}" in figures_of(page), scene
    assert seconds < 300


@pytest.mark.slow
def test_the_quick_stability_grid_has_no_nan_and_no_time_out(quick):
    cells = _stability(quick[0])
    bad = cells[cells["verdict"].isin(UNACCEPTABLE)]
    assert bad.empty, _listed(bad)
