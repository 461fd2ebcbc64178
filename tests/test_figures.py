"""The report's figures as the page shows them: legends clear of the panels, every series named,
tick labels readable at the page's width and apart, gaps where a value is missing.

The figures are drawn by the report's own sections from small study tables (fast laws on a few
scenes) and small measured studies (closed-form laws on two sets), and saved as the page saves
them; the page shows an SVG at its natural width up to `plots.DISPLAY_WIDTH_PX` and scales a
wider one down, its text with it.
"""

import dataclasses
import itertools
import re

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import SymLogNorm

from lawbench.core.case import CASES
from lawbench.views.report import (
    QUICK,
    inside,
    measured,
    outcomes,
    paradoxes,
    plots,
    sweeps,
    tradeoff,
)
from lawbench.views.report.page import Figure, Table, save_figure
from lawbench.views.report.runs import Context

# Small study tables: (laws, scenes, studies), each run on its own so that no slow law meets a
# large grid. The speed/accuracy study keeps its ground truth's model, compliant contact.
RUNS = (
    (("moreau", "whittaker"), ("falling_rod", "rocking_block"), ("falling_rod_energy_map",)),
    (("moreau", "whittaker"), ("rocking_block",), ("rocking_block",)),
    (("newton", "moreau", "compliant"), ("three_ball_chain",), ("summary",)),
    (
        ("newton", "moreau", "compliant"),
        ("three_ball_chain",),
        ("three_ball_chain_speed_accuracy",),
    ),
    (("lzb",), ("disk_ball",), ("disk_ball_energies",)),
)
# The laws and sets of the section against measurements, the quick report's subsample of each:
# Kharaz's impacts (one planar contact) and the cube's tosses (spatial, several contacts) draw
# its two kinds of scatter plot, and the two frictional laws, in closed form, Kharaz's curves.
MEASURED = (("whittaker", "brach"), ("kharaz", "cube"))
SECTIONS = (sweeps, paradoxes, tradeoff, inside, outcomes, measured)
MIN_PX = 9.0
SVG_WIDTH = re.compile(r'<svg[^>]*\swidth="([\d.]+)pt"')


@pytest.fixture(scope="module")
def context(tmp_path_factory):
    """One context holding the tables of every run of `RUNS`, judging `MEASURED`'s laws and sets."""
    out = tmp_path_factory.mktemp("figures")
    config = dataclasses.replace(QUICK, executor="serial", workers=1, studies=())
    laws, sets = MEASURED
    merged = Context(dataclasses.replace(config, laws=laws, cases=(), measurements=sets), out)
    views = [view for module in SECTIONS for view in module.VIEWS]
    for laws, cases, studies in RUNS:
        run = dataclasses.replace(config, measurements=(), laws=laws, cases=cases, studies=studies)
        ctx = Context(run, out / studies[0])
        ctx.run(views)
        merged.studies += ctx.studies
        merged.cases += [case for case in ctx.cases if case not in merged.cases]
        merged._tables |= ctx._tables
    return merged


@pytest.fixture(scope="module")
def sections(context):
    return {module.ANCHOR: module.build(context) for module in SECTIONS}


def nan_sweep() -> Figure:
    """A sweep whose second measure is missing (NaN) at the middle of the axis for one law."""
    frame = pd.DataFrame(
        {
            "law": ["moreau"] * 3 + ["whittaker"] * 3,
            "x": [0.0, 1.0, 2.0] * 2,
            "speed": [1.0, 2.0, 3.0, 1.5, 2.5, 3.5],
            "curvature": [0.1, np.nan, 0.3, 0.2, 0.2, 0.2],
            "verdict": ["holds"] * 6,
        }
    )
    units = {"x": "m", "speed": "m/s", "curvature": "1/m"}
    return sweeps._figure("nan", "a sweep with a gap", frame, "x", units)


@pytest.fixture(scope="module")
def figures(sections, tmp_path_factory):
    """Every figure drawn, saved as the page saves it, with its natural width in CSS px."""
    out = tmp_path_factory.mktemp("saved")
    drawn = [f for section in sections.values() for f in section.figures()] + [nan_sweep()]
    widths = {}
    for block in drawn:
        save_figure(block.figure, block.name, block.data, out)
        text = (out / f"{block.name}.svg").read_text()
        widths[block.name] = float(SVG_WIDTH.search(text).group(1)) * plots.CSS_DPI / 72.0
        FigureCanvasAgg(block.figure).draw()
    return [(block, widths[block.name]) for block in drawn]


def by_name(figures, prefix: str) -> Figure:
    return next(block for block, _ in figures if block.name.startswith(prefix))


def legends(fig) -> list:
    return [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]


def axis_labels(axis) -> list:
    """The visible, non-empty tick labels of ``axis``, major and minor."""
    ticks = axis.get_major_ticks() + axis.get_minor_ticks()
    return [
        label
        for tick in ticks
        for label in (tick.label1, tick.label2)
        if tick.get_visible() and label.get_visible() and label.get_text()
    ]


def tick_labels(ax) -> list:
    return axis_labels(ax.xaxis) + axis_labels(ax.yaxis)


def test_every_section_draws_figures(figures):
    names = [block.name for block, _ in figures]
    prefixes = ("sweep_", "paradoxes_", "tradeoff_", "inside_", "outcomes_")
    measured_kinds = ("measured_kharaz_scatter", "measured_cube_scatter", "kharaz_curves")
    for prefix in prefixes + measured_kinds:
        assert any(name.startswith(prefix) for name in names), (prefix, names)


def test_no_legend_overlaps_any_panel(figures):
    seen = 0
    for block, _ in figures:
        renderer = block.figure.canvas.get_renderer()
        for legend in legends(block.figure):
            seen += 1
            box = legend.get_window_extent(renderer)
            for ax in block.figure.axes:
                if ax.get_visible() and ax.axison:
                    assert not box.overlaps(ax.get_window_extent(renderer)), block.name
    assert seen >= 5


def test_every_series_is_in_the_legend_the_ground_truths_model_too(figures):
    for block, _ in figures:
        named = {text.get_text() for lg in legends(block.figure) for text in lg.get_texts()}
        for ax in block.figure.axes:
            assert set(ax.get_legend_handles_labels()[1]) <= named, block.name
    speed = by_name(figures, "tradeoff_three_ball_chain").figure
    assert {"compliant", "moreau", "Pareto front"} <= {
        t.get_text() for lg in legends(speed) for t in lg.get_texts()
    }


def test_every_tick_label_is_at_least_9_px_tall_at_the_page_width(figures):
    for block, width in figures:
        for ax in block.figure.axes:
            for label in tick_labels(ax):
                height = plots.displayed_height(label.get_fontsize(), width)
                assert height >= MIN_PX, (block.name, label.get_text(), height, width)


def test_no_two_tick_labels_of_an_axis_overlap(figures):
    for block, _ in figures:
        renderer = block.figure.canvas.get_renderer()
        for ax in block.figure.axes:
            for axis in (ax.xaxis, ax.yaxis):
                shown = axis_labels(axis)
                boxes = [label.get_window_extent(renderer) for label in shown]
                for (a, ta), (b, tb) in itertools.combinations(zip(boxes, shown, strict=True), 2):
                    assert not a.overlaps(b), (block.name, ta.get_text(), tb.get_text())


def test_decades_alone_are_labelled_over_a_decade_and_more():
    fig, axes = plots.figure(1, 1)
    ax = axes[0, 0]
    ax.plot([3e-4, 2e-2], [1e-3, 1e-2])
    plots.log_scale(ax, "x")
    FigureCanvasAgg(fig).draw()
    minor = {t.get_text() for t in ax.get_xticklabels(minor=True)} - {""}
    assert minor == set()
    assert {"10⁻³", "10⁻²"} <= {t.get_text() for t in ax.get_xticklabels()}


def test_a_missing_value_is_a_gap_never_a_zero(figures):
    fig = by_name(figures, "sweep_nan").figure
    curvature = next(ax for ax in fig.axes if ax.get_title() == "curvature")
    moreau = next(line for line in curvature.lines if line.get_label() == "moreau")
    y = np.asarray(moreau.get_ydata(), dtype=float)
    assert np.isnan(y[1]) and y[0] == 0.1 and y[2] == 0.3


def test_each_paradox_map_has_its_own_symmetric_log_scale(figures, context):
    block = by_name(figures, "paradoxes_falling_rod")
    norms = {id(m.norm): m.norm for ax in block.figure.axes for m in ax.collections}
    scales = [n for n in norms.values() if isinstance(n, SymLogNorm)]
    assert len(scales) == 1
    largest = np.nanmax(np.abs(block.data["dT_over_T"].to_numpy(dtype=float)))
    assert scales[0].vmax == pytest.approx(max(largest, 10 * paradoxes.LINEAR))
    assert scales[0].vmin == -scales[0].vmax


def test_lzb_paths_are_drawn_against_the_total_normal_impulse(figures):
    fig = by_name(figures, "inside_disk_ball_energies").figure
    labels = {ax.get_xlabel() for ax in fig.axes if ax.get_title().startswith("lzb")}
    assert labels == {"total normal impulse [N s]"}


def test_the_ground_truth_appears_once_in_an_outcomes_table(sections):
    """On the chain, compliant contact at its defaults gives its ground truth: one row."""
    blocks = sections["outcomes"].blocks
    (table,) = [b for b in blocks if isinstance(b, Table) and "three_ball_chain" in b.name]
    labels = table.frame[""].astype(str).tolist()
    assert sum(label.startswith("ground truth: compliant") for label in labels) == 1, labels
    assert {"newton", "moreau"} <= set(labels) and "compliant" not in labels, labels


def _captions(sections, names) -> list[str]:
    texts = []
    for name in names:
        for block in sections[name].blocks:
            texts.append(block if isinstance(block, str) else getattr(block, "caption", ""))
    return texts


def test_no_caption_of_the_figures_says_nan(sections):
    for text in _captions(sections, ("sweeps", "paradoxes", "inside", "outcomes")):
        assert not re.search(r"\bnan\b", text, re.I), text


def test_no_speed_accuracy_note_says_nan():
    rows = [
        {
            "law": "compliant",
            "knob": "tol",
            "value": 1e-6,
            "failure": "",
            "wall_time_s": 0.1,
            "verdict": "holds",
        },
        {
            "law": "whittaker",
            "knob": "",
            "value": None,
            "failure": "NotApplicable: 2 contacts",
            "verdict": "refused",
        },
    ]
    data = pd.DataFrame(rows).assign(candidate=True, model_error=np.nan, numerical_error=np.nan)
    blocks = tradeoff._scene_blocks(CASES.get("billiard"), data, 1)
    assert not any(re.search(r"\bnan\b", b, re.I) for b in blocks if isinstance(b, str))
