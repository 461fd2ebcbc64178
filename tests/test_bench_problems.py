"""``lawbench bench --problems DIR``: every law and method on every problem file of a folder.

Sources: Dolan and Moré (2002), "Benchmarking optimization software with performance profiles",
for the profiles; Acary, Brémond and Huber (2018) for the FC3D error that decides whether a
frictional problem is solved; nevergrad's runner for rows that record their failure.
"""

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from lawbench.bench import COLUMNS, performance_profiles, solvers
from lawbench.bench.peer import siconos_available
from lawbench.bench.problems import PEER
from lawbench.views.cli import main

pytest.importorskip("h5py")

FCLIB = Path(__file__).parent / "data" / "fclib"
# One law with two methods, one without a method that refuses frictional problems.
LAWS = "moreau,newton"
# Gauss-Seidel settles away from any solution on this singular W, as Siconos' NSGS does; the
# fixed point solves it (tests/data/fclib).
STALLS = "OneObject-i100000-499.hdf5"


def solved_but_where_the_law_says_why(moreau):
    """Every Moreau row solves its file to 1e-8 but Gauss-Seidel's on the singular W, whose
    failure says why."""
    stalled = (moreau["file"] == STALLS) & (moreau["method"] == "nsgs")
    assert list(moreau.loc[stalled, "status"]) == ["solver failure"]
    assert "W is singular, rank 49 of 72" in moreau.loc[stalled, "error"].iloc[0]
    assert (moreau.loc[~stalled, "status"] == "ok").all()
    assert (moreau.loc[~stalled, "fc3d_error"] <= 1e-8).all()


@pytest.fixture
def folder(tmp_path):
    """A copy of the committed FCLIB files, with one damaged file among them.

    Without the 286 capsules: the fixed point spends about a minute on them, and their solve at
    the defaults is tested in tests/test_moreau_defaults.py (slow profile).
    """
    copy = tmp_path / "problems"
    shutil.copytree(FCLIB, copy, ignore=shutil.ignore_patterns("*.md", "Capsules-*"))
    (copy / "damaged.hdf5").write_bytes(b"not an HDF5 file")
    return copy


def test_one_row_per_file_law_and_method_and_a_profile_figure(folder, tmp_path, capsys):
    out = tmp_path / "bench" / "table.csv"
    code = main(["bench", "--problems", str(folder), "--laws", LAWS, "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    table = pd.read_csv(out, comment="#", keep_default_na=False, na_values=[""])
    assert list(table.columns) == list(COLUMNS)
    files = sorted(p.name for p in folder.iterdir())
    pairs = solvers(LAWS.split(","))
    assert ("moreau", "nsgs") in pairs and ("newton", "") in pairs
    # Siconos' NSGS joins where the bench finds Siconos, as `lawbench bench` does.
    rows_per_file = pairs + [PEER] * siconos_available()
    assert len(table) == len(files) * len(rows_per_file)
    assert sorted(set(table["file"])) == files
    for (law, method), rows in table.fillna({"method": ""}).groupby(["law", "method"]):
        assert (law, method) in rows_per_file
        assert sorted(rows["file"]) == files
    solved_but_where_the_law_says_why(
        table[(table["law"] == "moreau") & (table["file"] != "damaged.hdf5")]
    )
    newton = table[(table["law"] == "newton") & (table["file"] != "damaged.hdf5")]
    assert (newton["status"] == "not applicable").all()
    assert out.with_suffix(".png").stat().st_size > 0
    assert "Siconos" in out.read_text().splitlines()[1] or "siconos" in set(table["law"])
    assert "moreau (nsgs)" in capsys.readouterr().out


def test_a_damaged_file_is_an_error_row_and_the_others_are_solved(folder, tmp_path):
    out = tmp_path / "table.csv"
    assert main(["bench", "--problems", str(folder), "--laws", "moreau", "--out", str(out)]) == 0
    table = pd.read_csv(out, comment="#")
    damaged = table[table["file"] == "damaged.hdf5"]
    assert len(damaged) == len(solvers(["moreau"])) + siconos_available()
    assert (damaged["status"] == "error").all()
    assert damaged["error"].str.startswith("InvalidProblem").all()
    solved_but_where_the_law_says_why(
        table[(table["file"] != "damaged.hdf5") & (table["law"] == "moreau")]
    )


@pytest.mark.parametrize("where", ["missing", "empty"])
def test_a_missing_or_empty_folder_is_refused_in_one_line(tmp_path, capsys, where):
    folder = tmp_path / "problems"
    if where == "empty":
        folder.mkdir()
    assert main(["bench", "--problems", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("lawbench: bench --problems") and err.count("\n") == 1


def test_performance_ratios_follow_dolan_and_more():
    """r_ps = t_ps / min_s t_ps; unsolved is infinite; a solver that solves nothing is absent."""
    table = pd.DataFrame(
        [
            ("a", 3, "x", "", "ok", 1e-12, 1.0),
            ("a", 3, "y", "", "ok", 1e-12, 4.0),
            ("b", 3, "x", "", "ok", 1e-3, 1.0),  # above the FC3D threshold: unsolved
            ("b", 3, "y", "", "ok", 1e-9, 2.0),
            ("a", 3, "z", "", "budget", np.nan, np.nan),
            ("b", 3, "z", "", "budget", np.nan, np.nan),
        ],
        columns=COLUMNS[:-1],
    ).assign(error="")
    ratios = performance_profiles(table)
    assert set(ratios) == {"x", "y"}
    np.testing.assert_array_equal(ratios["x"], [1.0, np.inf])
    np.testing.assert_array_equal(ratios["y"], [1.0, 4.0])
