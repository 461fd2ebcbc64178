"""The conventions users already know: --version, python -m, tidy frames and HTML views."""

import subprocess
import sys

import lawbench


def test_version_and_python_dash_m():
    version = subprocess.run(
        [sys.executable, "-m", "lawbench", "--version"], capture_output=True, text=True
    )
    assert version.returncode == 0
    assert version.stdout.strip() == f"lawbench {lawbench.__version__}"
    helped = subprocess.run(
        [sys.executable, "-m", "lawbench", "--help"], capture_output=True, text=True
    )
    assert helped.returncode == 0 and "solve" in helped.stdout


def test_outcome_and_checks_give_tidy_frames_and_html():
    trial = lawbench.evaluate("moreau", "three_ball_chain", e=1.0)
    frame = trial.outcome.to_frame()
    v_plus = frame[frame["quantity"] == "v_plus"]["value"].to_numpy()
    assert (v_plus == trial.outcome.v_plus).all()
    assert frame[frame["quantity"] == "dT"]["value"].item() == trial.outcome.dT
    assert "<table" in trial.outcome._repr_html_()
    checks = lawbench.run_checks(trial)
    table = checks.to_frame()
    assert list(table["check"]) == list(checks)
    assert set(table["verdict"]) <= {str(v) for v in lawbench.Verdict}
    assert "<table" in checks._repr_html_()
