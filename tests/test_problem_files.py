"""Problems in files: every scene round-trips through JSON, NPZ and HDF5, bit for bit."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import lawbench
from lawbench.files.problem_files import load_problem, save_problem

ENCODINGS = (".json", ".npz", ".h5")
# The integrating laws cost seconds a solve and read the same arrays, which `same_problem`
# compares bit for bit: the closed-form laws' outcomes check what the arrays do not show (their
# types and layout).
SLOW = {"compliant", "lzb", "jia", "darboux_keller"}


def examples():
    for case in lawbench.CASES.values():
        for example in case.examples:
            yield pytest.param(case.name, example, id=f"{case.name}-{example}".replace(" ", "_"))


def same_problem(a, b):
    for name in ("M", "Wn", "v", "gaps"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert (a.Wt is None) == (b.Wt is None)
    if a.Wt is not None:
        assert np.array_equal(a.Wt, b.Wt)
    assert a.contacts == b.contacts
    assert a.bodies == b.bodies


def answer(law, problem):
    """The law's outcome on ``problem``, or the class of the error it raises."""
    try:
        return law.resolve(problem)
    except lawbench.LawbenchError as exc:
        return type(exc)


@pytest.mark.parametrize(("case", "example"), list(examples()))
def test_every_scene_round_trips_to_an_identical_problem_and_outcomes(case, example, tmp_path):
    scene = lawbench.CASES.get(case)
    problem = scene.build(**scene.examples[example])
    loaded = {
        suffix: load_problem(save_problem(problem, tmp_path / f"p{suffix}")) for suffix in ENCODINGS
    }
    for copy in loaded.values():
        same_problem(problem, copy)
    for law in lawbench.LAWS.values():
        if law.name in SLOW:
            continue
        if law.refusal(loaded[ENCODINGS[0]]) == "the scene declares no geometry":
            continue  # a file does not carry the geometry an engine builds
        expected = answer(law, problem)
        for suffix, copy in loaded.items():
            obtained = answer(law, copy)
            if isinstance(expected, type):
                assert obtained is expected, (law.name, suffix)
                continue
            for field in ("v_plus", "Pn", "Pt"):
                assert np.array_equal(getattr(expected, field), getattr(obtained, field)), (
                    law.name,
                    suffix,
                    field,
                )


def test_a_sparse_chain_is_stored_sparse(tmp_path):
    problem = lawbench.CASES.get("ball_chain").build(n=200)
    dense = tmp_path / "dense.json"
    sparse = save_problem(problem, tmp_path / "chain.npz")
    save_problem(problem, dense)
    with np.load(sparse) as archive:
        assert "M.data" in archive.files and "Wn.indptr" in archive.files
    assert sparse.stat().st_size < dense.stat().st_size / 20
    same_problem(problem, load_problem(sparse))


def run(*argv, cwd):
    return subprocess.run(
        [sys.executable, "-m", "lawbench", *argv], capture_output=True, text=True, cwd=cwd
    )


def test_export_then_solve_the_file_from_the_command_line(tmp_path):
    exported = run("export", "three_ball_chain", "--set", "e=0.5", "-o", "p.json", cwd=tmp_path)
    assert exported.returncode == 0, exported.stderr
    from_file = run("solve", "moreau", "--problem", "p.json", "--json", cwd=tmp_path)
    from_scene = run(
        "solve", "moreau", "three_ball_chain", "--set", "e=0.5", "--json", cwd=tmp_path
    )
    assert from_file.returncode == 0, from_file.stderr
    assert json.loads(from_file.stdout)["v_plus"] == json.loads(from_scene.stdout)["v_plus"]
    assert json.loads(from_file.stdout)["case"] == "problem"


GOOD = {
    "format": "lawbench-problem",
    "version": 1,
    "M": [[1.0]],
    "Wn": [[1.0]],
    "v": [-1.0],
    "contacts": [{"e": 0.5}],
}


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("p.json", {**GOOD, "version": 2}, "version 2 is not supported"),
        ("p.json", {**GOOD, "format": "other"}, "format is 'other'"),
        ("p.json", {k: v for k, v in GOOD.items() if k != "Wn"}, "field 'Wn' is missing"),
        ("p.json", {**GOOD, "Wn": [[1.0, 2.0]]}, r"Wn has shape \(1, 2\), expected \(1, 1\)"),
        ("p.json", {**GOOD, "contacts": [{"e": "half"}]}, r"contacts\[0\]\.e = 'half'"),
        ("p.json", {**GOOD, "contacts": [{"e": 1.5}]}, r"contacts\[0\]\.e = 1\.5"),
        ("p.json", "{not json", "malformed JSON"),
        ("p.json", {**GOOD, "v": ["a"]}, "field 'v' holds a value that is not a number"),
        ("p.json", {**GOOD, "M": [["one"]]}, "field 'M' holds a value that is not a number"),
        ("p.json", json.dumps(GOOD).replace('"v": [', '"v": [NaN, '), r"p\.json: NaN is not"),
        ("p.json", "[" * 100_000 + "]" * 100_000, "nested deeper"),
        ("p.json", b'{"format": "lawbench-problem", "x": "\xe9"}', "not UTF-8"),
        ("p.npz", "garbage bytes", "not a lawbench problem file"),
        ("p.txt", GOOD, "unknown extension '.txt'"),
    ],
)
def test_bad_files_exit_2_with_one_line_naming_the_field(tmp_path, name, content, message):
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content if isinstance(content, str) else json.dumps(content))
    with pytest.raises(lawbench.InvalidProblem, match=message):
        load_problem(path)
    done = run("solve", "newton", "--problem", name, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ({**GOOD, "contacts": [{"e": 10**400}]}, r"contacts\[0\]\.e: an integer of 1329 bits"),
        ({**GOOD, "M": [[10**400]]}, "field 'M' holds a value that is not a number"),
        ({**GOOD, "contacts": [{"mu": None}]}, r"contacts\[0\]\.mu = None: must be a number"),
        ({**GOOD, "colour": "red"}, "unknown key 'colour'; known: format"),
        ({**GOOD, "sparse": "yes"}, "field 'sparse' = 'yes': must be true or false"),
        ({**GOOD, "sparse": 1.5}, "field 'sparse' = 1.5: must be true or false"),
        ({**GOOD, "version": True}, "version True is not supported"),
    ],
)
def test_json_values_no_double_holds_unknown_keys_and_wrong_flags_are_refused(
    tmp_path, capsys, content, message
):
    """JSON integers have no bound: one of 400 digits was an OverflowError, and a null mu a
    TypeError in the law, each an internal error of ``lawbench solve``. Keys and flags were read
    only where known: a misspelt key or a flag of "yes" passed."""
    from lawbench.views import cli

    path = tmp_path / "p.json"
    path.write_text(json.dumps(content))
    with pytest.raises(lawbench.InvalidProblem, match=message):
        load_problem(path)
    assert cli.main(["solve", "moreau", "--problem", str(path)]) == 2
    assert len(capsys.readouterr().err.splitlines()) == 1


@pytest.mark.parametrize(
    ("arrays", "message"),
    [
        ({"sparse": np.array("yes")}, "field 'sparse' = array"),
        ({"sparse": np.array([True, False])}, "field 'sparse' = array"),
        ({"colour": np.array(1.0)}, "unknown array 'colour'"),
    ],
)
def test_an_array_file_with_an_unknown_array_or_a_wrong_flag_is_refused(tmp_path, arrays, message):
    path = save_problem(lawbench.CASES.get("ball_chain").build(n=4), tmp_path / "ok.npz")
    np.savez(tmp_path / "bad.npz", **dict(np.load(path, allow_pickle=False)), **arrays)
    with pytest.raises(lawbench.InvalidProblem, match=message):
        load_problem(tmp_path / "bad.npz")


@pytest.mark.parametrize("shape", [[1e300, 40], [math.inf, 40], [40.0, 40.0], [4, 1, 1], [-4, 40]])
def test_a_sparse_shape_that_is_not_two_non_negative_integers_is_refused(tmp_path, shape):
    """A claimed shape of 1e300 or inf was an OverflowError converting it to an integer."""
    path = save_problem(lawbench.CASES.get("ball_chain").build(n=80), tmp_path / "ok.npz")
    arrays = dict(np.load(path, allow_pickle=False))
    np.savez(tmp_path / "bad.npz", **{**arrays, "M.shape": np.array(shape)})
    with pytest.raises(lawbench.InvalidProblem, match="field 'M': its shape"):
        load_problem(tmp_path / "bad.npz")


def test_a_json_file_marked_sparse_is_read_with_sparse_matrices(tmp_path):
    problem = lawbench.CASES.get("ball_chain").build(n=80)
    path = save_problem(problem, tmp_path / "chain.json")
    path.write_text(json.dumps({**json.loads(path.read_text()), "sparse": True}))
    loaded = load_problem(path)
    assert loaded.sparse and np.array_equal(loaded.M.toarray(), problem.M)


@pytest.mark.parametrize("sparse", [False, True], ids=["dense", "marked sparse"])
def test_a_matrix_claiming_a_billion_columns_is_refused_before_it_is_allocated(tmp_path, sparse):
    """A few bytes of an NPZ claimed M to be 40 x 1e9 (298 GiB dense): a MemoryError."""
    path = tmp_path / "ok.npz"
    save_problem(lawbench.CASES.get("ball_chain").build(n=40), path)
    arrays = dict(np.load(path, allow_pickle=False))
    arrays["M.shape"] = np.array([40, 10**9])
    if sparse:
        arrays["sparse"] = np.array(True)
    np.savez(tmp_path / "bad.npz", **arrays)
    message = r"M has shape \(40, 1000000000\)" if sparse else "claims 40 x 1000000000 entries"
    with pytest.raises(lawbench.InvalidProblem, match=message):
        load_problem(tmp_path / "bad.npz")


@pytest.mark.parametrize(
    ("name", "fclib"),
    [("bc.npz", None), ("bc.json", None), ("bc.h5", None), ("l.h5", "local"), ("g.h5", "global")],
)
def test_the_projects_own_large_sparse_exports_are_read_back_and_solved(
    tmp_path, capsys, name, fclib
):
    """A 300-ball chain (its M and W stored sparse) exported in every format is solved from
    the file with exit 0, every check answered: the momentum check finds the free directions
    of a sparse problem, and the FCLIB forms interleave sparse columns. The local FCLIB form has
    no coordinates to check: it is solved in contact space, to its FC3D error."""
    from lawbench.views import cli

    export = ["export", "ball_chain", "--set", "n=300", "-o", str(tmp_path / name)]
    assert cli.main(export + (["--fclib", fclib] if fclib else [])) == 0
    capsys.readouterr()
    assert cli.main(["solve", "moreau", "--problem", str(tmp_path / name), "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["status"] == "ok"
    if fclib == "local":
        assert record["contacts"] == 299 and record["fc3d_error"] <= 1e-10
        return
    assert record["checks"]["momentum"]["verdict"] in ("holds", "refused")
    if fclib:
        assert record["diagnostics"]["fc3d_error"] <= 1e-10


def test_an_fclib_file_is_written_with_an_hdf5_extension_only(tmp_path):
    """FCLIB is HDF5: writing it under .json would leave HDF5 bytes where JSON is expected."""
    from lawbench.files.fclib import write_fclib

    problem = lawbench.CASES.get("three_ball_chain").build(e=[0.0])
    with pytest.raises(lawbench.InvalidProblem, match=r"extension is \.h5 or \.hdf5"):
        write_fclib(problem, tmp_path / "x.json")
    assert not (tmp_path / "x.json").exists()


@pytest.mark.parametrize(
    ("key", "entry", "value", "message"),
    [
        ("indices", 5, 10**6, "indices must be < 300"),
        ("indptr", 3, 10**7, "indptr must be a non-decreasing sequence"),
    ],
)
def test_corrupt_sparse_index_arrays_are_refused_before_they_are_read(
    tmp_path, key, entry, value, message
):
    """An index beyond the matrix in an NPZ's sparse triplets would be read out of bounds by
    scipy's compiled loops (the process died): every index is checked first, naming the file
    and the field."""
    path = tmp_path / "ok.npz"
    save_problem(lawbench.CASES.get("ball_chain").build(n=300), path)
    arrays = dict(np.load(path, allow_pickle=False))
    corrupt = arrays[f"M.{key}"].copy()
    corrupt[entry] = value
    np.savez(tmp_path / "bad.npz", **{**arrays, f"M.{key}": corrupt})
    with pytest.raises(lawbench.InvalidProblem, match=rf"bad\.npz: field 'M': .*{message}"):
        load_problem(tmp_path / "bad.npz")
