"""The tabulated studies and ``lawbench table``: rows, columns, no NaN, failures noted."""

from __future__ import annotations

import math
import subprocess
import sys
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest
from lawbench.cases.rocking_block import housner_ratio

import lawbench
from lawbench import tables
from lawbench.errors import SolverFailure
from lawbench.law import Law
from lawbench.tags import Tags


@pytest.fixture(scope="module")
def rocking():
    return tables.build_table("rocking_block")


@pytest.fixture(scope="module")
def sphere():
    return tables.build_table("sphere_wall")


def test_rocking_block_table_has_every_law_at_nine_aspect_ratios(rocking):
    frame = rocking.frame
    assert list(frame.columns) == [
        "law",
        "mu",
        "width_over_height",
        "omega_ratio",
        "housner",
        "difference",
    ]
    assert not frame.isna().any().any()
    assert set(frame["mu"]) <= {0.0, 1.0}
    for (_, _), group in frame.groupby(["law", "mu"]):
        np.testing.assert_allclose(group["width_over_height"], np.logspace(-1, 1, 9))
    present = set(frame["law"])
    for law in lawbench.LAWS.names():
        assert law in present or any(note.startswith(f"{law}: left out") for note in rocking.notes)
    np.testing.assert_allclose(
        frame["housner"], [housner_ratio(a, 1.0) for a in frame["width_over_height"]]
    )


def test_a_law_that_cannot_treat_two_contacts_is_left_out_with_the_reason(rocking):
    note = next(n for n in rocking.notes if n.startswith("brach:"))
    assert "left out" in note and "2 closed contacts" in note
    assert "brach" not in set(rocking.frame["law"])


def test_sticking_laws_reproduce_housner_where_it_holds(rocking):
    """Housner 1963: e = 0, mu = 1 sticks; the pivot lifts off while width <= sqrt(2) height."""
    frame = rocking.frame
    rows = frame[(frame["mu"] == 1.0) & (frame["width_over_height"] <= math.sqrt(2))]
    for law in {"moreau", "whittaker"} & set(rows["law"]):
        np.testing.assert_allclose(rows[rows["law"] == law]["difference"], 0.0, atol=1e-9)


def test_sphere_table_has_the_three_laws_or_their_reasons(sphere):
    frame = sphere.frame
    assert list(frame.columns) == [
        "law",
        "angle_deg",
        "ut_minus",
        "ut_plus",
        "spin_plus",
        "impulse_ratio",
    ]
    assert not frame.isna().any().any()
    for law in tables.SPHERE_LAWS:
        rows = frame[frame["law"] == law]
        if len(rows):
            np.testing.assert_allclose(rows["angle_deg"], np.linspace(5, 85, 9))
        else:
            assert any(note.startswith(f"{law}: left out") for note in sphere.notes)
    assert "brach" in set(frame["law"])


def test_sphere_table_brach_rows_follow_equation_11(sphere):
    """Eq. (11), spinless sphere: ut+ = -e_t ut- below tan(a) = 7 mu (1 + e) / (2 (1 + e_t)),
    impulse ratio mu above; the contact point velocity is vt - radius spin (rolling: equal)."""
    params = lawbench.CASES.get("sphere_wall").parameters()
    e, e_t, mu, radius = params["e"], params["e_t"], params["mu"], params["radius"]
    critical = math.degrees(math.atan(3.5 * mu * (1 + e) / (1 + e_t)))
    rows = sphere.frame[sphere.frame["law"] == "brach"]
    for row in rows.itertuples():
        if row.angle_deg < critical:
            assert row.ut_plus == pytest.approx(-e_t * row.ut_minus, abs=1e-12)
            assert row.impulse_ratio < mu
        else:
            assert row.impulse_ratio == pytest.approx(mu, rel=1e-12)
        vt = params["speed"] * math.sin(math.radians(row.angle_deg))
        centre = row.ut_plus + radius * row.spin_plus  # tangential velocity of the centre
        assert centre == pytest.approx(vt - row.impulse_ratio * _normal_impulse(params, row))


def _normal_impulse(params: dict[str, Any], row: Any) -> float:
    """Pn / m of eq. (11): (1 + e) times the approach speed."""
    return (1 + params["e"]) * params["speed"] * math.cos(math.radians(row.angle_deg))


class _Flaky(Law):
    """A law that fails on some rows, to check that a table goes on."""

    name = "flaky"
    summary = "fails above 40 degrees"
    source = "none"
    tags = Tags(friction=True, spatial=True)
    findings: ClassVar[dict] = {}

    def _resolve(self, problem, options):
        incidence = math.degrees(math.atan2(problem.v[0], -problem.v[1]))
        if incidence > 60:
            raise RuntimeError("a bug")
        if incidence > 40:
            raise SolverFailure("flaky: no convergence")
        return lawbench.LAWS.get("brach")._resolve(problem, options)


def test_a_failing_row_is_noted_and_the_table_goes_on(monkeypatch):
    monkeypatch.setitem(lawbench.LAWS._entries, "flaky", _Flaky())
    monkeypatch.setattr(tables, "SPHERE_LAWS", ("flaky", "not_a_law", "brach"))
    table = tables.sphere_wall_table()
    flaky = table.frame[table.frame["law"] == "flaky"]
    np.testing.assert_allclose(flaky["angle_deg"], [5, 15, 25, 35])
    assert len(table.frame[table.frame["law"] == "brach"]) == 9
    failures = [note for note in table.notes if note.startswith("flaky: failed")]
    assert len(failures) == 5
    assert any("SolverFailure" in note for note in failures)
    assert any("RuntimeError: a bug" in note for note in failures)
    assert "not_a_law: left out, not registered" in table.notes


def test_an_unknown_table_is_refused():
    with pytest.raises(lawbench.InvalidProblem, match="unknown table 'nope'"):
        tables.build_table("nope")


def test_the_command_writes_the_csv_and_prints_the_table(tmp_path):
    out = tmp_path / "sub" / "sphere.csv"
    result = subprocess.run(
        [sys.executable, "-m", "lawbench", "table", "sphere_wall", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    written = pd.read_csv(out)
    expected = tables.build_table("sphere_wall").frame
    assert list(written.columns) == list(expected.columns)
    assert len(written) == len(expected)
    np.testing.assert_allclose(written["ut_plus"], expected["ut_plus"], rtol=1e-12)
    assert "impulse_ratio" in result.stdout and str(out) in result.stdout


def test_the_command_refuses_an_unknown_table_in_one_line():
    result = subprocess.run(
        [sys.executable, "-m", "lawbench", "table", "nope"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "unknown table 'nope'" in result.stderr
