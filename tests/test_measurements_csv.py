"""A user's own CSV file of measured impacts, read as a measurement set, and refused when bad."""

import csv

import numpy as np
import pytest

from lawbench.core.errors import InvalidProblem
from lawbench.measurements import consistency, read_csv


def write(path, rows):
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return path


def row(v_after="0.98 0.5 0", Wn="0 1 0", train=""):
    """A ball of 1 kg (inertia 0.4) bouncing off a plane, planar: (vx, vy, omega)."""
    return {
        "n": "3",
        "m": "1",
        "d": "1",
        "M": "1 0 0 0 1 0 0 0 0.4",
        "Wn": Wn,
        "Wt": "1 0 1",
        "v_before": "0 -1 0",
        "v_after": v_after,
        "train": train,
    }


def test_a_csv_file_loads_as_a_set_of_measured_impacts(tmp_path):
    path = write(tmp_path / "drops.csv", [row(train="1"), row("0 0.9 0", train="0")])
    drops = read_csv(path)
    assert drops.name == "drops" and len(drops) == 2
    assert [i.index for i in drops.train] == [1] and [i.index for i in drops.test] == [2]
    first = drops.impacts[0]
    assert first.problem.Wt.shape == (3, 1) and np.allclose(first.v_after, [0.98, 0.5, 0])
    assert first.problem.contacts[0].e == 0.0 and first.problem.contacts[0].mu == 0.0
    # The second row is a pure normal bounce, the first a spin-free slide change: inconsistent.
    assert consistency(drops.test).median == pytest.approx(0.0, abs=1e-12)
    assert consistency(drops.train).median > 0.1


def test_a_bad_cell_is_refused_naming_its_column_and_row(tmp_path):
    path = write(tmp_path / "bad.csv", [row(), row(Wn="0 1")])
    with pytest.raises(InvalidProblem, match=r"column 'Wn', row 2: 2 numbers, expected 3"):
        read_csv(path)
    path = write(tmp_path / "words.csv", [row(v_after="fast")])
    with pytest.raises(InvalidProblem, match=r"column 'v_after', row 1"):
        read_csv(path)


def test_a_missing_column_is_refused_naming_it(tmp_path):
    rows = [{k: v for k, v in row().items() if k != "v_after"}]
    with pytest.raises(InvalidProblem, match=r"missing column.*v_after"):
        read_csv(write(tmp_path / "short.csv", rows))
