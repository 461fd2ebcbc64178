"""Fuzzing the files a user hands over: a corrupted file is refused, never a crash.

Hypothesis corrupts valid files of every format lawbench reads (its problem files in JSON, NPZ
and HDF5; FCLIB's local and global forms, among them a problem written by LMGC90; a TOML run
file; a CSV of measurements) by flipping, cutting and inserting bytes, and reads each back. A
read ends in a problem (the corruption missed what matters) or a `LawbenchError` naming what is
wrong: never another exception, and never the end of the process (an index read out of range).
The deeper run (more examples) is marked slow.
"""

import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import lawbench
from lawbench.files.fclib import write_fclib
from lawbench.files.problem_files import load_problem, save_problem
from lawbench.fitting.trials import read_trials
from lawbench.studies.grid import RunSpec

h5py = pytest.importorskip("h5py")

FIELD = Path(__file__).parent / "data" / "fclib" / "LMGC_GFC3D-i00001-1-00000.hdf5"
SPEC = b"""[[grid]]
laws = ["newton"]
cases = ["three_ball_chain"]
params = { e = [0.0, 0.5] }
"""
TRIALS = b"v1_minus,v2_minus,v3_minus,v1_plus,v2_plus,v3_plus\n1,0,0,0,0,1\n1,0,0,0.1,0,0.9\n"


def _problem_file(folder: Path, name: str) -> Path:
    problem = lawbench.CASES.get("ball_chain").build(n=40)
    return save_problem(problem, folder / name)


def _fclib_file(folder: Path, form: str) -> Path:
    problem = lawbench.CASES.get("sphere_wall").build(e=0.0, e_t=0.0)
    return write_fclib(problem, folder / f"{form}.h5", form)


def _copy(folder: Path, source: Path) -> Path:
    return Path(shutil.copy(source, folder / source.name))


def _text(folder: Path, name: str, content: bytes) -> Path:
    path = folder / name
    path.write_bytes(content)
    return path


# Each format: how to make a valid file in a folder, and how lawbench reads it.
FORMATS = {
    "json": (lambda f: _problem_file(f, "p.json"), load_problem),
    "npz": (lambda f: _problem_file(f, "p.npz"), load_problem),
    "hdf5": (lambda f: _problem_file(f, "p.h5"), load_problem),
    "fclib-local": (lambda f: _fclib_file(f, "local"), load_problem),
    "fclib-global": (lambda f: _fclib_file(f, "global"), load_problem),
    "fclib-lmgc90": (lambda f: _copy(f, FIELD), load_problem),
    "toml": (lambda f: _text(f, "spec.toml", SPEC), RunSpec.from_toml),
    "csv": (lambda f: _text(f, "trials.csv", TRIALS), lambda p: read_trials(p, "three_ball_chain")),
}

edits = st.lists(
    st.one_of(
        st.tuples(st.just("flip"), st.floats(0, 1, exclude_max=True), st.integers(1, 255)),
        st.tuples(st.just("cut"), st.floats(0, 1), st.just(0)),
        st.tuples(st.just("insert"), st.floats(0, 1), st.integers(0, 255)),
    ),
    min_size=1,
    max_size=6,
)


def corrupted(data: bytes, changes: list[tuple[str, float, int]]) -> bytes:
    """``data`` with each change applied at its relative position."""
    out = bytearray(data)
    for kind, where, value in changes:
        at = min(int(where * len(out)), max(len(out) - 1, 0))
        if kind == "flip" and out:
            out[at] ^= value
        elif kind == "cut":
            del out[at:]
        else:
            out.insert(at, value)
    return bytes(out)


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("examples", [25, pytest.param(400, marks=pytest.mark.slow)])
def test_a_corrupted_file_is_read_or_refused(tmp_path_factory, fmt, examples):
    make, read = FORMATS[fmt]
    valid = make(tmp_path_factory.mktemp(fmt)).read_bytes()

    @settings(max_examples=examples, deadline=None)
    @given(changes=edits)
    def read_back(changes):
        folder = tmp_path_factory.mktemp(fmt)
        path = make(folder)
        path.write_bytes(corrupted(valid, changes))
        try:
            read(path)
        except lawbench.LawbenchError:
            pass

    read_back()


def _hostile_fclib(path: Path, field: str, value: float, seed: int, form: str) -> Path:
    """The sphere on a wall as an FCLIB file whose ``field`` is made hostile.

    ``value`` scales the matrix (signs drawn from ``seed``: indefinite, skew) or sets ``mu``
    (from 1e-300 to 1e300), or is the size a matrix claims or a vector holds; a negative one
    makes a vector a group.
    """
    rng = np.random.default_rng(seed)
    problem = lawbench.CASES.get("sphere_wall").build(e=0.0, e_t=0.0)
    write_fclib(problem, path, form)
    size = int(min(abs(value), 1e12))
    with h5py.File(path, "a") as handle:
        root = handle[f"fclib_{form}"]
        vectors = root["vectors"]
        matrix = root["W" if form == "local" else "H"]
        if field == "spacedim":
            del root["spacedim"]
            root.create_dataset("spacedim", data=np.zeros(size % 3, dtype=np.int32))
        elif field in ("mu", "q", "f") and field in vectors and value < 0:
            del vectors[field]
            vectors.create_group(field)  # a group where a dataset belongs
        elif field in ("q", "f", "w") and field in vectors:
            data = rng.standard_normal(size % 9)
            del vectors[field]
            vectors.create_dataset(field, data=data)
        elif field == "mu":
            vectors["mu"][...] = abs(value)
        elif field == "shape":
            for key in ("m", "n"):
                del matrix[key]
                matrix.create_dataset(key, data=np.array([size], dtype=np.int64))
        elif field == "text":
            del matrix["x"]
            matrix.create_dataset("x", data=np.array([b"x"] * 3))
        else:  # the matrix scaled, or made indefinite and skew
            x = matrix["x"][()]
            matrix["x"][...] = x * abs(value) * np.where(rng.random(x.size) < 0.5, -1.0, 1.0)
    return path


@pytest.mark.parametrize("examples", [25, pytest.param(200, marks=pytest.mark.slow)])
def test_a_hostile_fclib_file_is_refused_or_answered_right(tmp_path_factory, examples):
    """Files valid in form: read, refused naming a field, or solved to tolerance with no
    contact left approaching, never an internal error, a NaN or a wrong answer labelled ok."""
    moreau = lawbench.LAWS.get("moreau")

    @settings(max_examples=examples, deadline=None, derandomize=True)
    @given(
        field=st.sampled_from(["spacedim", "mu", "q", "f", "w", "shape", "text", "scale"]),
        value=st.sampled_from([-1.0, 0.0, 1e-300, 1e-8, 2.0, 5.0, 7.0, 1e9, 1e300]),
        seed=st.integers(0, 3),
        form=st.sampled_from(["local", "global"]),
    )
    def solve_back(field, value, seed, form):
        path = tmp_path_factory.mktemp("hostile") / "p.h5"
        _hostile_fclib(path, field, value, seed, form)
        try:
            problem = load_problem(path)
            if not isinstance(problem, lawbench.ContactProblem):
                return
            solution = moreau.solve_contact(problem, max_steps=50)
        except lawbench.LawbenchError:
            return
        assert solution.fc3d_error <= 1e-10
        normal = solution.u[:: problem.dim]
        assert normal.min() >= -1e-5 * np.abs(problem.q).max()

    solve_back()
