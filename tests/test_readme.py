"""Every block of the README that shows output is checked against what the code prints.

A shell block shows a command on a line that starts with ``$ lawbench`` and, below it, what the
command prints; it runs in an empty folder holding only the files of this repository it names
(``tests/data/...``). A ``pycon`` block is a Python session, run as a doctest. Blocks that show
only commands (long runs) are not run here, except the FCLIB example, a few seconds.
"""

import doctest
import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
BLOCK = re.compile(r"^```(\w*)\n(.*?)^```", re.M | re.S)


def blocks(language: str) -> list[str]:
    """The README's fenced blocks of ``language`` ('' for a plain block), in order."""
    return [body for lang, body in BLOCK.findall(README.read_text()) if lang == language]


def shown_commands() -> list[tuple[str, list[str]]]:
    """Every ``$ lawbench ...`` line of a plain block followed by its output, with the output."""
    found = []
    for body in blocks(""):
        command, output = None, []
        for line in [*body.splitlines(), "$"]:
            if line.startswith("$"):
                if command is not None and output:
                    found.append((command, output))
                command, output = line[1:].strip(), []
            elif command is not None:
                output.append(line.rstrip())
    return [(command, output) for command, output in found if command.startswith("lawbench ")]


def test_the_readme_shows_the_commands_checked_here():
    commands = [command.split()[1] for command, _ in shown_commands()]
    assert {"list", "run"} <= set(commands)


@pytest.mark.parametrize(("command", "output"), shown_commands(), ids=lambda c: str(c)[:40])
def test_a_command_prints_what_the_readme_shows(command, output, tmp_path):
    words = shlex.split(command)[1:]
    given(words, tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "lawbench", *words],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert [line.rstrip() for line in done.stdout.splitlines()] == output


def given(words: list[str], folder: Path) -> None:
    """Copy into ``folder`` the repository's files that ``words`` name, at the same paths."""
    for word in words:
        if word.startswith("tests/data/"):
            (folder / word).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(ROOT / word, folder / word)


def test_the_fclib_example_solves_the_file_in_the_sweeps_the_readme_states(tmp_path):
    """The Capsules file, as the README names it, solved to an FC3D error below 1e-8."""
    text = README.read_text()
    (command,) = re.findall(r"^lawbench solve moreau --problem tests/data/fclib/\S+$", text, re.M)
    sweeps = int(re.search(r"(\d+)\s+sweeps, whose wall time", text).group(1))
    words = shlex.split(command)[1:]
    given(words, tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "lawbench", *words, "--json"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    record = json.loads(done.stdout)
    assert record["fc3d_error"] <= 1e-8
    assert record["diagnostics"]["sweeps"] == sweeps


def test_the_fit_examples_trials_are_the_ones_the_readme_describes():
    """Eight drops from 0.5 to 3 m/s, jia at k2/k1 = 3 (the scene's default), 5 mm/s noise of
    seed 5: made again here, they are the shipped file's."""
    import lawbench

    v0 = np.linspace(0.5, 3.0, 8)
    v_minus = np.column_stack([-v0, -v0])
    after = np.array(
        [lawbench.solve("jia", "ping_pong", velocities=list(v)).v_plus for v in v_minus]
    )
    after += np.random.default_rng(5).normal(0.0, 0.005, after.shape)
    shipped = pd.read_csv(ROOT / "tests" / "data" / "ping_pong_trials.csv")
    assert list(shipped.columns) == ["v1_minus", "v2_minus", "v1_plus", "v2_plus"]
    np.testing.assert_allclose(shipped.to_numpy(), np.hstack([v_minus, after]), atol=1e-9)


def test_the_python_sessions_print_what_the_readme_shows():
    sessions = blocks("pycon")
    assert sessions
    parser, runner = doctest.DocTestParser(), doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    globs: dict = {}
    for number, session in enumerate(sessions):
        test = parser.get_doctest(session, globs, f"README pycon block {number}", str(README), 0)
        runner.run(test, clear_globs=False)
        globs = test.globs  # a session goes on where the one above stopped
    assert runner.failures == 0, f"{runner.failures} README example(s) print otherwise"
