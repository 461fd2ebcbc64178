"""Fuzzing the environment of a command: whatever the streams and the disk do, one line at most.

Hypothesis draws a fault (a reader that closed the pipe, standard output to ``/dev/full``, a
closed standard error, ASCII-only streams, a full disk, an output under ``/sys``, behind a
symbolic link or with a name that is not UTF-8) and a command that writes (``--version``,
``list``, ``describe``, ``solve``, ``export``, ``run``), and runs it through
`lawbench.views.cli.main` in this process. The promise is the command line's: exit 0, 2 or 4
(1 for a broken pipe, Python's advice on SIGPIPE), at most one line on stderr, never a
traceback or an internal error; a symbolic link is written through. The deeper run is slow.
"""

import contextlib
import io
import itertools
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lawbench.views.cli import main


@contextlib.contextmanager
def _environment(fault: str):
    """Standard streams and a file system with ``fault``; yields the captured stderr."""
    stderr = io.StringIO()
    opened = []
    if fault == "broken pipe":
        read, write = os.pipe()
        os.close(read)
        stdout = os.fdopen(write, "w")
        opened.append(stdout)
    elif fault == "stdout to /dev/full":
        stdout = open("/dev/full", "w")
        opened.append(stdout)
    elif fault == "ascii streams":
        stdout = io.TextIOWrapper(io.BytesIO(), encoding="ascii")
        stderr = io.TextIOWrapper(io.BytesIO(), encoding="ascii")
    else:
        stdout = io.StringIO()
    replace = os.replace

    def full(*args):
        raise OSError(28, os.strerror(28))

    if fault == "full disk":
        os.replace = full
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = stdout, None if fault == "closed stderr" else stderr
    try:
        yield stderr
    finally:
        sys.stdout, sys.stderr = saved
        os.replace = replace
        for stream in opened:
            with contextlib.suppress(OSError):
                stream.close()


FAULTS = [
    "broken pipe", "stdout to /dev/full", "closed stderr", "ascii streams", "full disk",
    "out under /sys", "symlink out", "non-UTF-8 out",
]  # fmt: skip
WRITERS = [
    ["--version"],
    ["list"],
    ["describe", "moreau"],
    ["solve", "newton", "three_ball_chain", "--json"],
    ["export", "three_ball_chain", "-o", "{out}.json"],
    ["run", "--laws", "newton", "--cases", "three_ball_chain", "--executor", "serial",
     "--quiet", "--out", "{out}.csv"],
]  # fmt: skip


@pytest.mark.parametrize("examples", [12, pytest.param(60, marks=pytest.mark.slow)])
def test_environment_faults_end_in_one_line_and_a_documented_code(tmp_path_factory, examples):
    """Streams closed, broken, full or narrow, a full disk, outputs that cannot be written,
    behind a symlink or not UTF-8: exit 0, 2 or 4 (1 for a broken pipe, Python's advice on
    SIGPIPE), at most one line on stderr, never a traceback or an internal error."""

    folder, counter = tmp_path_factory.mktemp("environment"), itertools.count()

    @settings(max_examples=examples, deadline=None, derandomize=True)
    @given(fault=st.sampled_from(FAULTS), argv=st.sampled_from(WRITERS))
    def check(fault, argv):
        out = str(folder / f"env{next(counter)}")
        if fault == "out under /sys":
            out = "/sys/lawbench"
        elif fault == "non-UTF-8 out":
            out += "\udcff\u00e9"
        elif fault == "symlink out":
            for ext in (".json", ".csv"):
                Path(out + ext).symlink_to(f"{out}-target{ext}")
        with _environment(fault) as stderr:
            code = main([a.replace("{out}", out) for a in argv])
        text = stderr.getvalue() if isinstance(stderr, io.StringIO) else ""
        allowed = {0, 1, 2, 4} if fault == "broken pipe" else {0, 2, 4}
        assert code in allowed, (fault, argv, code, text)
        assert "Traceback" not in text and "internal error" not in text, text
        assert len([line for line in text.splitlines() if line.strip()]) <= 1, text
        if fault == "symlink out" and code == 0 and "-o" in argv:
            assert Path(out + ".json").is_symlink() and Path(f"{out}-target.json").is_file()

    check()


@pytest.mark.parametrize("kib", [60_000, 200_000])
def test_an_address_space_too_small_to_start_is_one_line_and_exit_4(kib):
    """Under ``ulimit -v`` numpy's and scipy's start failed in native code: a traceback at 60
    MB (a library that cannot be mapped), OpenBLAS looping without end at 200 MB. The program
    checks the room first and says what is missing in one line, exit 4."""
    done = subprocess.run(
        ["bash", "-c", f"ulimit -v {kib}; exec {sys.executable} -m lawbench list"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 4, done.stderr[-1000:]
    assert done.stderr.startswith("lawbench: out of memory: the address-space limit")
    assert len(done.stderr.splitlines()) == 1 and done.stdout == ""


class _Unmappable:
    """A finder under which the command line cannot be loaded: its library does not map."""

    def find_spec(self, name, path=None, target=None):
        if name == "lawbench.views.cli.main":
            raise ImportError("libopenblas.so: failed to map segment from shared object")
        return None


def test_a_library_that_cannot_be_mapped_at_start_is_one_line_and_exit_4(monkeypatch, capsys):
    from lawbench.views.program import program

    monkeypatch.delitem(sys.modules, "lawbench.views.cli.main")
    monkeypatch.setattr(sys, "meta_path", [_Unmappable(), *sys.meta_path])
    assert program() == 4
    err = capsys.readouterr().err
    assert err.startswith("lawbench: out of memory while starting (ImportError: libopenblas.so")
    assert len(err.splitlines()) == 1


@pytest.mark.parametrize("kib", [330_000, 400_000, 440_000])
def test_an_address_space_too_small_to_solve_is_one_line_and_exit_4(kib):
    """Room to start is not room to solve: numba's compiler and the BLAS buffers of the first
    products map more. Under 320 to 520 MB a solve ended with OpenBLAS's exit(1), a hang, an
    interrupt (OpenBLAS raising SIGINT), LLVM's or glibc's abort, or llvmlite's OSError read as
    the standard output's ('lawbench: the output: ...', exit 2)."""
    done = subprocess.run(
        [
            "bash",
            "-c",
            f"ulimit -v {kib}; exec {sys.executable} -m lawbench solve moreau sphere_wall",
        ],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
    )
    assert done.returncode == 4, done.stderr[-1000:]
    assert done.stderr.startswith("lawbench: out of memory")
    assert len(done.stderr.splitlines()) == 1 and done.stdout == ""


def test_a_library_that_cannot_be_mapped_mid_command_is_one_line_and_exit_4(monkeypatch, capsys):
    from lawbench.views.cli import listing

    def unmappable(args):
        try:
            raise OSError("libllvmlite.so: failed to map segment from shared object")
        except OSError as exc:
            raise OSError("Could not find/load shared object file 'libllvmlite.so'") from exc

    monkeypatch.setattr(listing, "run", unmappable)
    assert main(["list"]) == 4
    err = capsys.readouterr().err
    assert (
        err.startswith("lawbench: out of memory while loading a library")
        and len(err.splitlines()) == 1
    )
