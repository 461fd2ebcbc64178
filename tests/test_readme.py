"""Every block of the README that shows output is checked against what the code prints.

A shell block shows a command on a line that starts with ``$ lawbench`` and, below it, what the
command prints; a ``pycon`` block is a Python session, run as a doctest. Blocks that show only
commands (long runs) are not run here.
"""

import doctest
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
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
    done = subprocess.run(
        [sys.executable, "-m", "lawbench", *words],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert [line.rstrip() for line in done.stdout.splitlines()] == output


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
