"""The run and regress commands, as a user calls them: real subprocesses and signals."""

import re
import signal
import subprocess
import sys
import time

import pandas as pd
import pytest

SPEC = """
[[grid]]
laws = ["compliant"]
cases = ["three_ball_chain"]
params = { stiffness_ratio = { logrange = [-2, 2, 12] }, e = [1.0, 0.9] }
"""
CELLS = 24
RUN = ("run", "spec.toml", "--chunk-size", "2")


def lawbench(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "lawbench", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=600,
    )


def computed_now(stdout):
    return int(re.search(r"\((\d+) computed now", stdout).group(1))


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    """The table of the grid run once without interruption."""
    folder = tmp_path_factory.mktemp("whole")
    (folder / "spec.toml").write_text(SPEC)
    whole = lawbench(*RUN, "--out", "whole.parquet", cwd=folder)
    assert whole.returncode == 0, whole.stderr
    return pd.read_parquet(folder / "whole.parquet").drop(columns="wall_time_s")


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGKILL], ids=["ctrl-c", "killed"])
def test_an_interrupted_run_resumes_to_the_same_table(tmp_path, stop, uninterrupted):
    """Stop a run halfway with a signal; resuming computes only the missing rows and gives
    the table of an uninterrupted run."""
    (tmp_path / "spec.toml").write_text(SPEC)
    process = subprocess.Popen(
        [sys.executable, "-m", "lawbench", *RUN, "--executor", "serial", "--out", "cut.parquet"],
        # A shell without job control starts background jobs with SIGINT ignored, and Python
        # then keeps ignoring it: give the run the default, as in a terminal.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    parts = tmp_path / "cut.parquet.parts"
    deadline = time.monotonic() + 120
    while len(list(parts.glob("part-*.parquet"))) < 3 and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(stop)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode != 0, "the run ended before the signal: make the grid longer"
    assert "Traceback" not in stderr
    finished = sum(len(pd.read_parquet(p)) for p in parts.glob("part-*.parquet"))
    assert 0 < finished < CELLS
    resumed = lawbench(*RUN, "--out", "cut.parquet", "--resume", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert computed_now(resumed.stdout) == CELLS - finished
    obtained = pd.read_parquet(tmp_path / "cut.parquet").drop(columns="wall_time_s")
    pd.testing.assert_frame_equal(obtained, uninterrupted)


def test_ctrl_c_on_a_pool_of_workers_prints_one_line(tmp_path):
    """A terminal's Ctrl-C reaches the whole process group, workers included: the parent
    alone answers it (one line, exit 130); no worker prints its traceback."""
    import os

    grid = ["--laws", "lzb,compliant", "--cases", "ball_chain", "--param", "n=20,30"]
    process = subprocess.Popen(
        [sys.executable, "-m", "lawbench", "run", *grid, "--param", "e=0", "--quiet"],
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        process_group=0,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(6)  # the workers have started and are solving plastic chains (seconds each)
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert stderr.strip().splitlines() == [
        "lawbench: interrupted; finished rows are kept (rerun with --resume)"
    ]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "--laws", "nope"], "unknown law 'nope'"),
        (["run", "--cases", "three_ball_chain", "--param", "e=3"], r"e\[0\] = 3"),
        (["run", "bad.toml"], "malformed TOML"),
        (
            [
                "run",
                "--laws",
                "newton",
                "--cases",
                "three_ball_chain",
                "--executor",
                "dask",
                "--address",
                "tcp://127.0.0.1:9",
            ],
            "cannot be reached",
        ),
    ],
)
def test_bad_specs_stop_with_one_line(tmp_path, args, message):
    (tmp_path / "bad.toml").write_text("[[grid]\n")
    result = lawbench(*args, cwd=tmp_path)
    assert result.returncode == 2
    assert len(result.stderr.splitlines()) == 1 and re.search(message, result.stderr)
    assert not list(tmp_path.glob("results*"))


GRID = '[[grid]]\nlaws = ["newton"]\ncases = ["three_ball_chain"]\nparams = {{ {} }}\n'


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ("masses = { random = [2.0, 0.5, 2], size = 3 }", "low 2 is above high 0.5"),
        ("masses = { random = [0.5, inf, 2] }", "bounds 0.5 and inf must be finite"),
        ("masses = { random = [0.5, 2.0, 2], size = 1000000000000 }", "a size of 1000000000000"),
        ("e = { range = [0, 1, 1e21] }", "a count of 1000000000000000000000"),
        (
            "e = { range = [0, 1, 1001] }, masses = { range = [1, 2, 1000000] }",
            "a grid of 1001000000 cells, more than the 1000000000",
        ),
    ],
)
def test_a_bad_generator_or_a_grid_too_large_stops_with_one_line(tmp_path, params, message):
    (tmp_path / "grid.toml").write_text(GRID.format(params))
    result = lawbench("run", "grid.toml", "--executor", "serial", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert len(result.stderr.splitlines()) == 1 and re.search(message, result.stderr)
    assert not list(tmp_path.glob("results*"))


def test_a_param_nested_deep_stops_with_one_short_line(tmp_path):
    nested = "e=" + "[" * 50_000 + "]" * 50_000
    result = lawbench("run", "--cases", "three_ball_chain", "--param", nested, cwd=tmp_path)
    assert result.returncode == 2
    assert len(result.stderr.splitlines()) == 1 and "nested brackets" in result.stderr
    assert len(result.stderr) < 300


# The optional dependencies (extras dask and hdf5; cvxpy and hypothesis come with the tests):
# blocked, as in an installation without extras.
WITHOUT_EXTRAS = """
import sys
for name in ("dask", "distributed", "h5py", "cvxpy", "hypothesis"):
    sys.modules[name] = None
from lawbench.views.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize(
    ("args", "status", "said"),
    [
        (["solve", "moreau", "three_ball_chain"], 0, "v_plus|after"),
        (["study", "ping_pong", "--executor", "processes", "--workers", "2"], 0, "ping_pong"),
        (
            ["run", "--laws", "newton", "--cases", "three_ball_chain", "--executor", "dask"],
            2,
            r"needs Dask: pip install 'lawbench\[dask\]'",
        ),
        (["solve", "newton", "--problem", "p.h5"], 2, r"need h5py: pip install 'lawbench\[hdf5\]'"),
    ],
)
def test_an_installation_without_extras_solves_and_names_what_is_missing(
    tmp_path, args, status, said
):
    """Without Dask, h5py and cvxpy the solver and the study engine (what the report runs)
    work; asking for what an extra gives exits 2 naming the extra to install."""
    (tmp_path / "p.h5").write_bytes(b"\x89HDF\r\n\x1a\n")
    result = subprocess.run(
        [sys.executable, "-c", WITHOUT_EXTRAS, *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == status, result.stderr
    assert re.search(said, result.stdout + result.stderr)
    assert "Traceback" not in result.stderr


def test_the_summary_counts_refused_cells_apart_from_failed_ones(tmp_path):
    """Brach's law treats one contact: it refuses two balls on a wall (NotApplicable), which is
    no failure; sequential impacts out of steps are one. The time goes to stderr."""
    grid = ("--laws", "newton,brach,sequential", "--cases", "two_balls_wall", "--param", "e=0")
    done = lawbench(
        "run", *grid, "--option", "sequential.max_steps=5", "--executor", "serial",
        "--out", "r.parquet", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == (
        "3 rows in r.parquet (3 computed now, 1 refused, 1 failed)"
    )
    number = r"\d[\d.e+-]*"
    last = done.stderr.splitlines()[-1]
    assert re.fullmatch(rf"run: 3 rows computed in {number} s, {number} rows/s", last), last
