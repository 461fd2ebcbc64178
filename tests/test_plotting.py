"""Figures in matplotlib's convention: drawn on the axes given (a new figure's when none),
the axes returned."""

import subprocess
import sys

import matplotlib
import pytest

import lawbench
from lawbench.views.report.plots import law_style

matplotlib.use("Agg")
import matplotlib.pyplot as plt


@pytest.fixture
def ax():
    figure, axes = plt.subplots()
    yield axes
    plt.close(figure)


@pytest.fixture(scope="module")
def run_table(tmp_path_factory):
    from lawbench.views.cli import main

    out = tmp_path_factory.mktemp("sweep") / "e.parquet"
    args = ["run", "--laws", "newton,moreau", "--cases", "three_ball_chain", "--param"]
    assert main([*args, "e=0,0.5,1", "--executor", "serial", "--out", str(out)]) == 0
    return lawbench.load_run(out)


def test_importing_lawbench_does_not_import_matplotlib():
    code = "import sys, lawbench; print('matplotlib' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "False", done.stderr


def test_plot_outcome_draws_bars_before_and_after_named_by_coordinate(ax):
    trial = lawbench.evaluate("moreau", "rocking_block")
    assert lawbench.plot_outcome(trial, ax=ax) is ax
    assert len(ax.patches) == 2 * 3
    assert [t.get_text() for t in ax.get_xticklabels()] == ["vx", "vy", "omega"]
    heights = [p.get_height() for p in ax.patches]
    assert heights[:3] == pytest.approx(list(trial.problem.v))
    assert heights[3:] == pytest.approx(list(trial.outcome.v_plus))


def test_plot_outcome_of_an_outcome_draws_its_pre_impact_velocity(ax):
    outcome = lawbench.solve("newton", "three_ball_chain", e=1)
    assert lawbench.plot_outcome(outcome, ax=ax) is ax
    assert [p.get_height() for p in ax.patches][:3] == pytest.approx([1.0, 0.0, 0.0])
    assert ax.get_ylabel() == "velocity"
    assert [t.get_text() for t in ax.get_xticklabels()] == ["q1", "q2", "q3"]


@pytest.mark.parametrize(
    ("law", "case", "key", "lines"),
    [
        ("lzb", "three_ball_chain", "stored_energy", 2),
        ("compliant", "three_ball_chain", "force", 2),
        ("darboux_keller", "falling_rod", "v", 3),
        ("jia", "bouncing_ball", "Pt", 2),
    ],
)
def test_plot_path_draws_each_component_against_the_impact_variable(ax, law, case, key, lines):
    outcome = lawbench.solve(law, case, {"path": True})
    assert lawbench.plot_path(outcome, key, ax=ax) is ax
    assert len(ax.lines) == lines
    first = next(iter(outcome.path))
    assert list(ax.lines[0].get_xdata()) == pytest.approx(list(outcome.path[first]))


def test_plot_path_names_what_is_missing():
    with pytest.raises(lawbench.InvalidProblem, match="path=True"):
        lawbench.plot_path(lawbench.solve("lzb", "three_ball_chain"))
    with pytest.raises(lawbench.InvalidProblem, match="no 'colour'; it holds Pn_sum, t, Pn"):
        lawbench.plot_path(lawbench.solve("lzb", "three_ball_chain", {"path": True}), "colour")


def test_plot_sweep_draws_one_line_per_law_with_units(ax, run_table):
    assert lawbench.plot_sweep(run_table, "e", "v_plus[2]", ax=ax) is ax
    assert [line.get_label() for line in ax.lines] == ["moreau", "newton"]
    assert list(ax.lines[1].get_xdata()) == [0.0, 0.5, 1.0]
    assert ax.get_xlabel() == "e [-]" and ax.get_ylabel() == "v_plus[2] [m/s]"
    newton = law_style("newton")["color"]
    assert matplotlib.colors.to_rgba(ax.lines[1].get_color()) == matplotlib.colors.to_rgba(newton)
    with pytest.raises(lawbench.InvalidProblem, match="no column 'colour'"):
        lawbench.plot_sweep(run_table, "e", "colour", ax=ax)


def test_without_axes_each_draws_on_a_new_figure(run_table):
    outcome = lawbench.solve("lzb", "three_ball_chain", {"path": True})
    drawn = [
        lawbench.plot_outcome(outcome),
        lawbench.plot_path(outcome),
        lawbench.plot_sweep(run_table, "e", "dT"),
    ]
    assert len({id(ax.figure) for ax in drawn}) == len(drawn)
    assert all(ax.patches or ax.lines for ax in drawn)
    plt.close("all")


def test_no_legend_sits_on_its_axes(run_table):
    outcome = lawbench.solve("lzb", "three_ball_chain", {"path": True})
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.5), layout="tight")
    lawbench.plot_outcome(outcome, ax=axes[0])
    lawbench.plot_path(outcome, ax=axes[1])
    lawbench.plot_sweep(run_table, "e", "dT", ax=axes[2])
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in axes:
        box = ax.get_legend().get_window_extent(renderer)
        assert not any(box.overlaps(other.get_window_extent(renderer)) for other in axes)
    plt.close(fig)
