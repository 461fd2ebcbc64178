"""Regression baselines: the committed outcomes of every law hold, and drift is reported."""

import subprocess
import sys

import numpy as np

import lawbench
from lawbench.studies.baselines import BASELINES, load, regress


def test_regress_passes_on_the_committed_baselines():
    result = subprocess.run(
        [sys.executable, "-m", "lawbench", "regress"], capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "every law holds its baseline" in result.stdout


def test_every_law_has_a_baseline_and_a_tolerance():
    _, tolerances = load()
    for law in lawbench.LAWS.names():
        assert (BASELINES / f"{law}.csv").exists(), law
        assert set(tolerances[law]) == {"v_plus", "Pn", "Pt", "T_plus"}, law


def test_a_law_moved_past_its_tolerance_is_named(monkeypatch, tmp_path):
    """Newton's output nudged by 1e-9 (its tolerance is 1e-12): regress names the law, the
    cases and the quantity, and writes what it obtained beside the baseline."""
    law = lawbench.LAWS.get("newton")
    original = law.resolve

    def nudged(problem, **options):
        outcome = original(problem, **options)
        outcome.v_plus[...] = outcome.v_plus + 1e-9
        return outcome

    monkeypatch.setattr(law, "resolve", nudged)
    for name in ("baseline.toml", "newton.csv"):
        (tmp_path / name).write_text((BASELINES / name).read_text())
    drift = regress(laws=["newton"], cases=["three_ball_chain"], folder=tmp_path)
    assert set(drift["law"]) == {"newton"}
    assert set(drift["case"]) == {"three_ball_chain"}
    assert "v_plus" in set(drift["quantity"])
    assert np.all(drift.loc[drift["quantity"] == "v_plus", "difference"] > 1e-12)
    assert (tmp_path / "newton.obtained.csv").exists()
