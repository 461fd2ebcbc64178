"""Hostile files, streams and run files: a clear refusal or a right answer, never a crash.

FCLIB files valid in form but hostile (an empty ``spacedim``, ``mu`` stored as a group, a global
form whose ``f`` is shorter than ``M``, a matrix that claims a billion rows, a ``W`` of 1e-300,
an indefinite or skew ``W``, ``mu = 1e300``); the standard streams closed, broken, full or
narrow; outputs on a full disk, under ``/sys`` or behind a symlink; resuming onto a table no run
wrote; run files with a negative seed, a fractional count or bad continuity sizes, options of a law
that has no cell in their grid, a check named twice. Every scene at the extremes of each of its
declared parameters (its bounds and just beyond, 0, subnormal, huge, negative, NaN, infinite,
text): an answer whose checks hold, or a refusal.
"""

import errno
import io
import json
import math
import os
import sys

import numpy as np
import pytest

import lawbench
from lawbench.core.mechanics import fc3d_error
from lawbench.core.verdicts import ACCEPTABLE
from lawbench.files.problem_files import load_problem
from lawbench.studies.grid import RunSpec
from lawbench.views.cli import main

h5py = pytest.importorskip("h5py")

Q = np.array([-1.0, 0.5, 0.2])


def _matrix(group, A, shape=None):
    rows, columns = np.nonzero(A)
    m, n = shape or A.shape
    for key, value in (("m", m), ("n", n), ("nz", rows.size), ("nzmax", rows.size)):
        group.create_dataset(key, data=np.array([value], dtype=np.int64))
    group.create_dataset("p", data=columns.astype(np.int32))
    group.create_dataset("i", data=rows.astype(np.int32))
    group.create_dataset("x", data=A[rows, columns])


def local_file(path, W=None, mu=0.3, *, spacedim=3, mu_as_group=False, shape=None, q=Q):
    """An FCLIB local form; each keyword makes one field hostile."""
    with h5py.File(path, "w") as handle:
        root = handle.create_group("fclib_local")
        root.create_dataset("spacedim", data=np.array(spacedim, dtype=np.int32).ravel())
        _matrix(root.create_group("W"), np.eye(3) if W is None else np.asarray(W), shape)
        vectors = root.create_group("vectors")
        vectors.create_dataset("q", data=q)
        if mu_as_group:
            vectors.create_group("mu")
        else:
            vectors.create_dataset("mu", data=[mu])
    return path


def global_file(path, f_size, n=6):
    with h5py.File(path, "w") as handle:
        root = handle.create_group("fclib_global")
        root.create_dataset("spacedim", data=np.array([3], dtype=np.int32))
        _matrix(root.create_group("M"), np.eye(n))
        _matrix(root.create_group("H"), np.eye(n, 3))
        vectors = root.create_group("vectors")
        vectors.create_dataset("f", data=np.ones(f_size))
        vectors.create_dataset("w", data=np.zeros(3))
        vectors.create_dataset("mu", data=[0.3])
    return path


def run_cli(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err):
    lines = [line for line in err.splitlines() if line.strip()]
    return len(lines) == 1 and lines[0].startswith("lawbench: ") and "internal error" not in err


HOSTILE = {
    "empty spacedim": (lambda p: local_file(p, spacedim=[]), "spacedim holds 0 entries"),
    "mu a group": (lambda p: local_file(p, mu_as_group=True), "mu is a group"),
    "f shorter than M": (lambda p: global_file(p, 4), "M is 6 x 6 where the 4 entries of f"),
    "a billion rows": (lambda p: local_file(p, shape=(10**9, 10**9)), "W is 1000000000 x"),
    "no coordinates": (lambda p: global_file(p, 0, n=0), "f holds no entry"),
}


@pytest.mark.parametrize("name", HOSTILE)
def test_a_hostile_fclib_file_is_refused_naming_its_field(tmp_path, capsys, name):
    make, message = HOSTILE[name]
    path = make(tmp_path / "p.h5")
    with pytest.raises(lawbench.InvalidProblem, match=message):
        load_problem(path)
    code, _, err = run_cli(["solve", "moreau", "--problem", path], capsys)
    assert code == 2 and one_line(err), err


@pytest.mark.parametrize("method", ["fixed_point", "nsgs"])
def test_a_tiny_delassus_matrix_is_solved_with_a_finite_error(tmp_path, capsys, method):
    path = local_file(tmp_path / "tiny.h5", 1e-300 * np.eye(3))
    code, out, err = run_cli(
        ["solve", "moreau", "--problem", path, "--option", f"method={method}", "--json"], capsys
    )
    assert code == 0, err
    answer = json.loads(out)
    assert answer["fc3d_error"] <= 1e-10
    assert answer["r"][0] == pytest.approx(1e300, rel=1e-6)


@pytest.mark.parametrize(
    ("W", "q"),
    [(1e-320 * np.eye(3), Q), (np.eye(3), [-1e308, 3e307, 1e307])],
    ids=["subnormal W", "huge q"],
)
@pytest.mark.parametrize("method", ["nsgs", "auto"])
def test_a_sweep_beyond_double_precision_fails_or_answers_right(tmp_path, capsys, W, q, method):
    """A block of W of 1e-320 has no finite inverse, and q of 1e308 overflows the sweep's
    local solves: numba's LinAlgError ended the command as an internal error, exit 1."""
    path = local_file(tmp_path / "w.h5", W, q=q)
    argv = ["solve", "moreau", "--problem", path, "--option", f"method={method}", "--json"]
    code, out, err = run_cli(argv, capsys)
    assert code in (0, 4) and (code == 0 or one_line(err)), err
    if code == 0:
        assert json.loads(out)["fc3d_error"] <= 1e-10


INDEFINITE = [[1.0, 2.0, 0.0], [2.0, -1.0, 0.5], [0.0, 0.5, 1.0]]
SKEW = [[1.0, 3.0, 0.0], [-3.0, 1.0, 2.0], [0.0, -2.0, 1.0]]


@pytest.mark.parametrize("W", [INDEFINITE, SKEW], ids=["indefinite", "skew"])
@pytest.mark.parametrize("mu", [0.3, 5.0])
def test_an_indefinite_or_skew_w_answers_right_or_fails_cleanly(tmp_path, capsys, W, mu):
    path = local_file(tmp_path / "w.h5", W, mu)
    argv = ["solve", "moreau", "--problem", path, "--option", "method=nsgs", "--json"]
    argv += ["--option", "max_steps=200"]
    code, out, err = run_cli(argv, capsys)
    assert code in (0, 3, 4), err
    if code:
        assert one_line(err), err
        return
    answer = json.loads(out)
    r, u = np.array(answer["r"]), np.array(answer["u"])
    assert answer["fc3d_error"] <= 1e-10
    assert u[0] >= -1e-5 * np.abs(Q).max() and np.abs(r).max() < 1e6


def test_a_huge_friction_coefficient_leaves_no_contact_approaching(tmp_path, capsys):
    path = local_file(tmp_path / "mu.h5", mu=1e300)
    for method in ("fixed_point", "nsgs"):
        argv = ["solve", "moreau", "--problem", path, "--option", f"method={method}", "--json"]
        code, out, err = run_cli(argv, capsys)
        assert code == 0, err
        answer = json.loads(out)
        # Sticking: W = I, so r = -q and every local velocity vanishes.
        assert np.allclose(answer["r"], -Q) and np.allclose(answer["u"], 0.0, atol=1e-12)


def test_the_fc3d_error_never_overflows_and_is_never_nan():
    W, mu, q = np.eye(3), np.array([0.3]), np.array([-1.0, 0.0, 0.0])
    assert fc3d_error(W, q, mu, np.array([1.0, 0.0, 0.0])) == 0.0
    assert fc3d_error(W, q, mu, np.array([0.5, 0.0, 0.0])) > 0
    # Impulses of 1e300 against a W of 1e-300: a solution, measured without overflow.
    assert fc3d_error(W * 1e-300, q, mu, np.array([1e300, 0.0, 0.0])) <= 1e-15
    assert fc3d_error(W, q, mu, np.array([math.inf, 0.0, 0.0])) == math.inf
    assert fc3d_error(W, q, mu, np.array([math.nan, 0.0, 0.0])) == math.inf


def test_run_files_refuse_a_negative_seed_a_fractional_count_and_bad_sizes():
    grid = [{"laws": ["newton"], "cases": ["three_ball_chain"]}]
    with pytest.raises(lawbench.InvalidProblem, match="'seed'"):
        RunSpec.from_dict({"grid": grid, "seed": -1})
    with pytest.raises(lawbench.InvalidProblem, match="'continuity_sizes'"):
        RunSpec.from_dict({"grid": grid, "continuity_sizes": [-1, math.nan]})
    with pytest.raises(lawbench.InvalidProblem, match=r"params\.e.*2\.5 is not a whole number"):
        RunSpec.from_dict({"grid": [{**grid[0], "params": {"e": {"range": [0, 1, 2.5]}}}]})
    with pytest.raises(lawbench.InvalidProblem, match="unknown key 'sizes'"):
        RunSpec.from_dict({"grid": grid, "sizes": [1]})


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (
            {"grid": [{"laws": ["newton"], "options": {"moreau": {"max_seconds": [5.0]}}}]},
            r"grid\[0\]\.options\.moreau: 'moreau' has no cell",
        ),
        (
            {"grid": [{"cases": ["two_balls_wall"], "options": {"brach": {"max_seconds": [5]}}}]},
            r"grid\[0\]\.options\.brach: 'brach' has no cell",
        ),
        (
            {"grid": [{"laws": ["newton"]}], "checks": ["momentum", "admissible", "momentum"]},
            "key 'checks' names the check 'momentum' twice",
        ),
    ],
    ids=["law not listed", "law that treats no case", "check twice"],
)
def test_run_files_refuse_options_no_cell_uses_and_a_check_named_twice(spec, message):
    """Both were taken: the options were silently ignored, and the check was run twice."""
    with pytest.raises(lawbench.InvalidProblem, match=message):
        RunSpec.from_dict(spec).rows()


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ({"params": {"e": {"random": [0, 1, 2], "log": "yes"}}}, r"params\.e\.log: must be true"),
        ({"params": {"e": {"random": [0, 1, 2], "sizes": 3}}}, "unknown key 'sizes'"),
        ({"params": {"e": {"range": [0, 1, 2], "logrange": [0, 1, 2]}}}, "unknown key 'logrange'"),
        ({"transforms": ["grazing=nan"]}, "'nan' is not a positive, finite speed"),
        ({"transforms": ["duplicated=-1"]}, "'-1' is not a contact's number"),
    ],
    ids=["log not a bool", "unknown generator key", "two generators", "nan speed", "contact -1"],
)
def test_run_files_refuse_a_bad_generator_or_transform_naming_it(entry, message):
    """Each was taken: ``log = "yes"`` drew logarithmically, ``sizes`` was ignored, the second
    generator was dropped, and the transforms failed row by row as 'unexplained' cells."""
    grid = {"laws": ["newton"], "cases": ["three_ball_chain"], **entry}
    with pytest.raises(lawbench.InvalidProblem, match=message):
        RunSpec.from_dict({"grid": [grid]}).rows()


RUN = ["run", "--laws", "newton", "--cases", "three_ball_chain", "--executor", "serial", "--quiet"]


@pytest.mark.parametrize(("laws", "e"), [("newton,newton", "e=0"), ("newton", "e=0,0")])
def test_a_cell_named_twice_is_computed_once_and_the_table_written(tmp_path, capsys, laws, e):
    """The table held one row per cell and waited for two: the run said '1 row in OUT' and
    exited 0, and no OUT was ever written."""
    out = tmp_path / "t.csv"
    argv = ["run", "--laws", laws, "--cases", "three_ball_chain", "--param", e, "--out", out]
    code, _, err = run_cli([*argv, "--executor", "serial", "--quiet"], capsys)
    assert code == 0, err
    assert len(lawbench.load_run(out)) == 1
    assert not (tmp_path / "t.csv.parts").exists()


def test_resume_refuses_a_users_own_table_and_one_whose_rows_changed(tmp_path, capsys):
    own = tmp_path / "own.csv"
    own.write_text("key,a\nx,1\ny,2\n")
    code, _, err = run_cli([*RUN, "--out", own, "--resume"], capsys)
    assert code == 2 and "a table no run wrote" in err and one_line(err)
    assert own.read_text() == "key,a\nx,1\ny,2\n"
    table = tmp_path / "r.csv"
    assert run_cli([*RUN, "--out", table], capsys)[0] == 0
    with table.open("a") as handle:
        handle.write(table.read_text().splitlines()[-1] + "\n")
    code, _, err = run_cli([*RUN, "--out", table, "--resume"], capsys)
    assert code == 2 and "rows were added" in err and one_line(err)


def test_a_symlink_out_is_written_through_and_a_full_disk_leaves_nothing(
    tmp_path, capsys, monkeypatch
):
    target, link = tmp_path / "target.json", tmp_path / "link.json"
    link.symlink_to(target)
    assert run_cli(["export", "three_ball_chain", "-o", link], capsys)[0] == 0
    assert link.is_symlink() and load_problem(target).m == 2

    def full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "replace", full)
    for argv in (
        ["export", "three_ball_chain", "-o", tmp_path / "p.json"],
        [*RUN, "--out", tmp_path / "t.csv"],
    ):
        code, _, err = run_cli(argv, capsys)
        assert code == 4 and "No space left on device" in err and one_line(err), err
    assert not (tmp_path / "p.json").exists() and not list(tmp_path.glob(".*.tmp"))


@pytest.mark.parametrize(
    "argv",
    [
        [*RUN, "--out", "/sys/lawbench.csv"],
        ["export", "three_ball_chain", "-o", "/sys/lawbench.json"],
        ["report", "--out", "/sys/lawbench-report"],
        ["bench", "--problems", ".", "--out", "/sys/lawbench.csv"],
    ],
    ids=["run", "export", "report", "bench"],
)
def test_an_output_that_cannot_be_written_is_exit_2_before_the_work(capsys, argv):
    code, _, err = run_cli(argv, capsys)
    assert code == 2 and one_line(err), err


def test_closed_broken_full_and_narrow_streams(tmp_path, capsys, monkeypatch):
    read, write = os.pipe()
    os.close(read)
    with os.fdopen(write, "w") as broken:
        monkeypatch.setattr(sys, "stdout", broken)
        assert main(["--version"]) == 1  # Python's advice on SIGPIPE: quiet, exit 1
    with open("/dev/full", "w") as full:
        monkeypatch.setattr(sys, "stdout", full)
        assert main(["list"]) == 4
    monkeypatch.undo()
    assert "No space left on device" in capsys.readouterr().err
    monkeypatch.setattr(sys, "stderr", None)  # 2>&-
    assert main(["solve", "nope", "three_ball_chain"]) == 2
    assert capsys.readouterr().out == ""
    monkeypatch.undo()
    narrow = io.TextIOWrapper(io.BytesIO(), encoding="ascii")
    monkeypatch.setattr(sys, "stdout", narrow)
    assert main(["export", "three_ball_chain", "-o", str(tmp_path / "é\udcff.json")]) == 0
    narrow.flush()
    assert b"\\xe9\\udcff.json" in narrow.buffer.getvalue()


def test_out_of_memory_is_one_line_and_exit_4(capsys, monkeypatch):
    from lawbench.views.cli import listing

    def exhausted(args):
        raise MemoryError

    monkeypatch.setattr(listing, "run", exhausted)
    code, _, err = run_cli(["list"], capsys)
    assert code == 4 and "out of memory" in err and one_line(err)


def extremes(spec):
    """Values of a scene parameter at its bounds, just beyond them, and far from them."""
    values = []
    for bound, direction in ((spec.low, -1.0), (spec.high, 1.0)):
        if bound is not None:
            values += [bound, float(np.nextafter(bound, direction * math.inf))]
    values += [0.0, 5e-324, 1e-300, 1.7e308, -1e300, math.nan, math.inf, "abc"]
    if spec.kind == "floats":
        return [
            value if isinstance(value, str) else [value] * len(spec.default) for value in values
        ]
    if spec.kind == "int":
        return [spec.low, spec.high + 1, spec.low - 1, 1.5, "abc"]
    return [True, False, "maybe", 2] if spec.kind == "bool" else values


def answers_or_refuses(law, scene, name, value, seconds):
    """An answer whose single-solve checks are all acceptable, or a one-line `LawbenchError`."""
    try:
        trial = lawbench.evaluate(law, scene, {"max_seconds": seconds}, **{name: value})
    except lawbench.LawbenchError as exc:
        assert "\n" not in str(exc) and str(exc), repr(exc)
        return
    assert np.isfinite(trial.outcome.v_plus).all()
    verdicts = {key: check.verdict for key, check in lawbench.run_checks(trial).items()}
    assert set(verdicts.values()) <= ACCEPTABLE, verdicts


SCENE_PARAMETERS = [
    (scene.name, spec.name, value)
    for scene in lawbench.CASES.values()
    for spec in scene.params
    for value in extremes(spec)
]


@pytest.mark.parametrize(("law", "share"), [("newton", 1), ("moreau", 5)])
def test_every_scene_at_the_extremes_of_its_parameters_answers_or_refuses(law, share):
    """The cheap part: Newton's law at every extreme, Moreau's at one in five, each within a
    short budget (running out of it is a refusal)."""
    for scene, name, value in SCENE_PARAMETERS[::share]:
        answers_or_refuses(law, scene, name, value, 0.5)


@pytest.mark.slow
@pytest.mark.parametrize(
    "law", ["newton", "moreau", "lzb", "compliant", "jia", "poisson", "whittaker"]
)
@pytest.mark.parametrize(("scene", "name", "value"), SCENE_PARAMETERS, ids=str)
def test_every_scene_at_every_extreme_answers_or_refuses_with_every_law(law, scene, name, value):
    answers_or_refuses(law, scene, name, value, 2)
