"""The comparison report: its sections, files, verdicts, reproducers, and the page in a browser.

Most tests read one small report (the closed-form and single-contact laws on a few scenes)
written once into a temporary folder; the slow tests run the true quick mode end to end.
"""

import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import CLOSED_FORM, SMALL
from matplotlib.backends.backend_agg import FigureCanvasAgg

import lawbench
from lawbench.core.verdicts import Verdict
from lawbench.studies.declared import STUDIES
from lawbench.views.report import write_report
from lawbench.views.report.config import view
from lawbench.views.report.inside import QUANTITIES
from lawbench.views.report.marks import Mark
from lawbench.views.report.outcomes import _figure as outcomes_figure
from lawbench.views.report.page import Figure, Legend, Section, Table, write_page
from lawbench.views.report.plots import figure, log_scale
from lawbench.views.report.tradeoff import pareto

SECTIONS = ("summary", "outcomes", "tradeoff", "stability", "paradoxes", "dispersion", "inside")
DECADE_STUDIES = (
    "three_ball_chain_stiffness",
    "three_ball_chain_masses",
    "three_ball_chain_grazing",
    "ball_chain_masses",
)
ROUNDING = 1e-12
CHROMIUM = Path("/usr/bin/chromium")
CLASSES = {str(v) for v in Verdict}
SET_ASIDE = ("numerical failure", "budget", "unexplained")


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The true quick report, every law and scene, and its wall time."""
    start = time.perf_counter()
    out = write_report(tmp_path_factory.mktemp("report") / "quick", mode="quick")
    return out, time.perf_counter() - start


def figures_of(page: str) -> list[str]:
    return re.findall(r'<img src="([^"]+)\.svg"', page)


def runs(out: Path) -> dict[str, pd.DataFrame]:
    """Every study table of a report, by study."""
    return {p.stem: pd.read_parquet(p) for p in sorted((out / "runs").glob("*.parquet"))}


# Helpers.


def test_the_pareto_front_keeps_the_points_nothing_beats():
    cost = np.array([1.0, 2.0, 3.0, 2.5])
    error = np.array([1e-2, 1e-4, 1e-6, 1e-3])
    assert pareto(cost, error).tolist() == [True, True, True, False]


def test_log_axes_are_labelled_in_plain_text_powers_of_ten():
    """Decades read 10⁻⁶, the multiples within a decade 2×10⁻⁶: no TeX markup to lay out.

    Below a decade only 2 and 5 times a power of ten are labelled, so labels never collide."""
    fig, axes = figure(1, 1)
    ax = axes[0, 0]
    ax.plot([1e-6, 1e-3], [2e-6, 8e-6])
    log_scale(ax, "xy")
    FigureCanvasAgg(fig).draw()
    decades = [t.get_text() for t in ax.get_xticklabels()]
    within = [t.get_text() for t in ax.get_yticklabels(minor=True)]
    assert {"10⁻⁶", "10⁻⁵", "10⁻⁴", "10⁻³"} <= set(decades)
    assert {"2×10⁻⁶", "5×10⁻⁶"} == set(within) - {""}
    assert all("$" not in label for label in decades + within)


def test_velocities_of_different_units_never_share_an_axis():
    coordinates = ["vx [m/s]", "vy [m/s]", "omega [rad/s]"]
    data = pd.DataFrame(
        {
            "source": ["before the impact"] * 3 + ["newton"] * 3,
            "kind": ["v-"] * 3 + ["law"] * 3,
            "coordinate": coordinates * 2,
            "value": [1.0, -2.0, 0.5, 1.0, 1.0, 0.1],
        }
    )
    fig = outcomes_figure(data, coordinates, "rod")
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["velocity [m/s]", "velocity [rad/s]"]


def test_an_outcome_figure_with_every_law_keeps_its_plot_area_wide():
    """Every law, two references and their legend on a two-ball scene: the plot area is at
    least a third of the figure as saved (its tight bounding box), the legend below it."""
    coordinates = ["v1 [m/s]", "v2 [m/s]"]
    laws = [law.name for law in lawbench.LAWS.values()]
    references = [
        "ground truth: compliant (tol=1e-10)",
        "reference eq. (27) (sequential, order=right_to_left)",
    ]
    sources = ["before the impact", *laws, *references]
    kinds = ["v-", *(["law"] * len(laws)), *(["reference"] * len(references))]
    data = pd.DataFrame(
        {
            "source": [s for s in sources for _ in coordinates],
            "kind": [k for k in kinds for _ in coordinates],
            "coordinate": coordinates * len(sources),
            "value": np.linspace(-1.0, 1.0, 2 * len(sources)),
        }
    )
    fig = outcomes_figure(data, coordinates, "ping_pong")
    renderer = FigureCanvasAgg(fig).get_renderer()
    whole = fig.get_tightbbox(renderer).width * fig.dpi
    (ax,) = fig.axes
    assert ax.get_window_extent(renderer).width >= whole / 3


def test_no_path_quantity_is_drawn_under_a_bare_symbol():
    for key, (name, unit) in QUANTITIES.items():
        assert name != key and unit, key
    assert QUANTITIES["Wn"][0] == "work of the normal impulse"


# The page writer.


def test_the_page_writes_every_file_escapes_and_keeps_the_rerun_command(tmp_path):
    fig, axes = figure(1, 1)
    axes[0, 0].plot([1, 2], [3, 4])
    data = pd.DataFrame({"x": [1, 2], "y": [3, 4]})
    table = pd.DataFrame(
        {
            "id": ["row-1"],
            "text": ["see [row](#row-1) and `code` <script>x</script>"],
            "verdict": [[Mark("e", Verdict.LAW_PROPERTY, "a <reason>", "#row-1")]],
            "command": ["lawbench solve newton three_ball_chain"],
            "within 1e-06": ["x"],
        }
    )
    section = Section(
        "first",
        "First",
        [
            "A paragraph.",
            Legend(),
            Table("t", "A table.", table, anchors="id", commands=("command",)),
            Figure("f", "A figure.", fig, data),
        ],
    )
    write_page(tmp_path, "Title", ["Intro."], [section], "lawbench report --quick --out X")
    for name in ("t.csv", "f.svg", "f.csv", "index.html", "report.md"):
        assert (tmp_path / name).stat().st_size > 0, name
    page = (tmp_path / "index.html").read_text()
    assert 'id="row-1"' in page and 'href="#row-1"' in page and "<code>code</code>" in page
    assert "<script>" not in page and "&lt;script&gt;" in page
    assert 'title="a &lt;reason&gt;"' in page
    assert '<code class="reproducer">lawbench solve newton three_ball_chain</code>' in page
    assert "Rerun: <code>lawbench report --quick --out X</code>" in page
    markdown = (tmp_path / "report.md").read_text()
    assert '<a id="row-1"></a>' in markdown and "[e✗](#row-1)" in markdown
    assert pd.read_csv(tmp_path / "t.csv")["verdict"].tolist() == ["[e✗](#row-1)"]
    # A browser breaks a line after a hyphen: a header's exponent keeps its digits together.
    assert "<th>within 1e\u201106</th>" in page
    assert "within 1e-06" in pd.read_csv(tmp_path / "t.csv").columns


# The small report.


def test_every_section_is_in_both_pages(report):
    page, markdown = (report / "index.html").read_text(), (report / "report.md").read_text()
    for anchor in SECTIONS:
        assert re.search(rf'<h3 id="{anchor}">', page), anchor
        assert f'<a id="{anchor}"></a>' in markdown, anchor
    assert "This section failed" not in page


def test_every_figure_has_svg_csv_and_a_caption_with_the_rerun_command(report):
    page = (report / "index.html").read_text()
    names = figures_of(page)
    expected = {"stability_errors", "paradoxes_falling_rod", "paradoxes_double_pendulum"}
    expected |= {f"tradeoff_{c}" for c in ("three_ball_chain", "lamina", "falling_rod")}
    expected |= {f"shares_{c}" for c in ("three_ball_chain", "two_balls_wall")}
    expected |= {f"continuity_{c}" for c in ("three_ball_chain", "two_balls_wall")}
    expected |= {f"stability_{law}" for law in SMALL.laws}
    expected |= {"inside_darboux_keller_lamina"}
    assert expected <= set(names)
    for name in names:
        for ext in ("svg", "csv"):
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


def test_every_cell_of_every_study_has_one_verdict_of_the_taxonomy(report):
    tables = runs(report)
    assert {"summary", "three_ball_chain_stiffness", "falling_rod_energy_map"} <= set(tables)
    for name, table in tables.items():
        assert set(table["verdict"]) <= CLASSES, name
        checks = [c for c in table.columns if c.endswith("_verdict")]
        for column in checks:
            answered = table[table["error_class"].fillna("") == ""]
            assert set(answered[column]) <= CLASSES, (name, column)


def test_the_summary_matrix_marks_and_links_the_findings(report):
    findings = pd.read_csv(report / "findings.csv")
    rows = pd.read_csv(report / "comparison.csv").set_index(["law", "case"])
    page = (report / "index.html").read_text()
    observed = findings[findings["in this run"].str.startswith("met on ")]
    assert len(observed) > 0, "no finding of the selected laws is at a scene's defaults"
    for finding in observed.itertuples():
        for case in finding._5.removeprefix("met on ").split(", "):
            assert rows.loc[(finding.law, case), finding.check] == "law property"
        assert f'class="mark v-law-property" href="#{finding.finding}"' in page
        assert f'<tr id="{finding.finding}">' in page


def test_a_law_refusing_a_scene_looks_like_a_check_that_does_not_apply(report):
    rows = pd.read_csv(report / "comparison.csv").set_index(["law", "case"])
    assert rows.loc[("brach", "three_ball_chain"), "verdict"] == "refused"
    page = (report / "index.html").read_text()
    refused = re.findall(r'<span class="mark v-refused" title="([^"]*)">([^<]*)</span>', page)
    assert any("NotApplicable" in title and text == "·" for title, text in refused)
    holds = re.findall(r'<span class="mark v-holds" title="([^"]*)">([^<]*)</span>', page)
    assert any("friction_cone: refused" in title and text == "✓" for title, text in holds)


@pytest.mark.parametrize(
    ("verdict", "name", "plural"),
    [
        ("unexplained", "unexplained", "unexplained"),
        ("numerical failure", "numerical_failures", "numerical failures"),
        ("budget", "budgets", "budgets"),
    ],
)
def test_the_headline_counts_each_kind_of_bad_cell_and_links_its_list(
    report, verdict, name, plural
):
    """Unexplained cells, numerical failures and budgets are each counted in the headline,
    linked to their list, and each listed cell has its reproducer."""
    counted = sum(
        int(((t["verdict"] == verdict) & (t["repeat"] == 0)).sum()) for t in runs(report).values()
    )
    page = (report / "index.html").read_text()
    markdown = (report / "report.md").read_text()
    if counted == 0:
        assert f"0 {plural}" in page
        assert not (report / f"{name}.csv").exists()
        return
    assert f'<a href="#{name}">{counted} {plural}</a>' in page
    assert f'<table id="{name}"' in page
    assert f"[{counted} {plural}](#{name})" in markdown and f'<a id="{name}"></a>' in markdown
    listed = pd.read_csv(report / f"{name}.csv")
    assert len(listed) == counted
    assert listed["reproducer"].str.startswith("lawbench solve ").all()


def _answered(tables: dict[str, pd.DataFrame], names) -> pd.DataFrame:
    frames = [tables[name] for name in names if name in tables]
    table = pd.concat(frames, ignore_index=True)
    return table[table["error_class"].fillna("") == ""]


def test_the_stability_grid_has_no_nan_and_no_time_out(report):
    tables = runs(report)
    stability = [s.name for s in STUDIES.values() if view(s) == "stability"]
    cells = pd.concat([tables[n] for n in stability if n in tables], ignore_index=True)
    assert set(cells["verdict"]) <= CLASSES
    budget = cells[cells["verdict"] == "budget"]
    assert (budget["budget"] != "").all() and budget["spent_s"].notna().all()
    answered = cells[cells["error_class"].fillna("") == ""]
    for vector in answered["v_plus"]:
        assert np.isfinite(vector).all()


def test_closed_form_laws_conserve_to_rounding_across_all_decades(report):
    cells = _answered(runs(report), DECADE_STUDIES)
    cells = cells[cells["law"].isin(CLOSED_FORM)]
    assert set(cells["law"]) == set(CLOSED_FORM)
    assert (cells["momentum_value"].fillna(0.0).abs() <= ROUNDING).all()
    assert (cells["energy_gain_value"] <= ROUNDING).all()


def test_speed_accuracy_shows_model_and_numerical_error_apart(report):
    points = pd.read_csv(report / "tradeoff_three_ball_chain.csv")
    scene = lawbench.CASES.get("three_ball_chain")
    able = {name for name in SMALL.laws if lawbench.LAWS.get(name).tags.covers(scene.requires)}
    measured = points[points["failure"].isna()]
    assert set(measured["law"]) == able
    assert (measured["wall_time_s"] > 0).all()
    assert measured["model_error"].notna().all()
    exact = measured[measured["knob"].isna()]
    assert (exact["numerical_error"] == 0).all()
    answer = pd.read_csv(report / "answer.csv").set_index("scene")
    truth = answer.loc["[three_ball_chain](#scene-three_ball_chain)", "ground truth"]
    assert truth == "compliant (tol=1e-10)"
    page = (report / "index.html").read_text()
    assert "model error against the ground truth, compliant (tol=1e-10)" in page


def test_every_declared_study_is_on_the_page_or_listed_with_why_it_is_not(report):
    page = (report / "report.md").read_text()
    ran = set(runs(report))
    (line,) = [x for x in page.splitlines() if x.startswith("Declared studies left out")]
    for study in STUDIES.values():
        assert (study.name in ran) != (f"`{study.name}`: " in line), study.name


def test_the_paradox_table_is_tidy_one_row_per_scene_and_law(report):
    """No pseudo-law row: the points where no law gains are said in a sentence per map."""
    table = pd.read_csv(report / "paradoxes_regions.csv")
    assert not table.duplicated(["case", "law"]).any()
    assert set(table["law"]) <= set(lawbench.LAWS.names())
    page = (report / "report.md").read_text()
    for case in set(table["case"]):
        pattern = rf"On `{case}`, every law answered at \d+ of the \d+ points; at \d+ of them"
        assert re.search(pattern, page), case


def test_budget_cells_say_which_budget_and_after_how_long(report):
    attention = pd.read_csv(report / "stability_attention.csv")
    budget = attention[attention["verdict"] == "budget"]
    assert len(budget), "no budget cell in the small grid"
    # A law's own budget (max_steps = ...) or the cell's (wall-clock guard = 5 s).
    named = re.compile(r"budget [\w -]+ = [\d.e+]+( s)?, after [\d.e+-]+ s")
    for row in budget.itertuples():
        assert named.search(row.detail), row.detail


def _shown_commands(report: Path) -> list[tuple[str, int]]:
    """Every reproducer the report's tables show, with the exit status shown beside it."""
    shown = []
    for name in ("unexplained.csv", "stability_attention.csv"):
        path = report / name
        if path.exists():
            table = pd.read_csv(path)
            shown += list(zip(table["reproducer"], table["exit status"], strict=True))
    return shown


def test_reproducers_rerun_their_cell_and_exit_with_the_status_shown(report):
    """A sample of the report's reproducers, each run as a user would, every status covered."""
    cells = pd.concat(runs(report).values(), ignore_index=True)
    sample = cells.drop_duplicates("reproducer").groupby("exit_status").head(2)
    commands = list(zip(sample["reproducer"], sample["exit_status"], strict=True))
    commands += _shown_commands(report)[:4]
    transformed = cells[cells["transform"] != ""].drop_duplicates("reproducer").head(2)
    commands += list(zip(transformed["reproducer"], transformed["exit_status"], strict=True))
    assert {0, 3, 4} <= {status for _, status in commands}
    processes = [
        (
            command,
            status,
            subprocess.Popen(
                [sys.executable, "-m", *command.split()],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
            ),
        )
        for command, status in commands
    ]
    for command, status, process in processes:
        _, stderr = process.communicate(timeout=300)
        assert process.returncode == status, (command, stderr)


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
        for ext in ("svg", "csv"):
            assert (out / f"{name}.{ext}").stat().st_size > 0, (name, ext)
    for scene in ("three_ball_chain", "lamina", "bead_column"):
        assert f"tradeoff_{scene}" in figures_of(page), scene
    assert seconds < 300


def _answer_without_costs(out: Path) -> pd.DataFrame:
    """A report's answer table with the costs taken out of its cells ("lzb (tol=1e-10)")."""
    table = pd.read_csv(out / "answer.csv", keep_default_na=False)
    return table.replace(r", [\d.]+ [um]?s$", "", regex=True)


@pytest.mark.slow
def test_two_quick_reports_in_a_row_give_the_same_answer_but_for_the_costs(quick, tmp_path):
    """Each cost is a median of timed solves and a tie within the noise goes to the loosest
    tolerance, then the name: a second quick report chooses the same laws."""
    again = write_report(tmp_path / "again", mode="quick")
    first = _answer_without_costs(quick[0])
    assert first.map(lambda text: " ms" in text or text.endswith(" s")).sum().sum() == 0
    assert (first != "none").any(axis=None)
    pd.testing.assert_frame_equal(first, _answer_without_costs(again))


@pytest.mark.slow
def test_the_quick_stability_grid_has_no_nan_and_no_time_out(quick):
    tables = runs(quick[0])
    stability = [s.name for s in STUDIES.values() if view(s) == "stability"]
    cells = pd.concat([tables[n] for n in stability if n in tables], ignore_index=True)
    assert set(cells["verdict"]) <= CLASSES
    assert not (cells["error_class"].fillna("") == "WorkerDied").any()
    budget = cells[cells["verdict"] == "budget"]
    assert (budget["budget"] != "").all()


def test_a_path_study_along_a_parameter_draws_each_cell_side_by_side():
    """disk_ball_energies, the central figure of Zhang et al. 2013: the stored energy per
    contact (J) at three impact heights, one panel per height on a shared energy axis, a row
    for the energetic law (against its impulse-time variable) and a row for the compliant
    ground truth (against time). A contact's energy is never negative and ends at zero (every
    spring relaxes when the impact ends); struck high, lzb's primary contact passes from the
    ball D to the floor's far point C."""
    from lawbench.studies.runner import Executor, collect
    from lawbench.views.report.inside import _along

    study = STUDIES.get("disk_ball_energies")
    with Executor() as pool:
        table = collect(study.plan(), pool)
    drawn = _along(lawbench.CASES.get("disk_ball"), study, table)
    shown = [ax for ax in drawn.figure.axes if ax.get_visible()]
    assert [ax.get_title() for ax in shown] == [
        f"{law}, b = {b} m" for law in ("lzb", "compliant") for b in ("-0.045", "0", "0.045")
    ]
    assert {ax.get_ylabel() for ax in shown} == {"stored energy [J]"}
    assert [ax.get_xlabel() for ax in shown[3:]] == ["time [s]"] * 3
    assert "lzb, b = 0.045 m: stored_energy_peaks = [" in drawn.caption
    assert "primary_contacts = [3, 2]" in drawn.caption
    data = drawn.data
    assert set(data["law"]) == {"lzb", "compliant"}
    assert set(data["component"]) == {f"contact {j}" for j in range(4)}
    assert (data["value"] >= -1e-12 * data["value"].max()).all()
    for _, group in data.groupby(["law", "b", "component"]):
        assert group["value"].iloc[-1] <= 1e-9 * data["value"].max()
