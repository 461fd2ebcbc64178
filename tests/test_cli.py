"""The ``lawbench`` command line: a stable contract that other tools script against.

Most calls run the command as a real subprocess (``python -m lawbench``, the same entry point
as the console script); the exit codes that need a law to misbehave on purpose call
`lawbench.views.cli.main` in the test process with a monkeypatched law.
"""

from __future__ import annotations

import csv
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import lawbench
from lawbench.checks import SINGLE_SOLVE
from lawbench.views import cli

CONSOLE_SCRIPT = Path(sys.executable).parent / "lawbench"
RECORD_KEYS = {
    "law",
    "case",
    "params",
    "coordinates",
    "v_minus",
    "v_plus",
    "Pn",
    "Pt",
    "T_minus",
    "T_plus",
    "checks",
    "status",
    "diagnostics",
}


def command_line(*args: str, script: bool = False) -> list[str]:
    """The argument vector of ``python -m lawbench ARGS`` or of the console script."""
    prefix = [str(CONSOLE_SCRIPT)] if script else [sys.executable, "-m", "lawbench"]
    return [*prefix, *args]


def run_together(*commands: list[str]) -> list[subprocess.CompletedProcess]:
    """Run the commands as concurrent subprocesses; return their results in order."""
    processes = [
        subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        for command in commands
    ]
    results = []
    for command, process in zip(commands, processes, strict=True):
        try:
            stdout, stderr = process.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            process.kill()
            raise
        results.append(subprocess.CompletedProcess(command, process.returncode, stdout, stderr))
    return results


def run_lawbench(*args: str, script: bool = False) -> subprocess.CompletedProcess:
    """Run the command line in a subprocess and capture its output as text."""
    return run_together(command_line(*args, script=script))[0]


def strict_json(text: str) -> dict:
    """Parse ``text`` as standard JSON: NaN and Infinity tokens are refused."""

    def refuse(token: str) -> None:
        raise ValueError(f"non-standard JSON token {token}")

    return json.loads(text, parse_constant=refuse)


def solve_json(*args: str) -> dict:
    """Run ``lawbench solve ARGS --json``, check it succeeded and return the parsed record."""
    result = run_lawbench("solve", *args, "--json")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    record = strict_json(result.stdout)
    assert isinstance(record, dict)
    return record


def section(text: str, title: str) -> list[str]:
    """First words of the indented lines that follow the line ``title``, up to the next title."""
    lines = text.splitlines()
    start = lines.index(title) + 1
    names = []
    for line in lines[start:]:
        if not line.startswith("  "):
            break
        names.append(line.split()[0])
    return names


# 1. list and describe


def test_list_prints_every_registered_law_and_case():
    result = run_lawbench("list")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert section(result.stdout, "laws:") == lawbench.LAWS.names()
    assert section(result.stdout, "cases:") == lawbench.CASES.names()


def test_describe_case_prints_parameters_coordinates_and_references():
    case = lawbench.CASES.get("three_ball_chain")
    result = run_lawbench("describe", "three_ball_chain")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert section(out, "parameters:") == [spec.name for spec in case.params]
    coordinates = case.coordinates(case.parameters())
    assert coordinates
    assert all(name in out for name in coordinates)
    assert case.references
    reference_lines = out.split("references:", 1)[1]
    for reference in case.references:
        assert reference.name in reference_lines
        assert f"[{reference.law}" in reference_lines


def test_describe_law_prints_its_options():
    law = lawbench.LAWS.get("moreau")
    result = run_lawbench("describe", "moreau")
    assert result.returncode == 0, result.stderr
    assert law.options
    assert section(result.stdout, "options:") == [spec.name for spec in law.options]
    for spec in law.options:
        assert repr(spec.default) in result.stdout


# 2. solve --json


def test_solve_json_record_has_the_documented_shape():
    case = lawbench.CASES.get("three_ball_chain")
    record = solve_json("moreau", "three_ball_chain")
    assert set(record) == RECORD_KEYS
    assert record["law"] == "moreau"
    assert record["case"] == "three_ball_chain"
    assert record["params"] == case.parameters()
    assert list(record["params"]) == [spec.name for spec in case.params]
    assert record["coordinates"] == case.coordinates(case.parameters())
    n = len(record["coordinates"])
    assert len(record["v_minus"]) == n
    assert len(record["v_plus"]) == n
    assert record["Pt"] == []
    assert isinstance(record["T_minus"], float)
    assert isinstance(record["T_plus"], float)
    assert isinstance(record["status"], str)
    assert set(record["checks"]) == set(SINGLE_SOLVE)
    for name, result in record["checks"].items():
        assert set(result) == {"value", "passed", "verdict", "detail", "claim"}, name
        assert result["passed"] in (True, False, None), name
        assert isinstance(result["detail"], str), name


def test_solve_set_fills_a_list_and_a_scalar_and_keeps_other_defaults():
    case = lawbench.CASES.get("three_ball_chain")
    record = solve_json(
        "newton",
        "three_ball_chain",
        "--set",
        "velocities=1,0,0",
        "--set",
        "e=0.5",
        "--set",
        "exponent=1",
    )
    params = record["params"]
    assert set(params) == {spec.name for spec in case.params}
    assert params["velocities"] == [1.0, 0.0, 0.0]
    assert record["v_minus"] == [1.0, 0.0, 0.0]
    # One restitution coefficient serves every contact.
    assert params["e"] and set(params["e"]) == {0.5}
    assert params["exponent"] == 1.0
    defaults = case.parameters()
    for name in ("masses", "stiffness_ratio", "gaps"):
        assert params[name] == defaults[name], name
    # The value set changes the result: e = 0.5 dissipates energy, the default e = 1 does not.
    assert record["T_plus"] < record["T_minus"]


def test_solve_option_reaches_the_sequential_law():
    args = ["solve", "sequential", "three_ball_chain", "--json"]
    results = run_together(
        command_line(*args), command_line(*args, "--option", "order=right_to_left")
    )
    for result in results:
        assert result.returncode == 0, result.stderr
    default, chosen = (strict_json(result.stdout) for result in results)
    assert chosen["diagnostics"]["options"]["order"] == "right_to_left"
    assert default["diagnostics"]["options"]["order"] != "right_to_left"
    assert "right_to_left" in chosen["diagnostics"]["formulation"]


def test_solve_without_json_prints_a_readable_table():
    result = run_lawbench("solve", "newton", "three_ball_chain")
    assert result.returncode == 0, result.stderr
    case = lawbench.CASES.get("three_ball_chain")
    for name in case.coordinates(case.parameters()):
        assert name in result.stdout
    for name in SINGLE_SOLVE:
        assert name in result.stdout


# 3. determinism


# The laws with an iterative solver (clarabel) or a sequence of steps.
@pytest.mark.parametrize("law", ["moreau", "poisson", "sequential"])
def test_solve_json_is_deterministic_apart_from_wall_time(law):
    args = ["solve", law, "three_ball_chain", "--set", "velocities=1,0,-1", "--set", "e=0.5,1"]
    records = []
    for result in run_together(command_line(*args, "--json"), command_line(*args, "--json")):
        assert result.returncode == 0, result.stderr
        record = strict_json(result.stdout)
        wall_time = record["diagnostics"].pop("wall_time_s")
        assert isinstance(wall_time, float)
        assert wall_time >= 0
        assert "wall_time_s" not in json.dumps(record)
        records.append(record)
    assert records[0] == records[1]
    # Identical text, key order included.
    assert json.dumps(records[0]) == json.dumps(records[1])


# 4. bad input


def assert_one_line_error(result: subprocess.CompletedProcess, code: int) -> str:
    """Check the exit code, one stderr line and no traceback; return that line."""
    assert result.returncode == code, (result.returncode, result.stdout, result.stderr)
    assert "Traceback" not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert result.stdout == ""
    return lines[0]


def listing(names: list[str]) -> list[str]:
    """Patterns matching each of ``names`` in a message."""
    return [re.escape(name) for name in names]


LAWS = lawbench.LAWS.names()
CASES = lawbench.CASES.names()
CHAIN_PARAMETERS = [spec.name for spec in lawbench.CASES.get("three_ball_chain").params]
SEQUENTIAL_OPTIONS = [spec.name for spec in lawbench.LAWS.get("sequential").options]


def chain_setting(setting: str, patterns: list[str], id: str) -> object:
    """A bad ``--set`` of ``solve newton three_ball_chain``, and what its message names."""
    return pytest.param(["solve", "newton", "three_ball_chain", "--set", setting], patterns, id=id)


BAD_INPUT = [
    chain_setting("e=1.5", [r"(?<![\w'\[])e(\[\d+\])?(?!\w)", r"1\.5"], "restitution-above-one"),
    chain_setting("masses=1,-1,1", [r"masses\[1\]", "-1"], "negative-mass"),
    chain_setting("velocities=1,0", [r"\bvelocities\b"], "wrong-number-of-velocities"),
    chain_setting("velocities=nan,0,0", [r"velocities\[0\]", "(?i)nan"], "nan-velocity"),
    chain_setting("foo=1", ["foo", *listing(CHAIN_PARAMETERS)], "unknown-parameter"),
    pytest.param(
        ["solve", "foo", "three_ball_chain"],
        ["foo", *listing(LAWS)],
        id="unknown-law",
    ),
    pytest.param(
        ["solve", "newton", "foo"],
        ["foo", *listing(CASES)],
        id="unknown-case",
    ),
    pytest.param(
        ["solve", "sequential", "three_ball_chain", "--option", "bogus=1"],
        ["bogus", *listing(SEQUENTIAL_OPTIONS)],
        id="unknown-option",
    ),
    pytest.param(
        ["solve", "newton", "three_ball_chain", "--set", "e0.5"],
        ["--set", "e0.5"],
        id="set-without-equals",
    ),
    pytest.param(
        ["solve", "newton", "three_ball_chain", "--option", "order"],
        ["--option", "order"],
        id="option-without-equals",
    ),
    pytest.param(
        ["solve", "newton", "three_ball_chain", "--json", "--set", "velocities=1e200,0,0"],
        [r"\bv\b", "overflows"],
        id="kinetic-energy-overflow",
    ),
    pytest.param(
        ["solve", "newton", "three_ball_chain", "--set", "e=1", "--set", "e=0"],
        ["--set e", "twice"],
        id="parameter-given-twice",
    ),
    pytest.param(["frobnicate"], ["frobnicate"], id="unknown-subcommand"),
    pytest.param(["describe", "foo"], ["foo"], id="describe-unknown-name"),
]


@pytest.mark.parametrize(("args", "patterns"), BAD_INPUT)
def test_bad_input_exits_2_with_one_line_naming_the_culprit(args, patterns):
    line = assert_one_line_error(run_lawbench(*args), 2)
    for pattern in patterns:
        assert re.search(pattern, line), (pattern, line)


def test_main_returns_the_usage_exit_code_instead_of_raising(capsys):
    assert cli.main(["frobnicate"]) == 2
    assert "frobnicate" in capsys.readouterr().err
    assert cli.main(["solve"]) == 2


def test_solver_failure_exits_4_with_one_line():
    result = run_lawbench(
        "solve", "sequential", "two_balls_wall", "--set", "e=0", "--option", "max_steps=5"
    )
    line = assert_one_line_error(result, 4)
    assert re.search(r"\(5 binary impacts.*, max_steps\) after \d[\d.e-]* s$", line), line


def test_same_scene_without_the_impact_bound_succeeds():
    # The failure above comes from max_steps, not from the scene.
    record = solve_json("sequential", "two_balls_wall", "--set", "e=0")
    assert set(record) == RECORD_KEYS
    assert record["diagnostics"]["impacts"] > 5
    assert record["Pt"] == []
    assert len(record["Pn"]) == 2


@pytest.mark.parametrize(
    ("error", "code"),
    [
        pytest.param(lawbench.NotApplicable("x"), 3, id="not-applicable"),
        pytest.param(lawbench.SolverFailure("x"), 4, id="solver-failure"),
        pytest.param(RuntimeError("x"), 1, id="internal-error"),
    ],
)
def test_main_maps_law_errors_to_exit_codes(monkeypatch, capsys, error, code):
    law = lawbench.LAWS.get("newton")

    def resolve(problem, **options):
        raise error

    monkeypatch.setattr(law, "resolve", resolve)
    assert cli.main(["solve", "newton", "three_ball_chain", "--json"]) == code
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert "Traceback" not in captured.err
    assert lines[0].endswith("x")
    # Nothing stays patched: the law resolves again.
    monkeypatch.undo()
    assert "resolve" not in vars(law)
    assert cli.main(["solve", "newton", "three_ball_chain", "--json"]) == 0


# 5. python -m and the console script


def test_console_script_and_python_m_print_the_same_list():
    assert CONSOLE_SCRIPT.exists(), CONSOLE_SCRIPT
    script, module = run_together(command_line("list", script=True), command_line("list"))
    assert script.returncode == module.returncode == 0
    assert script.stdout == module.stdout
    assert script.stdout.strip()


def test_console_script_reports_bad_input_like_python_m():
    args = ["solve", "newton", "three_ball_chain", "--set", "e=1.5"]
    script, module = run_together(command_line(*args, script=True), command_line(*args))
    assert assert_one_line_error(script, 2) == assert_one_line_error(module, 2)


# 6. report


@pytest.mark.slow
def test_report_writes_its_three_files(tmp_path):
    out = tmp_path / "report"
    result = run_lawbench("report", "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert str(out) in result.stdout
    for name in ("report.md", "index.html", "comparison.csv"):
        assert (out / name).is_file(), name
        assert (out / name).stat().st_size > 0, name
    markdown = (out / "report.md").read_text()
    for name in lawbench.LAWS.names():
        assert name in markdown, name
    with (out / "comparison.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {row["law"] for row in rows} == set(lawbench.LAWS.names())
    assert {row["case"] for row in rows} <= set(lawbench.CASES.names())
    assert "<table" in (out / "index.html").read_text()


@pytest.mark.parametrize(
    ("args", "code", "pattern"),
    [
        (["solve", "whittaker", "falling_rod", "--set", "mu=-1"], 2, r"mu = -1"),
        (["solve", "brach", "sphere_wall", "--set", "e_t=1.5"], 2, r"e_t = 1\.5"),
        (["solve", "lzb", "sphere_wall"], 3, r"lzb: the problem is spatial"),
    ],
    ids=["negative-mu", "tangential-restitution-above-one", "planar-law-on-a-spatial-scene"],
)
def test_frictional_bad_input_has_the_right_exit_code(args, code, pattern):
    line = assert_one_line_error(run_lawbench(*args), code)
    assert re.search(pattern, line), line


HEAVY = ("scipy.integrate", "cvxpy", "pandas", "matplotlib", "dask")


@pytest.mark.parametrize("argv", [["list"], ["solve", "newton", "three_ball_chain"]])
def test_small_commands_import_no_heavy_library(argv):
    """Laws register by name; an integrator, a table or plotting library loads on first use."""
    code = (
        "import contextlib, io, sys\n"
        "from lawbench.views.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main({argv!r})\n"
        f"print(sorted(m for m in sys.modules if m.split('.')[0] in {HEAVY!r} "
        f"or m.startswith('scipy.integrate')))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.mark.parametrize("module", ["importlib.metadata", "lawbench.core.batch"])
def test_a_solve_of_built_in_entries_reads_no_metadata_and_no_batch_code(module):
    """A built-in law on a built-in scene needs no plugin lookup and no version: the package
    metadata (a third of the start-up) is read only for ``list``, plugins and ``--version``;
    nor does one solve read the batch module, compiled at every start without cached bytecode."""
    code = (
        "import contextlib, io, sys\n"
        "from lawbench.views.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    main(['solve', 'newton', 'three_ball_chain'])\n"
        f"print({module!r} in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_describe_names_every_scenes_ground_truth(capsys):
    """A scene's outcomes are measured against its declared ground truth: describe prints it,
    with why, on a line of its own. Every scene has one, and none is a rigid law under test:
    a closed form, or the time-domain model of compliant contact."""
    for case in lawbench.CASES.values():
        truth = case.ground_truth
        assert truth is not None, case.name
        assert truth.law in (None, "compliant"), (case.name, truth.law)
    for name in CASES:
        assert cli.main(["describe", name]) == 0
        stdout = capsys.readouterr().out
        (line,) = [line for line in stdout.splitlines() if line.startswith("ground truth:")]
        truth = lawbench.CASES[name].ground_truth
        expected = (
            f"ground truth: {truth.describe()}: {truth.why}" if truth else "ground truth: none"
        )
        assert line == expected


# Paths a careless or hostile user gives: a FIFO blocks whoever opens it, so each must be refused
# from its status alone, before anything opens it (the test would hang otherwise).
FIFO_COMMANDS = [
    (["solve", "newton", "--problem", "{fifo}.json"], "problem file"),
    (["solve", "moreau", "--problem", "{fifo}.h5"], "problem file"),
    (["run", "{fifo}.toml"], "spec"),
    (["fit", "newton", "three_ball_chain", "--data", "{fifo}.csv", "--free", "e"], "data"),
    (["export", "three_ball_chain", "-o", "{fifo}.json"], "problem file"),
    (["export", "three_ball_chain", "--fclib", "local", "-o", "{fifo}.h5"], "FCLIB file"),
    (["run", "--laws", "newton", "--cases", "three_ball_chain", "--out", "{fifo}.csv"], "run"),
    (["study", "rocking_block", "--out", "{fifo}.parquet"], "table"),
]


@pytest.mark.parametrize(("argv", "what"), FIFO_COMMANDS, ids=lambda x: " ".join(x[:2]))
def test_a_fifo_or_a_directory_is_refused_before_it_is_opened(tmp_path, capsys, argv, what):
    """Every file a command reads or writes must be a regular file (or a new one, to write):
    a FIFO and a directory are refused with exit 2, naming the argument's role and the kind."""
    import os

    for suffix in (".json", ".h5", ".toml", ".csv", ".parquet"):
        os.mkfifo(tmp_path / f"p{suffix}")
        (tmp_path / f"d{suffix}").mkdir()
    for name, kind in (("p", "a FIFO"), ("d", "a directory")):
        given = [a.format(fifo=tmp_path / name) for a in argv]
        assert cli.main(given) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and what in err[0] and kind in err[0], err


@pytest.mark.parametrize(
    "argv",
    [
        ["solve", "newton", "three_ball_chain", "--max-seconds", value]
        for value in ("-1", "0", "nan", "inf", "1e20", "soon")
    ]
    + [
        ["run", "--laws", "newton", "--cases", "three_ball_chain", "--workers", "100000"],
        ["run", "--laws", "newton", "--cases", "three_ball_chain", "--workers", "0"],
        ["run", "--laws", "newton", "--cases", "three_ball_chain", "--chunk-size", "0"],
        ["run", "--laws", "newton", "--cases", "three_ball_chain", "--max-seconds", "-5"],
        ["run", "--laws", "newton", "--cases", "three_ball_chain", "--seed", "-1"],
        ["study", "rocking_block", "--max-seconds", "nan"],
        ["check", "newton", "--random", "1000000000"],
        [
            "fit",
            "newton",
            "three_ball_chain",
            "--data",
            "x.csv",
            "--free",
            "e",
            "--bootstrap",
            "1000000000",
        ],
        ["fit", "newton", "three_ball_chain", "--data", "x.csv", "--free", "e", "--holdout", "1.5"],
    ],
    ids=lambda argv: " ".join(argv[:1] + argv[-2:]),
)
def test_every_count_and_wall_clock_limit_has_a_range(tmp_path, capsys, monkeypatch, argv):
    """A worker count, a repeat count, a seed and a wall-clock limit outside their ranges stop
    the command at once with a usage error (exit 2) naming the argument: no run starts 100000
    workers or a billion bootstrap refits, and no limit of -1, 0, NaN or inf seconds is taken."""
    monkeypatch.chdir(tmp_path)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"argument {argv[-2]}" in err[0], err


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["regress", "--laws", "nolaw"], "unknown law 'nolaw'"),
        (["regress", "--cases", "nocase"], "unknown case 'nocase'"),
        (["regress", "--laws", ""], "--laws '': an empty name"),
        (["check", "newton", "--cases", "nocase", "--random", "0"], "unknown case 'nocase'"),
        (["run", "--laws", "newton", "--cases", ""], "--cases '': an empty name"),
        (["run", "--laws", "newton,", "--cases", "three_ball_chain"], "an empty name"),
        (["run", "--laws", "nolaw", "--cases", "three_ball_chain"], "unknown law 'nolaw'"),
        (["run", "--laws", "newton", "--out", ""], "argument --out: an empty path"),
        (["study", "rocking_block", "--out", " "], "argument --out: an empty path"),
        (["report", "--out", ""], "argument --out: an empty path"),
        (["solve", "newton", "--problem", ""], "argument --problem: an empty path"),
        (["export", "three_ball_chain", "-o", ""], "an empty path"),
    ],
    ids=lambda x: " ".join(x) if isinstance(x, list) else None,
)
def test_unknown_or_empty_names_and_paths_are_refused(tmp_path, capsys, monkeypatch, argv, said):
    """A misspelled or empty law or scene never selects nothing (a regression that 'holds' on
    no law, a check that passes on no scene), and an empty path never names the current
    folder: exit 2, one line naming the argument."""
    monkeypatch.chdir(tmp_path)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and said in err[0], err
    assert not any(tmp_path.iterdir())


def test_a_check_with_nothing_to_check_is_refused(capsys):
    """A check on scenes the law does not treat, with no random problem, checks nothing: it
    is refused (exit 3), never a pass."""
    assert cli.main(["check", "brach", "--cases", "three_ball_chain", "--random", "0"]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nothing to check" in err[0], err


def test_the_python_api_refuses_unknown_names_too():
    """regress and check_law name what they do not know rather than return an empty result."""
    from lawbench.studies.baselines import regress
    from lawbench.studies.conformance import check_law

    with pytest.raises(lawbench.UnknownName, match="nolaw"):
        regress(["nolaw"])
    with pytest.raises(lawbench.UnknownName, match="nocase"):
        check_law("newton", cases=["nocase"], random_problems=0)


def test_library_warnings_stay_in_the_diagnostics_unless_asked_for(capsys, monkeypatch):
    """A warning raised inside a solve (scipy's LSODA complaining, a numpy overflow) is kept in
    the outcome's diagnostics, not printed: stderr carries only lawbench's own lines, and the
    warning is shown under --verbose."""
    import warnings

    law = type(lawbench.LAWS.get("newton"))
    resolve = law._resolve

    def noisy(self, problem, options):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        return resolve(self, problem, options)

    monkeypatch.setattr(law, "_resolve", noisy)
    outcome = lawbench.solve("newton", lawbench.CASES.get("three_ball_chain").build())
    assert outcome.diagnostics["warnings"] == ["RuntimeWarning: overflow encountered in multiply"]
    assert cli.main(["solve", "newton", "three_ball_chain", "--json"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and "overflow" in json.loads(out)["diagnostics"]["warnings"][0]
    assert cli.main(["--verbose", "solve", "newton", "three_ball_chain"]) == 0
    assert "lawbench: warning: RuntimeWarning: overflow" in capsys.readouterr().err
