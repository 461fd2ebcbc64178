"""A run's files: the lock on --out, checksummed chunks, resuming after SIGKILL, formats."""

import logging
import random
import signal
import subprocess
import sys
import threading
import time

import pandas as pd
import pytest

import lawbench
from lawbench.studies.runfile import Store
from lawbench.studies.runner import Task, compute, run
from lawbench.studies.study import Job, Plan
from lawbench.views.cli import main

GRID = [
    "--laws",
    "newton,moreau,poisson,compliant",
    "--cases",
    "three_ball_chain",
    "--param",
    "e=0,0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9",
]
CELLS = 40
TIMING = ["wall_time_s", "spent_s"]


def command(*args):
    return [sys.executable, "-m", "lawbench", "run", *GRID, "--workers", "2", *args]


def lawbench_run(*args, cwd):
    return subprocess.run(command(*args), cwd=cwd, capture_output=True, text=True, timeout=300)


def rows(path):
    return lawbench.load_run(path).drop(columns=TIMING)


def first_chunk(process, folder):
    """Wait until ``process`` writes its first chunk into ``folder`` (or ends)."""
    parts = folder / "cut.parquet.parts"
    while not parts.exists() and process.poll() is None:
        time.sleep(0.01)


def start(folder):
    return subprocess.Popen(
        command("--out", "cut.parquet", "--chunk-size", "2"),
        cwd=folder,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """An uninterrupted run, and the seconds from its first chunk to its end."""
    folder = tmp_path_factory.mktemp("whole")
    process = start(folder)
    first_chunk(process, folder)
    begun = time.monotonic()
    assert process.wait(timeout=300) == 0
    return folder / "cut.parquet", time.monotonic() - begun


# Two moments in the default run; three more in the slow profile.
KILL_SEEDS = [0, 1, *(pytest.param(seed, marks=pytest.mark.slow) for seed in range(2, 5))]


@pytest.mark.parametrize("seed", KILL_SEEDS)
def test_a_process_pool_run_killed_anywhere_resumes_to_the_same_rows(tmp_path, whole, seed):
    reference, seconds = whole
    process = start(tmp_path)
    # Kill it at a random moment between its first chunk and its end (before the first chunk
    # nothing is kept, and the test would only show a fresh run).
    first_chunk(process, tmp_path)
    time.sleep(random.Random(seed).uniform(0, seconds))
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=30)
    resumed = lawbench_run("--out", "cut.parquet", "--resume", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    pd.testing.assert_frame_equal(rows(tmp_path / "cut.parquet"), rows(reference))


def test_a_truncated_chunk_is_reported_and_computed_again(tmp_path, caplog):
    plan = Plan("", [Job("newton", "three_ball_chain", {"e": [e]}) for e in (0.0, 0.5, 1.0)])
    store = Store(tmp_path / "out.parquet")
    for index, job in enumerate(plan.jobs[:2]):
        store.write_chunk([compute(Task(index, job))])
    first = store.chunks()[0]
    first.write_bytes(first.read_bytes()[:100])
    with caplog.at_level(logging.WARNING, logger="lawbench.studies.runner"):
        table, computed = run(plan, tmp_path / "out.parquet", resume=True)
    assert computed == 2  # the damaged chunk's cell and the missing one
    assert "part-000000.parquet is damaged (checksum mismatch)" in caplog.text
    assert list(table["index"]) == [0, 1, 2]


def test_two_runs_on_one_output_one_completes_the_other_names_the_lock(tmp_path):
    started = [
        subprocess.Popen(
            command("--out", "both.parquet", "--chunk-size", "2"),
            cwd=tmp_path,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    ended = [(p.wait(timeout=300), p.stderr.read()) for p in started]
    assert sorted(code for code, _ in ended) == [0, 2]
    refused = next(stderr for code, stderr in ended if code == 2)
    assert "both.parquet is locked by another run" in refused
    assert "both.parquet.lock" in refused
    table = lawbench.load_run(tmp_path / "both.parquet")
    assert len(table) == CELLS and table["key"].is_unique


def test_a_waiting_run_takes_the_lock_when_the_first_ends(tmp_path):
    store = Store(tmp_path / "w.parquet")
    with store.locked():
        waiting = subprocess.Popen(
            command("--out", "w.parquet", "--wait"), cwd=tmp_path, stdout=subprocess.PIPE
        )
        time.sleep(2)
        assert waiting.poll() is None
    assert waiting.wait(timeout=120) == 0
    assert len(lawbench.load_run(tmp_path / "w.parquet")) == CELLS


def test_a_run_leaves_no_lock_file_behind(tmp_path):
    assert lawbench_run("--out", "clean.parquet", cwd=tmp_path).returncode == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clean.parquet"]


def test_a_run_that_waited_on_a_removed_lock_file_still_holds_the_output_alone(tmp_path):
    """The first run removes the lock's name as it ends; the run waiting on that file gets its
    lock, sees the name gone, and locks the name anew: a third run is still refused."""
    first, second = Store(tmp_path / "o.parquet"), Store(tmp_path / "o.parquet")
    held = threading.Event()
    release = threading.Event()

    def wait_then_hold():
        with second.locked(wait=True):
            held.set()
            release.wait(30)

    waiter = threading.Thread(target=wait_then_hold)
    with first.locked():
        waiter.start()
        time.sleep(0.5)
        assert not held.is_set()
    assert held.wait(30)
    with pytest.raises(lawbench.InvalidProblem, match="is locked by another run"):
        with Store(tmp_path / "o.parquet").locked():
            pass
    release.set()
    waiter.join(30)
    assert not (tmp_path / "o.parquet.lock").exists()


def test_resume_of_a_finished_run_says_it_is_complete(tmp_path):
    assert lawbench_run("--out", "done.csv", cwd=tmp_path).returncode == 0
    again = lawbench_run("--out", "done.csv", "--resume", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert "done.csv is complete: 40 rows" in again.stdout
    assert (tmp_path / "done.csv").read_text().startswith("index,key,")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--out", "r.txt"], "unknown extension '.txt'"),
        (["--out", "r.csv", "--format", "parquet"], "--format parquet contradicts --out r.csv"),
    ],
)
def test_an_output_format_that_is_not_clear_exits_2(tmp_path, args, message):
    result = lawbench_run(*args, cwd=tmp_path)
    assert result.returncode == 2
    assert message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("name", "write", "message"),
    [
        ("junk.parquet", lambda path: path.write_text("not a table"), "not a table a run wrote"),
        (
            "other.parquet",
            lambda path: pd.DataFrame({"a": [1, 2]}).to_parquet(path),
            "a table no run wrote",
        ),
        ("other.csv", lambda path: path.write_text("a\n1\n"), "a table no run wrote"),
    ],
)
def test_an_output_that_is_not_a_run_table_is_refused_naming_it(
    tmp_path, capsys, name, write, message
):
    out = tmp_path / name
    write(out)
    before = out.read_bytes()
    args = ["run", "--laws", "newton", "--cases", "three_ball_chain", "--executor", "serial"]
    code = main([*args, "--quiet", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and f"{name}: {message}" in err
    assert out.read_bytes() == before
