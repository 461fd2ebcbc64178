"""A problem file is read once: the solve prints what that one read learned of the file.

``lawbench solve LAW --problem FILE`` runs in this process with ``h5py.File`` and ``open``
wrapped by a counter: the file is opened exactly once, whatever its encoding or FCLIB form, and
the facts of the read (form, layout, reformulation, W's asymmetry and rank) say what the file
holds.
"""

import builtins
import io
import os
from pathlib import Path

import numpy as np
import pytest

import lawbench
from lawbench.files.fclib import read_fclib_file
from lawbench.files.problem_files import load_problem, read_problem, save_problem
from lawbench.views.cli import main

h5py = pytest.importorskip("h5py")

DATA = Path(__file__).parent / "data" / "fclib"
# A local form of 24 contacts (Siconos) and a global form of one contact (LMGC90): both small.
LOCAL = DATA / "OneObject-i100000-499.hdf5"
GLOBAL = DATA / "LMGC_GFC3D-i00001-1-00000.hdf5"
# A global form whose M is not symmetric: read in contact space (tests/data/fclib/README.md).
NOT_AN_IMPACT = DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5"


@pytest.fixture
def opens(monkeypatch):
    """The paths opened through ``h5py.File``, ``open`` and ``io.open``, in order."""
    seen: list[Path] = []

    def counted(real):
        def opener(file, *args, **kwargs):
            if isinstance(file, str | os.PathLike):
                seen.append(Path(file).resolve())
            return real(file, *args, **kwargs)

        return opener

    monkeypatch.setattr(h5py, "File", counted(h5py.File))
    monkeypatch.setattr(builtins, "open", counted(builtins.open))
    monkeypatch.setattr(io, "open", counted(io.open))
    return seen


def solve_file(path, *flags):
    return main(["solve", "moreau", "--problem", str(path), *flags])


@pytest.mark.parametrize("path", [LOCAL, GLOBAL], ids=["local", "global"])
@pytest.mark.parametrize("flags", [(), ("--json",)], ids=["text", "json"])
def test_a_solve_opens_an_fclib_file_exactly_once(path, flags, opens, capsys):
    assert solve_file(path, *flags) == 0
    assert opens.count(path.resolve()) == 1
    assert "fc3d_error" in capsys.readouterr().out.replace("FC3D error", "fc3d_error")


@pytest.mark.parametrize("suffix", [".json", ".npz", ".h5"])
def test_a_solve_opens_a_lawbench_file_exactly_once(suffix, tmp_path, opens):
    problem = lawbench.CASES.get("three_ball_chain").build()
    path = save_problem(problem, tmp_path / f"p{suffix}")
    opens.clear()
    assert solve_file(path) == 0
    assert opens.count(path.resolve()) == 1


def test_the_facts_of_a_local_file():
    read = read_problem(LOCAL)
    assert read.facts.form == "local"
    assert dict(read.facts.storage)["W"] in {"triplets", "compressed columns", "compressed rows"}
    assert read.facts.reformulation == ""
    assert read.facts.asymmetry == pytest.approx(read.problem.asymmetry)
    W = read.problem.W.toarray()
    assert read.facts.rank == np.linalg.matrix_rank(W) <= W.shape[0]
    assert read.facts.diagnostics(None) == {}


def test_the_facts_of_a_global_file_give_the_fc3d_error_of_an_answer():
    read = read_problem(GLOBAL)
    assert read.facts.form == "global"
    assert [name for name, _ in read.facts.storage] == ["M", "H"]
    assert read.facts.reformulation == ""
    # W = H.T M^-1 H of a symmetric M is symmetric, to rounding.
    assert read.facts.asymmetry < 1e-10
    assert 1 <= read.facts.rank <= 3 * read.problem.m
    outcome = lawbench.LAWS["moreau"].resolve(read.problem)
    assert read.facts.diagnostics(outcome)["fc3d_error"] <= 1e-8


def test_a_global_file_that_is_no_impact_says_which_reformulation_it_had():
    read = read_problem(NOT_AN_IMPACT)
    assert "M is not symmetric" in read.facts.reformulation
    assert read.facts.reformulation in read.problem.name
    assert read.facts.asymmetry == pytest.approx(read.problem.asymmetry)


def test_a_lawbench_file_names_its_layouts_and_has_no_contact_space(tmp_path):
    problem = lawbench.CASES.get("three_ball_chain").build()
    read = read_problem(save_problem(problem, tmp_path / "p.npz"))
    assert read.facts.form == "lawbench"
    assert dict(read.facts.storage)["M"] == "dense"
    assert read.facts.asymmetry is None
    assert read.facts.rank is None


@pytest.mark.parametrize("path", [LOCAL, GLOBAL, NOT_AN_IMPACT], ids=lambda p: p.stem)
def test_load_problem_is_the_problem_of_read_problem(path):
    loaded, read = load_problem(path), read_fclib_file(path)
    assert type(loaded) is type(read.problem)
    assert loaded.m == read.problem.m
