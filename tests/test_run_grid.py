"""The grid of ``lawbench run`` as typed, its tidy table as pandas reads it, its progress."""

import contextlib
import io
import json
import math
import os
import re
import subprocess
import sys
import tomllib
import tracemalloc
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

import lawbench
from lawbench.core.verdicts import Verdict
from lawbench.studies.grid import RunSpec, parse_values
from lawbench.studies.runner import _progress
from lawbench.views.cli import main

CHAIN = ["--laws", "newton", "--cases", "three_ball_chain", "--executor", "serial"]


def lawbench_cli(*args, cwd):
    """The command line run in this process, in the folder ``cwd``: its exit code and output."""
    out, err, here = io.StringIO(), io.StringIO(), Path.cwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(args))
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(args, code, out.getvalue(), err.getvalue())


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    """``--param e=0,0.5,1`` run into Parquet and CSV: the folder and the first run's output."""
    folder = tmp_path_factory.mktemp("three")
    for out in ("three.parquet", "three.csv"):
        done = lawbench_cli("run", *CHAIN, "--param", "e=0,0.5,1", "--out", out, cwd=folder)
        assert done.returncode == 0, done.stderr
    return folder, done.stdout


def test_commas_give_grid_points_and_the_first_line_says_so(three):
    folder, stdout = three
    assert stdout.splitlines()[0] == (
        "run: 3 cells; grid 0: laws newton; cases three_ball_chain; e = 0 | 0.5 | 1 (3 grid points)"
    )
    table = pd.read_parquet(folder / "three.parquet")
    assert list(table["e"]) == [0.0, 0.5, 1.0]


def test_brackets_give_one_per_contact_vector(tmp_path):
    done = lawbench_cli("run", *CHAIN, "--param", "e=[0.9,0.8]", "--out", "v.parquet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "e = [0.9, 0.8] (1 grid point)" in done.stdout.splitlines()[0]
    (e,) = pd.read_parquet(tmp_path / "v.parquet")["e"]
    assert list(e) == [0.9, 0.8]


@pytest.mark.parametrize(
    ("text", "points"),
    [
        ("0,0.5,1", [0, 0.5, 1]),
        ("[0.9,0.8]", [[0.9, 0.8]]),
        ("[0.9,0.8], [1,1]", [[0.9, 0.8], [1, 1]]),
        ("left_to_right,right_to_left", ["left_to_right", "right_to_left"]),
    ],
)
def test_the_grid_spelling(text, points):
    assert parse_values("e", text) == points


@pytest.mark.parametrize(("text", "message"), [("[1,2", "unbalanced"), ("1,,2", "empty")])
def test_a_bad_grid_spelling_names_the_parameter(text, message):
    with pytest.raises(lawbench.InvalidProblem, match=f"--param e={re.escape(text)}.*{message}"):
        parse_values("e", text)


def test_run_help_documents_both_spellings():
    done = lawbench_cli("run", "--help", cwd=".")
    assert done.returncode == 0
    text = " ".join(done.stdout.split())
    assert "e=0,0.5,1 is three rows" in text and "e=[0.9,0.8] is one row" in text


def test_python_m_lawbench_help_works():
    done = lawbench_cli("--help", cwd=".")
    assert done.returncode == 0 and "usage: lawbench" in done.stdout


def test_option_gives_law_options_as_grid_points_and_set_scene_parameters(tmp_path):
    args = ["run", "--laws", "moreau", "--cases", "three_ball_chain", "--executor", "serial"]
    done = lawbench_cli(*args, "--option", "tol=1e-6,1e-10", "--out", "o.parquet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    options = [json.loads(o) for o in pd.read_parquet(tmp_path / "o.parquet")["options"]]
    assert options == [{"tol": 1e-6}, {"tol": 1e-10}]
    bad = lawbench_cli(*args, "--option", "colour=1", "--out", "p.parquet", cwd=tmp_path)
    assert bad.returncode == 2 and "colour" in bad.stderr
    scene = lawbench_cli(*args, "--set", "e=0,1", "--out", "s.parquet", cwd=tmp_path)
    assert scene.returncode == 0, scene.stderr
    assert sorted(pd.read_parquet(tmp_path / "s.parquet")["e"]) == [0.0, 1.0]


def test_a_large_grid_states_its_size_and_needs_yes(tmp_path):
    (tmp_path / "big.toml").write_text(
        '[[grid]]\nlaws = ["newton"]\ncases = ["three_ball_chain"]\n'
        "params = { e = { range = [0, 1, 10001] } }\n"
    )
    done = lawbench_cli("run", "big.toml", "--out", "big.parquet", cwd=tmp_path)
    assert done.returncode == 2
    assert "a grid of 10001 cells" in done.stderr and "give --yes" in done.stderr
    assert "0 | 0.0001 | 0.0002 | 0.0003 | 0.0004 | ... | 1 (10001 grid points)" in done.stdout
    assert not (tmp_path / "big.parquet").exists()


def test_a_grid_of_a_hundred_million_cells_is_refused_before_it_is_built(
    tmp_path, monkeypatch, capsys
):
    """Counted from the grid's sizes: no row is built, no generator drawn whole, and the
    memory taken stays far below what 10^7 grid points alone would take (80 MB as floats)."""
    from lawbench.studies import grid
    from lawbench.views import cli

    def built(*args):
        pytest.fail("the grid was built")

    monkeypatch.setattr(grid.RunSpec, "rows", built)
    monkeypatch.setattr(grid.Generated, "__iter__", built)
    monkeypatch.setattr(grid.Product, "__iter__", built)
    monkeypatch.chdir(tmp_path)
    Path("huge.toml").write_text(
        '[[grid]]\nlaws = ["moreau"]\ncases = ["three_ball_chain"]\n'
        "params = { e = { range = [0, 1, 10000000] } }\n"
        "options = { moreau = { tol = { logrange = [-12, -3, 10] } } }\n"
    )
    tracemalloc.start()
    try:
        code = cli.main(["run", "huge.toml", "--executor", "serial", "--out", "huge.parquet"])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    out, err = capsys.readouterr()
    assert code == 2, err
    assert "a grid of 100000000 cells" in err and "give --yes" in err
    first = out.splitlines()[0]
    assert first.startswith("run: 100000000 cells; grid 0: laws moreau; cases three_ball_chain")
    assert "e = 0 | 1e-07 | 2e-07 | 3e-07 | 4e-07 | ... | 1 (10000000 grid points)" in first
    assert peak < 40e6
    assert not Path("huge.parquet").exists()


GRIDS = [
    {"grid": [{"laws": ["newton", "moreau"], "cases": ["three_ball_chain", "two_balls_wall"]}]},
    {"grid": [{"cases": ["two_balls_wall"], "examples": True, "transforms": ["", "duplicated"]}]},
    {
        "grid": [
            {
                "cases": ["three_ball_chain"],
                "params": {"e": {"range": [0, 1, 4]}, "masses": {"random": [1, 2, 3], "size": 3}},
                "options": {"moreau": {"tol": {"logrange": [-9, -6, 2]}}},
            },
            {"laws": ["sequential"], "cases": ["*"], "params": {"e": []}},
        ]
    },
]


@pytest.mark.parametrize("data", GRIDS)
def test_the_count_and_the_sample_agree_with_the_rows(data):
    spec = RunSpec.from_dict(data)
    rows = spec.rows()
    assert spec.count() == len(rows)
    wanted = sorted({k * len(rows) // 5 for k in range(5)})
    assert spec.sample(5) == [rows[k] for k in wanted]


@pytest.mark.parametrize(
    "generator",
    [
        {"range": [0, 1, 10001]},
        {"range": [-3, 7, 13]},
        {"range": [2, 2, 4]},
        {"range": [1, 5, 1]},
        {"logrange": [-12, -4, 101]},
        {"random": [0.5, 2.0, 17], "log": True, "size": 3},
        {"random": [0, 1, 50]},
    ],
)
def test_a_grid_point_computed_alone_is_the_same_as_in_the_whole_list(generator):
    from lawbench.studies.grid import Generated

    points = Generated(generator, 7, (0, "param", "e"))
    whole = list(points)
    assert len(whole) == len(points)
    assert [points[k] for k in range(len(points))] == whole
    assert points[-1] == whole[-1]


def test_the_echoed_grid_shows_the_random_draws_the_rows_use():
    spec = RunSpec.from_dict(
        {
            "grid": [
                {
                    "laws": ["newton"],
                    "cases": ["three_ball_chain"],
                    "params": {"e": {"random": [0, 1, 3]}},
                }
            ]
        }
    )
    drawn = [job.params["e"] for job in spec.rows()]
    assert " | ".join(f"{e:g}" for e in drawn) + " (3 grid points)" in spec.describe()


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ({"grid": {"laws": ["newton"]}}, "key 'grid' must be an array of"),
        ({"grid": [{"laws": 3}]}, "key 'grid\\[0\\].laws' must be an array"),
        ({"grid": [{}, {"params": [1, 2]}]}, "key 'grid\\[1\\].params' must be a table"),
        ({"grid": [{"options": {"moreau": 1}}]}, "key 'grid\\[0\\].options.moreau'"),
        ({"grid": [{"examples": "yes"}]}, "key 'grid\\[0\\].examples' must be true or false"),
        ({"grid": [{}], "seed": "zero"}, "key 'seed' must be an integer"),
        ({"grid": [{"params": {"e": {"range": [0, 1]}}}]}, "grid\\[0\\].params.e: bad value"),
    ],
)
def test_a_bad_run_file_names_the_key(spec, message):
    with pytest.raises(lawbench.InvalidProblem, match=message):
        RunSpec.from_dict(spec).rows()


ONE_GRID = {"laws": ["newton"], "cases": ["three_ball_chain"]}


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"masses": {"random": [2.0, 0.5, 2], "size": 3}}, "low 2 is above high 0.5"),
        ({"masses": {"random": [0.5, math.inf, 2]}}, "its bounds 0.5 and inf must be finite"),
        ({"e": {"range": [0, math.nan, 3]}}, "its bounds 0 and nan must be finite"),
        (
            {"masses": {"random": [0.0, 2.0, 2], "log": True}},
            "log = true draws between positive bounds, not from 0",
        ),
        ({"masses": {"random": [-1e308, 1e308, 2]}}, "span -1e\\+308 to 1e\\+308 exceeds"),
        ({"masses": {"random": [0.5, 2.0, 2], "size": 10**12}}, "a size of 1000000000000, outside"),
        ({"e": {"range": [0, 1, 10**21]}}, "a count of 1000000000000000000000, outside 0..1000"),
        ({"e": {"range": [0, 1, math.inf]}}, "cannot convert float infinity"),
    ],
)
def test_a_bad_generator_is_refused_when_the_grid_is_read(params, message):
    with pytest.raises(lawbench.InvalidProblem, match=f"grid\\[0\\].params.*{message}"):
        RunSpec.from_dict({"grid": [{**ONE_GRID, "params": params}]})


@pytest.mark.parametrize("count", [10**6, 10**9])
def test_a_grid_above_the_largest_is_refused_with_its_count(count):
    axes = {name: {"range": [0.5, 1, count]} for name in ("e", "masses", "velocities")}
    spec = RunSpec.from_dict({"grid": [{**ONE_GRID, "params": axes}]})
    with pytest.raises(lawbench.InvalidProblem, match=f"a grid of {count**3} cells, more than"):
        spec.count()


@pytest.mark.parametrize("text", ["[[0.5]]", "[1,[2]]", "[" * 100_000 + "]" * 100_000])
def test_nested_brackets_are_refused_in_one_short_line(text):
    with pytest.raises(lawbench.InvalidProblem, match="nested brackets") as caught:
        parse_values("e", text)
    assert len(str(caught.value)) < 200


def test_braces_nested_deep_are_a_word_or_a_malformed_vector():
    deep = '{"a":' * 100_000 + "1" + "}" * 100_000
    assert parse_values("e", deep) == [deep]
    with pytest.raises(lawbench.InvalidProblem, match="malformed vector"):
        parse_values("e", f"[{deep}]")


def test_the_run_file_of_the_readme_is_valid():
    readme = (Path(__file__).parents[1] / "README.md").read_text()
    text = readme.split("```toml\n", 1)[1].split("```", 1)[0]
    spec = RunSpec.from_dict(tomllib.loads(text))
    assert len(spec.rows()) > 12
    assert "e = 0 | 0.5 | 1 (3 grid points)" in spec.describe()


# The tidy table.


def test_pandas_reads_numbers_lists_and_categorical_verdicts(three):
    folder, _ = three
    table = pd.read_parquet(folder / "three.parquet")
    assert table["e"].dtype == float
    assert len(table[table.e == 0.5]) == 1
    assert list(table[table.e == 0.5]["v_plus"].iloc[0]) == pytest.approx([0.0, 0.5, 0.5])
    assert isinstance(table["verdict"].dtype, pd.CategoricalDtype)
    assert list(table["verdict"].cat.categories) == [str(v) for v in Verdict]
    schema = pq.read_schema(folder / "three.parquet")
    assert str(schema.field("v_plus").type) == "list<element: double>"
    assert str(schema.field("Pn").type) == "list<element: double>"
    meta = json.loads(schema.metadata[b"lawbench"])
    assert set(meta["versions"]) >= {"lawbench", "numpy", "scipy", "clarabel"}
    assert {"git_commit", "machine", "seed", "started"} <= set(meta)


def test_csv_expands_vectors_and_load_run_gathers_them(three):
    folder, _ = three
    raw = pd.read_csv(folder / "three.csv")
    assert {"v_plus_0", "v_plus_1", "v_plus_2", "Pn_0", "Pn_1"} <= set(raw.columns)
    meta = json.loads((folder / "three.csv.meta.json").read_text())
    assert meta["versions"]["lawbench"] == lawbench.__version__
    from_csv = lawbench.load_run(folder / "three.csv")
    from_parquet = lawbench.load_run(folder / "three.parquet")
    assert [list(v) for v in from_csv["v_plus"]] == [list(v) for v in from_parquet["v_plus"]]
    assert list(from_csv["e"]) == [0.0, 0.5, 1.0]
    assert from_csv["verdict"].dtype == from_parquet["verdict"].dtype


def test_load_run_of_a_missing_file_is_invalid(tmp_path):
    with pytest.raises(lawbench.InvalidProblem, match=r"none\.parquet: cannot be read"):
        lawbench.load_run(tmp_path / "none.parquet")


def test_load_run_of_a_file_no_run_wrote_names_it(tmp_path):
    (tmp_path / "junk.parquet").write_text("not a table")
    with pytest.raises(lawbench.InvalidProblem, match=r"junk\.parquet: not a table a run wrote"):
        lawbench.load_run(tmp_path / "junk.parquet")
    (tmp_path / "junk.csv").write_text("a\n")
    (tmp_path / "junk.csv.meta.json").write_text("{")
    with pytest.raises(lawbench.InvalidProblem, match=r"junk\.csv\.meta\.json: not JSON"):
        lawbench.load_run(tmp_path / "junk.csv")


def test_load_run_of_a_fifo_is_refused_before_it_is_opened(tmp_path):
    os.mkfifo(tmp_path / "fifo.parquet")
    with pytest.raises(lawbench.InvalidProblem, match=r"fifo\.parquet: a FIFO, not a regular file"):
        lawbench.load_run(tmp_path / "fifo.parquet")


# Progress.


def test_progress_shows_on_a_terminal_only(monkeypatch):
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    monkeypatch.setattr(sys, "stderr", Terminal())
    assert not _progress(10, 0, quiet=False).disable
    assert _progress(10, 0, quiet=True).disable
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    assert _progress(10, 0, quiet=False).disable


def test_a_run_in_a_pipe_prints_no_progress(three):
    folder, _ = three
    done = lawbench_cli("run", *CHAIN, "--param", "e=0.2", "--out", "p.parquet", cwd=folder)
    assert done.returncode == 0
    assert re.fullmatch(r"run: 1 rows computed in \S+ s, \S+ rows/s\n", done.stderr), done.stderr
