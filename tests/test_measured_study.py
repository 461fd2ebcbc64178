"""Laws fitted on a measured set's training impacts and judged on its test impacts."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from lawbench.core.errors import InvalidProblem, NotApplicable
from lawbench.core.law import LAWS
from lawbench.core.problem import CONTACT_RANGES
from lawbench.fitting import heldout
from lawbench.fitting.measured import (
    COLUMNS,
    evenly,
    measured_study,
    predict,
    ranked,
    study_options,
)
from lawbench.measurements import MEASUREMENTS, MeasurementSet, Processing
from lawbench.views.cli import main

ELLIPSE = MEASUREMENTS.get("ellipse")


def small_set(train, test, name="small", facts=None):
    """A set of the given impacts, the first ones to fit and the others to judge."""
    impacts = [*train, *test]
    mask = np.arange(len(impacts)) < len(train)
    processing = Processing("chosen by the test", len(impacts), {})
    return MeasurementSet(
        name,
        "impacts chosen by a test",
        ELLIPSE.source,
        lambda: (impacts, mask, processing),
        facts or {},
    )


def made_by(law, impacts, **coefficients):
    """The impacts with their velocity after replaced by ``law``'s at ``coefficients``."""
    velocities, failures = predict(LAWS.get(law), impacts, coefficients, {})
    assert not failures
    return [dataclasses.replace(i, v_after=v) for i, v in zip(impacts, velocities, strict=True)]


@pytest.fixture(scope="module")
def thirty():
    """30 ellipse impacts of each half, evenly spaced: the split is the set's."""
    return evenly(ELLIPSE.train, 30), evenly(ELLIPSE.test, 30)


def test_every_law_declares_contact_fields_it_fits():
    fields = {name for name, *_ in CONTACT_RANGES}
    for name in LAWS.names():
        fitted = LAWS.get(name).fitted
        assert fitted and set(fitted) <= fields, name
    assert set(LAWS.get("whittaker").fitted) == {"e", "mu"}


def test_a_law_fitted_on_ellipse_impacts_beats_the_baselines(thirty):
    """Whittaker's and Moreau's laws are one law at one planar contact: one fit, one error."""
    train, test = thirty
    study = measured_study(
        small_set(train[:10], test[:20], facts=ELLIPSE.facts), ["whittaker", "moreau"]
    )
    table = study.table.set_index(["law", "coefficients"])
    assert list(study.table.columns[:2]) == ["law", "coefficients"]
    assert set(COLUMNS) <= set(study.table.columns) and {"e", "mu", "e_se"} <= set(table.columns)
    whittaker, moreau = table.loc[("whittaker", "fitted")], table.loc[("moreau", "fitted")]
    assert 0.4 < whittaker["e"] < 0.7 and 0.05 < whittaker["mu"] < 0.3
    assert moreau["e"] == pytest.approx(whittaker["e"], abs=1e-3)
    assert moreau["median_error"] == pytest.approx(whittaker["median_error"], rel=1e-3)
    assert whittaker["ci_low"] <= whittaker["median_error"] <= whittaker["ci_high"]
    for baseline in heldout.BASELINES:
        assert whittaker["median_error"] < table.loc[(baseline, "fitted"), "median_error"]
    assert ("whittaker", "ICRA 2017") in table.index and ("moreau", "CoRL 2017") in table.index
    assert table.loc[("whittaker", "ICRA 2017"), "mu"] == 0.057
    assert study.table["common_error"].is_monotonic_increasing and study.common_count == 20
    judged = study.predictions.query("law == 'whittaker' and coefficients == 'fitted'")
    assert len(judged) == 20 and (judged["status"] == "ok").all()
    assert np.median(judged["error"]) == pytest.approx(whittaker["median_error"])


def test_a_set_made_by_a_law_is_fitted_back_to_its_coefficients(thirty):
    """At mu = 0.1 the ellipse slips through most impacts: friction is identifiable."""
    train, test = (made_by("whittaker", half[:12], e=0.7, mu=0.1) for half in thirty)
    study = measured_study(small_set(train, test), ["whittaker"])
    row = study.table.set_index("law").loc["whittaker"]
    assert row["e"] == pytest.approx(0.7, abs=1e-4) and row["mu"] == pytest.approx(0.1, abs=1e-4)
    assert row["median_error"] < 1e-4


def test_a_frictionless_law_gets_a_row_that_names_its_refusal(thirty):
    train, test = (half[:5] for half in thirty)
    study = measured_study(small_set(train, test), ["newton"])
    row = study.table.set_index("law").loc["newton"]
    assert np.isnan(row["median_error"]) and row["refused"] == 5
    assert "newton" in row["reason"] and "friction" in row["reason"]


def test_predict_counts_a_refusal_and_never_raises():
    two = [i for i in MEASUREMENTS.get("cube").test if i.problem.m == 2][:1]
    velocities, failures = predict(LAWS.get("brach"), two, {"e": 0.5, "mu": 0.2}, {})
    assert isinstance(failures[0], NotApplicable) and np.isnan(velocities[0]).all()


def test_the_affine_baseline_recovers_an_affine_map(thirty):
    A = np.array([[0.9, 0.0, 0.01], [0.0, -0.5, 0.0], [2.0, 0.0, 0.3]])
    b = np.array([0.01, 0.02, -0.1])
    train, test = (
        [dataclasses.replace(i, v_after=A @ i.problem.v + b) for i in half] for half in thirty
    )
    basis = heldout.BASELINES["baseline: affine map"]
    theta = heldout.fit_baseline(basis, train)
    predicted = heldout.predict_baseline(basis, theta, test)
    assert heldout.errors(test, predicted).kinetic.max() < 1e-9


def test_the_error_is_relative_in_the_kinetic_metric(thirty):
    impact = thirty[1][0]
    error = heldout.errors([impact], impact.v_after[None, :] + impact.problem.v).kinetic[0]
    assert error == pytest.approx(1.0)


def test_the_median_and_its_interval_are_deterministic():
    errors = np.random.default_rng(1).lognormal(size=200)
    first, second = heldout.summary(errors), heldout.summary(errors)
    assert first == second and first["ci_low"] < first["median_error"] < first["ci_high"]
    assert np.isnan(heldout.summary(np.zeros(0))["median_error"])


def test_published_coefficients_are_read_from_the_facts():
    assert heldout.published(ELLIPSE.facts) == {
        "ICRA 2017": {"mu": 0.057, "e": 0.612},
        "CoRL 2017": {"mu": 0.120, "e": 0.537},
    }
    assert heldout.published({"normal_restitution": 0.98, "dem_friction": 0.092}) == {
        heldout.PUBLISHED_PAIR_NAME: {"e": 0.98, "mu": 0.092}
    }


def test_the_command_prints_the_ranked_table_and_writes_it(tmp_path, capsys):
    out = tmp_path / "kharaz.csv"
    code = main(["measurements", "kharaz", "--laws", "whittaker,newton", "--out", str(out)])
    assert code == 0
    printed = capsys.readouterr().out
    assert "ranked by median" in printed and "newton (fitted): 3 refused" in printed
    table = pd.read_csv(out)
    assert set(COLUMNS) <= set(table.columns) and {"e", "mu", "e_se", "mu_se"} <= set(table.columns)
    assert table["law"].tolist()[-1] == "newton"
    assert {"whittaker", *heldout.BASELINES} <= set(table["law"])


def test_the_command_refuses_a_bad_name_or_file(tmp_path, capsys):
    assert main(["measurements", "ellipse", "--laws", "nope"]) == 2
    assert "unknown law 'nope'" in capsys.readouterr().err
    assert main(["measurements", "nope", "--study"]) == 2
    assert main(["measurements", "--study"]) == 2
    assert main(["measurements", "kharaz", "--out", str(tmp_path / "t.txt")]) == 2
    assert ".csv or a .parquet" in capsys.readouterr().err


def test_the_command_writes_parquet_by_the_suffix(tmp_path, capsys):
    out = tmp_path / "kharaz.parquet"
    assert main(["measurements", "kharaz", "--laws", "whittaker", "--out", str(out)]) == 0
    table = pd.read_parquet(out)
    assert table["common_error"].is_monotonic_increasing and "whittaker" in set(table["law"])


def test_without_a_study_option_the_command_describes_the_set(capsys):
    assert main(["measurements", "kharaz"]) == 0
    out = capsys.readouterr().out
    assert "split:       3 to fit, 3 to judge" in out and "ranked" not in out


def test_rows_judged_on_different_impacts_are_ranked_on_those_all_solved():
    """A law that refused or failed some impacts, while judging (b) or before (d, offered
    only those it treats), is ranked with the others on the impacts every row solved; its
    median on all it judged stays beside."""
    table = pd.DataFrame(
        {
            "law": ["a", "b", "c", "d"],
            "coefficients": "fitted",
            "median_error": [0.1, 0.2, np.nan, 0.25],
            "refused": [0, 2, 4, 2],
        }
    )
    judged = pd.DataFrame(
        {
            "law": ["a"] * 4 + ["b"] * 4 + ["d"] * 2,
            "coefficients": "fitted",
            "index": [0, 1, 2, 3] * 2 + [1, 2],
            "status": ["ok", "ok", "ok", "failed", "refused", "ok", "ok", "refused", "ok", "ok"],
            "error": [0.1, 0.3, 0.3, np.nan, np.nan, 0.1, 0.2, np.nan, 0.2, 0.3],
        }
    )
    ordered, common = ranked(table, judged)
    assert common == 2 and ordered["law"].tolist() == ["b", "d", "a", "c"]
    assert ordered["common_error"].tolist()[:3] == pytest.approx([0.15, 0.25, 0.3])


def test_a_row_judged_on_a_subsample_follows_the_rows_judged_on_every_impact():
    """Two impacts of four, all it was given, decide no rank: the row judged on them follows
    the rows judged on all four, whatever its error there."""
    table = pd.DataFrame(
        {"law": ["a", "b"], "coefficients": "fitted", "median_error": [0.3, 0.1], "refused": 0}
    )
    judged = pd.DataFrame(
        {
            "law": ["a"] * 4 + ["b"] * 2,
            "coefficients": "fitted",
            "index": [0, 1, 2, 3, 1, 2],
            "status": "ok",
            "error": [0.3, 0.3, 0.3, 0.3, 0.1, 0.1],
        }
    )
    ordered, common = ranked(table, judged)
    assert common == 4 and ordered["law"].tolist() == ["a", "b"]
    assert np.isnan(ordered["common_error"].iloc[1])


@pytest.mark.slow
def test_laws_studied_side_by_side_give_the_same_table():
    """Two worker processes give the table one process gives, timings aside (Kharaz's set)."""
    laws = ["whittaker", "brach"]
    one = measured_study("kharaz", laws, quick=True, workers=1).table
    two = measured_study("kharaz", laws, quick=True, workers=2).table
    timings = ["cost_s", "wall_s"]
    pd.testing.assert_frame_equal(one.drop(columns=timings), two.drop(columns=timings))


def test_a_study_needs_a_worker():
    """Fewer than one worker is refused by name."""
    with pytest.raises(InvalidProblem, match="workers = 0"):
        measured_study("kharaz", ["whittaker"], workers=0)


def _cube_one_corner_tosses() -> list:
    return [i for i in MEASUREMENTS.get("cube").impacts if i.problem.m == 1][:12]


@pytest.mark.parametrize(
    ("engine", "impacts", "coefficients"),
    [
        ("pybullet", _cube_one_corner_tosses, {"e": 0.4, "mu": 0.3}),
        ("mujoco", lambda: evenly(ELLIPSE.impacts, 12), {"e": 0.6, "mu": 0.1}),
    ],
)
def test_an_engine_is_fitted_through_the_set_s_geometry(engine, impacts, coefficients):
    """The cube tosses and the ellipse bounces carry their geometry, so an engine is fitted and
    judged like a law, the pairs taking each trial's coefficients (an engine refuses a problem
    whose coefficients are not its geometry's). A set an engine makes at its tuned settings is
    fitted back to the coefficients it was made with: PyBullet's one-corner cube impacts at
    e = 0.4 and mu = 0.3, and MuJoCo's ellipse bounces at e = 0.6 and mu = 0.1 (the ellipse slips
    through most of them)."""
    pytest.importorskip(engine)
    law = LAWS.get(engine)
    chosen = impacts()
    velocities, failures = predict(law, chosen, coefficients, study_options(law))
    assert not failures
    made = [dataclasses.replace(i, v_after=v) for i, v in zip(chosen, velocities, strict=True)]
    study = measured_study(small_set(made[:6], made[6:]), [engine])
    row = study.table.set_index("law").loc[engine]
    for name, value in coefficients.items():
        assert row[name] == pytest.approx(value, abs=1e-3)
    assert row["median_error"] < 1e-3 and row["refused"] == 0
