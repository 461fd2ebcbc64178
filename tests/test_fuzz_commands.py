"""Fuzzing every command's options: whatever is typed, each command answers or says what is wrong.

For every subcommand of the argument parser that `lawbench.views.cli.build_parser` builds,
Hypothesis draws argument lists from the options the subcommand declares (positionals, flags,
choices, counts, wall-clock limits, paths, ``NAME=VALUE`` assignments), mixing valid values,
the bounds of each range and garbage (NaN, infinities, subnormal and overflowing numbers,
empty strings, unknown names, missing files, directories, FIFOs, empty files). Each argument
list runs through `lawbench.views.cli.main` in this process. The promise: the exit code is 0,
2 (bad input), 3 (the law does not apply), 4 (a solver failure or a budget) or, for ``check``, 6
(a cell is not acceptable) and for ``regress`` 5 (drift); a failure is one line on stderr
starting with ``lawbench: ``; never a traceback, never an internal error, never NaN printed
in an answer.

The commands that run many cells (``report``, ``study``, ``run``, ``check``, ``regress``,
``bench``) draw mostly arguments that are refused before any work, and now and then a tiny
valid grid on one law with a short wall-clock guard; ``report`` and ``regress`` are never
drawn valid (the real report takes minutes, and ``regress --update`` rewrites the baselines).
The deeper run (more examples, every executor) is marked slow.
"""

import argparse
import contextlib
import io
import itertools
import json
import os
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import lawbench
from lawbench.studies.declared import STUDIES
from lawbench.views.cli import build_parser, main

LAWS = lawbench.LAWS.names()
CASES = lawbench.CASES.names()
PARSER = build_parser()
SUBCOMMANDS = next(
    action.choices for action in PARSER._actions if isinstance(action, argparse._SubParsersAction)
)
ALLOWED = {"check": {0, 2, 3, 4, 6}, "regress": {0, 2, 3, 4, 5}}
NAN = re.compile(r"(?<![A-Za-z_])nan(?![A-Za-z_])", re.IGNORECASE)

# Laws that answer a small problem in milliseconds (the others integrate in time).
QUICK_LAWS = ["newton", "poisson", "moreau", "sequential"]
# Studies small enough to run under a short guard.
QUICK_STUDIES = ["rocking_block", "three_ball_chain_grazing"]

GARBAGE = ["", " ", "nope", "*", ",", "abc", "-1", "nan", "inf", "1e999", "=", "é", "a" * 300]
NUMBERS = [
    "0", "-0", "-1", "1", "0.5", "2", "1e-308", "5e-324", "1e308", "1e999", "-1e308",
    "nan", "NaN", "inf", "-inf", "", "abc", "1,2", "[1]", "0x10", "1_0", "18446744073709551617",
]  # fmt: skip
TRANSFORMS = [
    "grazing=1e-8", "grazing=0", "grazing=-1", "grazing=nan", "grazing=inf", "grazing=1e308",
    "grazing=5e-324", "grazing=", "grazing", "duplicated=0", "duplicated=1", "duplicated=-1",
    "duplicated=99", "duplicated=1.5", "duplicated=abc", "duplicated", "unknown=1", "=", "",
]  # fmt: skip
FREE = [
    "e", "stiffness_ratio", "e,stiffness_ratio", "e[0]", "e[1]", "e[99]", "masses[0]",
    "masses[9]", "e,e", "gaps", "nope", "", ",",
]  # fmt: skip
LAW_OBJECTS = [
    ":", ":x", "os:", "os:path", "no_such_module:x", "lawbench:Law", "lawbench:nope",
    "lawbench.core.law:LAWS", "builtins:object", "builtins:int", "lawbench.core.law:Law",
    "lawbench.core.errors:LawbenchError", "json:JSONDecoder", "..:x",
]  # fmt: skip


class Files:
    """Paths handed to the commands: valid files, broken ones, and things that are not files."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.counter = itertools.count()
        problem = lawbench.CASES.get("three_ball_chain").build()
        lawbench.save_problem(problem, folder / "problem.json")
        (folder / "problems").mkdir()
        lawbench.save_problem(problem, folder / "problems" / "chain.json")
        rows = []
        for v1, v2 in [(-1.0, -1.0), (-2.0, 0.5), (-1.5, -0.2)]:
            after = lawbench.solve("newton", "two_balls_wall", velocities=[v1, v2], e=[0.5])
            rows.append(",".join(repr(float(x)) for x in [v1, v2, *after.v_plus]))
        (folder / "trials.csv").write_text(
            "v1_minus,v2_minus,v1_plus,v2_plus\n" + "\n".join(rows) + "\n"
        )
        (folder / "run.toml").write_text(
            '[[grid]]\nlaws = ["newton"]\ncases = ["three_ball_chain"]\n'
            "params = { e = [0.0, 1.0] }\n"
        )
        (folder / "broken.toml").write_text("[[grid]\nlaws = [")
        (folder / "broken.json").write_text('{"format": "lawbench-problem", "M": [[1')
        (folder / "broken.csv").write_text("v1_minus,v2_minus\nnan,1\n")
        (folder / "ragged.csv").write_text("v1_minus,v2_minus,v1_plus,v2_plus\n1,2\n1,2,3,4,5,6\n")
        grid = '[[grid]]\nlaws = ["newton"]\ncases = ["three_ball_chain"]\nparams = {{ {} }}\n'
        draws = {
            "reversed": "masses = { random = [2.0, 0.5, 2], size = 3 }",
            "unbounded": "masses = { random = [0.5, inf, 2], size = 3 }",
            "huge_size": "masses = { random = [0.5, 2.0, 2], size = 1000000000000 }",
            "huge_count": "e = { range = [0, 1, 1000000000000000000000] }",
        }
        for name, params in draws.items():
            (folder / f"{name}.toml").write_text(grid.format(params))
        (folder / "junk.parquet").write_text("not a table")
        (folder / "empty").write_bytes(b"")
        (folder / "plain.txt").write_text("x")
        (folder / "folder").mkdir()
        os.mkfifo(folder / "fifo")

    def inputs(self, *valid: str) -> list[str]:
        """Paths to read: the valid files named, then broken ones and non-files."""
        f = self.folder
        broken = [
            "broken.toml",
            "broken.json",
            "broken.csv",
            "empty",
            "plain.txt",
            "folder",
            "fifo",
        ]
        return [
            *(str(f / name) for name in valid),
            *(str(f / name) for name in broken),
            str(f / "missing.json"),
            str(f / "plain.txt" / "child"),
            "/dev/null",
            "",
        ]

    def outputs(self, *extensions: str) -> list[str]:
        """Paths to write: new files (``{new}`` + extension), then paths that cannot be."""
        f = self.folder
        return [
            *(f"{{new}}{ext}" for ext in extensions),
            "{new}.txt",
            "{new}",
            str(f / "folder"),
            str(f / "fifo"),
            str(f / "plain.txt" / "child.csv"),
            str(f / "missing" / "deeper" / "x.csv"),
            "/dev/null",
            "",
        ]

    def fill(self, argv: list[str]) -> list[str]:
        """``argv`` with each ``{new}`` made a path no other example uses."""
        return [a.replace("{new}", str(self.folder / f"out{next(self.counter)}")) for a in argv]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    return Files(tmp_path_factory.mktemp("commands"))


def _kind(action: argparse.Action) -> str:
    """What an option takes, read from the parser: a flag, a choice, a count, seconds, ..."""
    if action.nargs == 0:
        return "flag"
    if action.choices:
        return "choice"
    name = getattr(action.type, "__qualname__", "")
    if name.startswith("_count"):
        return "count"
    if name.startswith("_real") or action.type is float:
        return "real"
    if name == "_path":
        return "path"
    if isinstance(action, argparse._AppendAction):
        return "assignments"
    return "text"


def _count_bounds(action: argparse.Action) -> tuple[int, int]:
    """The (low, high) of a count option, read from its parser's closure."""
    low, high = (cell.cell_contents for cell in action.type.__closure__)
    return low, high


def _counts(action: argparse.Action, deep: bool) -> st.SearchStrategy[str]:
    low, high = _count_bounds(action)
    # The upper bound of a repetition count is valid but would take hours: it only comes out
    # in the deep run, for the options where it is cheap.
    inside = [low, low + 1, min(low + 2, high)]
    if deep and high <= 256:
        inside.append(high)
    edges = [low - 1, high + 1, 2**64]
    return st.sampled_from([str(v) for v in inside + edges] + ["1.5", "abc", "", "nan", "1e3"])


def _seconds(deep: bool) -> st.SearchStrategy[str]:
    values = ["0.5", "1", "1e-9", "0", "-1", "nan", "inf", "1e7", "abc", "", "5e-324", "-0"]
    return st.sampled_from(values + (["1e6"] if deep else []))


def _assignment(names: list[str], values: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    name = st.sampled_from([*names, "bogus", "", " "])
    return st.builds(
        lambda n, v, sep: f"{n}{sep}{v}", name, values, st.sampled_from(["=", "=", ""])
    )


def _spec_values(specs: list) -> st.SearchStrategy[str]:
    """Text values of scene parameters or law options: in range, at the bounds, or garbage."""
    inside = []
    for spec in specs:
        default = spec.default
        inside.append(",".join(map(str, default)) if isinstance(default, list) else str(default))
        for bound in (spec.low, spec.high):
            if bound is not None:
                inside.append(str(bound))
        inside += [str(c) for c in spec.choices or ()]
    return st.one_of(st.sampled_from(inside or ["1"]), st.sampled_from(NUMBERS))


def _scene_assignments(case: str) -> st.SearchStrategy[str]:
    specs = lawbench.CASES.get(case).params if case in CASES else []
    return _assignment([s.name for s in specs], _spec_values(specs))


def _option_assignments(law: str) -> st.SearchStrategy[str]:
    # The wall-clock budget is drawn by --max-seconds; drawing it here too would be "given twice".
    specs = [s for s in lawbench.LAWS.get(law).options if s.name != "max_seconds"]
    if law not in LAWS:
        specs = []
    return _assignment([s.name for s in specs], _spec_values(specs))


def _grid_assignments() -> st.SearchStrategy[str]:
    points = st.sampled_from(
        ["0,0.5", "[0.9,0.8]", "[0.9,0.8],[1,1]", "[", "]", "[[1]]", "[]", "[NaN]", "NaN",
         "Infinity", "1e999", "[true]", "{}", "null", "x", "0,,1", "[" * 50 + "]" * 50]
    )  # fmt: skip
    return _assignment(
        ["e", "masses", "stiffness_ratio", "velocities"],
        st.one_of(points, st.sampled_from(NUMBERS)),
    )


class Context:
    """What the values of one command line depend on: its law, its scene, the deep run."""

    def __init__(self, command: str, files: Files, deep: bool, law: str, case: str) -> None:
        self.command, self.files, self.deep, self.law, self.case = command, files, deep, law, case

    def values(self, action: argparse.Action) -> st.SearchStrategy[str] | None:
        """Values of one option of ``self.command``; None: the option is left out."""
        dest, kind, f = action.dest, _kind(action), self.files
        if kind == "count":
            return _counts(action, self.deep)
        if dest == "max_seconds":
            return _seconds(self.deep)
        if kind == "real":
            return st.sampled_from(
                ["0", "0.3", "0.99", "1", "-0.1", "nan", "inf", "1e-320", "abc", ""]
            )
        if kind == "choice":
            choices = list(action.choices)
            if dest == "executor" and not self.deep:
                choices = ["serial"]  # processes and dask start workers: the deep run draws them
            return st.sampled_from([*choices, *choices, "bogus", ""])
        if dest == "set" and self.command in ("solve", "export", "fit", "study", "table"):
            return _scene_assignments(self.case)
        if dest == "option" and self.command in ("solve", "fit"):
            return _option_assignments(self.law)
        if dest in ("param", "option"):
            return _grid_assignments()
        if dest == "start":
            return _assignment(
                ["e", "stiffness_ratio", "e[0]", "masses[1]"], st.sampled_from(NUMBERS)
            )
        if dest == "transform":
            return st.sampled_from(TRANSFORMS)
        if dest == "free":
            return st.sampled_from(FREE)
        if dest in ("laws", "cases"):
            names = QUICK_LAWS if dest == "laws" else ["three_ball_chain", "two_balls_wall"]
            return st.sampled_from([*names, ",".join(names), *GARBAGE])
        if dest == "problem":
            return st.sampled_from(f.inputs("problem.json"))
        if dest == "data":
            return st.sampled_from(f.inputs("trials.csv"))
        if dest == "spec":
            return st.sampled_from(f.inputs("run.toml"))
        if dest == "problems":
            return st.sampled_from([str(f.folder / "problems"), *f.inputs()])
        if dest == "out":
            extensions = {
                "export": (".json", ".npz", ".h5", ".hdf5"),
                "study": (".csv", ".parquet"),
                "table": (".csv",),
                "run": (".csv", ".parquet", ".feather"),
                "bench": (".csv",),
            }.get(self.command, ())
            return st.sampled_from(f.outputs(*extensions))
        if dest == "address":
            return st.sampled_from(["", "nope", "tcp://127.0.0.1:1"])
        if kind == "path":
            return st.sampled_from(f.inputs())
        return st.sampled_from(GARBAGE)


def _positional(command: str, dest: str, files: Files) -> st.SearchStrategy[str]:
    if command == "describe":
        return st.sampled_from([*LAWS, *CASES, *GARBAGE])
    if dest == "law" and command == "check":
        return st.sampled_from([*QUICK_LAWS, *LAW_OBJECTS, *GARBAGE])
    if dest == "law" and command == "fit":
        return st.sampled_from([*QUICK_LAWS, "newton,moreau", "newton,nope", *GARBAGE])
    if dest == "law":
        return st.sampled_from([*LAWS, *GARBAGE])
    if dest == "case" and command == "fit":
        return st.sampled_from(["two_balls_wall", "two_balls_wall", "three_ball_chain", *GARBAGE])
    if dest == "case":
        return st.sampled_from([*CASES, *GARBAGE])
    if dest == "name":
        return st.sampled_from([*QUICK_STUDIES, *sorted(STUDIES)[:5], *GARBAGE])
    if dest == "spec":
        return st.sampled_from(files.inputs("run.toml"))
    return st.sampled_from(GARBAGE)


# A value no command accepts, so that the command stops before any work: the commands whose
# valid runs take minutes (or rewrite committed files) always carry one.
POISONS = {
    "report": [
        ["--out", "{plain}"],
        ["--out", "{fifo}"],
        ["--out", "{plain}/child"],
        ["--out", ""],
        ["--quick", "--full"],
        ["--bogus"],
    ],
    "regress": [
        ["--laws", "nope"],
        ["--cases", "nope"],
        ["--laws", ""],
        ["--cases", ","],
        ["--laws", "newton,"],
    ],
    "bench": [
        ["extra"],
        ["--bogus"],
        ["--max-seconds", "0"],
        ["--max-seconds", "nan"],
        ["--problems", "{plain}"],
        ["--problems", "{fifo}"],
        ["--problems", ""],
        ["--problems", "{problems}", "--out", "{plain}/child.csv"],
        ["--problems", "{problems}", "--laws", "nope"],
    ],
    "study": [
        ["--workers", "0"],
        ["--max-seconds", "nan"],
        ["--executor", "bogus"],
        ["--set", "bogus=1"],
        ["--set", "e=nan"],
        ["--out", "{plain}/x.csv"],
        ["--out", "{new}.txt"],
        ["--out", "{folder}"],
    ],
    "run": [
        ["--workers", "0"],
        ["--max-seconds", "0"],
        ["--seed", "-1"],
        ["--chunk-size", "0"],
        ["--laws", "nope"],
        ["--cases", ""],
        ["--param", "e=["],
        ["--param", "bogus=1"],
        ["--out", "{new}.txt"],
        ["--out", "{folder}"],
        ["--format", "bogus"],
    ],
    "check": [["--random", "-1"], ["--cases", "nope"], ["--cases", ""]],
}
POISONS["table"] = POISONS["study"]
# Commands whose valid runs are cheap enough to draw often; the others are drawn valid only
# in the tiny form of ``tiny`` below, now and then.
CHEAP = {"list", "describe", "solve", "export", "fit"}


def _poison(files: Files, argv: list[str]) -> list[str]:
    f = files.folder
    spots = {
        "{plain}": str(f / "plain.txt"),
        "{fifo}": str(f / "fifo"),
        "{folder}": str(f / "folder"),
        "{problems}": str(f / "problems"),
        "{data}": str(f),
    }
    out = []
    for item in argv:
        for key, value in spots.items():
            item = item.replace(key, value)
        out.append(item)
    return out


def tiny(command: str, files: Files) -> list[list[str]]:
    """Small valid command lines of the commands that run many cells."""
    guard = ["--max-seconds", "1", "--executor", "serial"]
    problems = str(files.folder / "problems")
    return {
        "study": [["rocking_block", "--set", "e=0", *guard], ["three_ball_chain_grazing", *guard]],
        "table": [["rocking_block", "--set", "e=1", *guard, "--out", "{new}.csv"], ["--list"]],
        "run": [
            ["--laws", "newton", "--cases", "three_ball_chain", "--param", "e=0,1", "--quiet",
             "--out", "{new}.csv", *guard],
            [str(files.folder / "run.toml"), "--quiet", "--out", "{new}.parquet", *guard],
        ],
        "check": [["newton", "--cases", "three_ball_chain", "--random", "0"],
                  ["moreau", "--cases", "two_balls_wall", "--random", "1", "--json"]],
        "bench": [["--problems", problems, "--laws", "newton", "--max-seconds", "1", "--out",
                   "{new}.csv"]],
    }.get(command, [])  # fmt: skip


@st.composite
def command_lines(draw, command: str, files: Files, deep: bool) -> list[str]:
    """An argument list for ``command``, drawn from the options its parser declares."""
    parser = SUBCOMMANDS[command]
    argv = [command]
    runs_long = command not in CHEAP
    valid_tiny = tiny(command, files)
    if runs_long and valid_tiny and draw(st.integers(0, 4)) == 0:
        return files.fill(_poison(files, [command, *draw(st.sampled_from(valid_tiny))]))
    law = draw(st.sampled_from(QUICK_LAWS if command == "fit" else LAWS))
    case = draw(st.sampled_from(CASES))
    context = Context(command, files, deep, law, case)
    for action in parser._actions:
        if action.option_strings or isinstance(action, argparse._HelpAction):
            continue
        if action.nargs == "?" and draw(st.booleans()):
            continue
        if action.dest == "law":
            value = draw(st.one_of(st.just(law), _positional(command, "law", files)))
        elif action.dest == "case":
            value = draw(st.one_of(st.just(case), _positional(command, "case", files)))
        else:
            value = draw(_positional(command, action.dest, files))
        argv.append(value)
    optionals = [
        a for a in parser._actions if a.option_strings and not isinstance(a, argparse._HelpAction)
    ]
    chosen = (
        draw(st.lists(st.sampled_from(optionals), max_size=5, unique_by=id)) if optionals else []
    )
    for action in chosen:
        flag = draw(st.sampled_from(action.option_strings))
        if _kind(action) == "flag":
            argv.append(flag)
            continue
        repeats = 2 if isinstance(action, argparse._AppendAction) else 1
        for value in draw(st.lists(context.values(action), min_size=1, max_size=repeats)):
            argv += [flag, value]
    for action in parser._actions:  # a required option left out half of the time
        if action.required and action.option_strings and action.option_strings[0] not in argv:
            if draw(st.integers(0, 3)):
                argv += [action.option_strings[0], draw(context.values(action))]
    if draw(st.integers(0, 9)) == 0:
        stray = draw(st.sampled_from(["--bogus", "extra", "-", "--"]))
        argv.insert(draw(st.integers(1, len(argv))), stray)
    if command == "solve" and "--max-seconds" not in argv:
        # Extreme values are slow to integrate; running out of the budget is an answer.
        argv += ["--max-seconds", "2"]
    if runs_long and command in POISONS:
        argv += draw(st.sampled_from(POISONS[command]))
    return files.fill(_poison(files, argv))


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """Exit code, stdout and stderr of the command line, run in this process."""
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(stdout):
        code = main(argv)
    return code, stdout.getvalue(), stderr.getvalue()


def assert_promise(argv: list[str], code: int, stdout: str, stderr: str) -> None:
    """The exit code is documented; a failure is one line; no traceback, no NaN answer."""
    allowed = ALLOWED.get(argv[0] if argv else "", {0, 2, 3, 4})
    assert code in allowed, f"exit {code}: {stderr}"
    assert "Traceback" not in stderr and "internal error" not in stderr, stderr
    if code:
        lines = [line for line in stderr.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("lawbench: "), stderr
    else:
        assert not NAN.search(stdout), stdout


@pytest.mark.parametrize("command", sorted(SUBCOMMANDS))
@pytest.mark.parametrize("examples", [20, pytest.param(150, marks=pytest.mark.slow)])
def test_every_option_answers_or_refuses_in_one_line(files, command, examples):
    deep = examples > 20

    @settings(
        max_examples=examples,
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
    )
    @given(argv=command_lines(command, files, deep))
    def check(argv):
        code, stdout, stderr = run_cli(argv)
        assert_promise(argv, code, stdout, stderr)

    check()


SERIAL = ["--executor", "serial", "--quiet", "--out", "{new}.csv"]
FIT = ["fit", "newton", "two_balls_wall", "--data", "{data}/trials.csv"]
# Command lines met while fuzzing, each a way the promise was broken.
MET = [
    ["report", "--out", "{plain}"],
    ["report", "--out", "{plain}/child"],
    ["check", ":", "--cases", "three_ball_chain", "--random", "0"],
    ["check", "..:x", "--cases", "three_ball_chain", "--random", "0"],
    ["check", "lawbench:Law", "--cases", "three_ball_chain", "--random", "0"],
    [*FIT, "--free", "e[99]"],
    [*FIT, "--free", "masses[5]"],
    [*FIT, "--free", "e", "--start", "e=nan"],
    [*FIT, "--free", "e", "--noise", "1e308"],
    [*FIT, "--free", "e,stiffness_ratio"],
    ["fit", "newton", "two_balls_wall", "--data", "{data}/ragged.csv", "--free", "e"],
    ["run", "--laws", "newton", "--cases", "three_ball_chain", "--param",
     "e=" + "[" * 100_000 + "]" * 100_000, *SERIAL],
    ["run", "{data}/reversed.toml", *SERIAL],
    ["run", "{data}/unbounded.toml", *SERIAL],
    ["run", "{data}/huge_size.toml", *SERIAL],
    ["run", "{data}/huge_count.toml", *SERIAL],
    ["run", "--laws", "newton", "--cases", "three_ball_chain", "--executor", "serial", "--quiet",
     "--out", "{data}/junk.parquet"],
    ["export", "ball_chain", "--set", "n=100000", "-o", "{new}.json"],
    ["solve", "moreau", "sphere_wall", "--set", "mass=1e300", "--json"],
    ["solve", "moreau", "falling_rod", "--set", "mass=1e300", "--json"],
    ["solve", "moreau", "rocking_block", "--set", "mass=1e308", "--json"],
    ["solve", "moreau", "sphere_wall", "--set", "mu=1e308", "--json"],
    ["solve", "moreau", "--problem", "{data}/problem.json\n"],
]  # fmt: skip


@pytest.mark.parametrize("argv", MET, ids=lambda argv: " ".join(argv)[:60])
def test_command_lines_met_while_fuzzing(files, argv):
    argv = files.fill(_poison(files, argv))
    code, stdout, stderr = run_cli(argv)
    assert_promise(argv, code, stdout, stderr)


@pytest.mark.parametrize(
    ("law", "case", "unit", "extreme", "factor"),
    [
        ("newton", "three_ball_chain", "masses=1,1,1", "masses=1e-300,1e-300,1e-300", 1.0),
        ("moreau", "three_ball_chain", "velocities=1,0,0", "velocities=1e150,0,0", 1e150),
        ("moreau", "sphere_wall", "mass=1", "mass=1e-300", 1.0),
        ("moreau", "falling_rod", "mu=1e8", "mu=1e300", 1.0),
    ],
)
def test_an_answer_with_status_ok_does_not_depend_on_the_scale(law, case, unit, extreme, factor):
    """Scaling every mass (or velocity) scales nothing (or every velocity) after the impact."""
    runs = []
    for assignment in (unit, extreme):
        code, stdout, stderr = run_cli(["solve", law, case, "--set", assignment, "--json"])
        runs.append((code, json.loads(stdout) if code == 0 else None, stderr))
    (_, reference, _), (code, answer, stderr) = runs
    assert reference is not None
    if code:
        assert_promise(["solve"], code, "", stderr)
        return
    expected = [factor * v for v in reference["v_plus"]]
    size = max(abs(v) for v in expected + [factor * v for v in reference["v_minus"]])
    gap = max(abs(a - b) for a, b in zip(answer["v_plus"], expected, strict=True))
    assert gap <= 1e-6 * size, (answer["status"], answer["v_plus"], expected)
