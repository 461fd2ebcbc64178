"""Run specifications, executors, chunked results and resuming."""

import numpy as np
import pandas as pd
import pytest

import lawbench
from lawbench.grid import RunSpec, values
from lawbench.runner import run

SPEC = {
    "seed": 3,
    "grid": [
        {
            "laws": ["newton", "moreau", "sequential"],
            "cases": ["three_ball_chain"],
            "params": {
                "e": {"range": [0, 1, 3]},
                "masses": {"random": [0.1, 10, 2], "log": True, "size": 3},
            },
            "options": {"sequential": {"order": ["left_to_right", "right_to_left"]}},
        },
        {"laws": ["*"], "cases": ["two_balls_wall"], "params": {"velocities": [[-2.0, -1.0]]}},
    ],
}


def test_the_same_spec_gives_the_same_rows_in_the_same_order():
    first, second = RunSpec.from_dict(SPEC).rows(), RunSpec.from_dict(SPEC).rows()
    assert [(r.law, r.params, r.options) for r in first] == [
        (r.law, r.params, r.options) for r in second
    ]
    assert len({r.key for r in first}) == len(first)
    # 3 e x 2 mass draws for newton and moreau, twice that for sequential's two orders.
    assert sum(r.case == "three_ball_chain" for r in first) == 3 * 2 * (1 + 1 + 2)
    masses = first[0].params["masses"]
    assert len(masses) == 3 and all(0.1 <= m <= 10 for m in masses)


def test_value_generators():
    assert values([1, 2], 0, ("x",)) == [1, 2]
    assert values(5, 0, ("x",)) == [5]
    np.testing.assert_allclose(values({"logrange": [-2, 2, 5]}, 0, ("x",)), np.logspace(-2, 2, 5))
    draws = values({"random": [0, 1, 4]}, 7, ("x",))
    assert draws == values({"random": [0, 1, 4]}, 7, ("x",))
    assert draws != values({"random": [0, 1, 4]}, 8, ("x",))


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ({"grid": [{"laws": ["nope"]}]}, "unknown law 'nope'"),
        ({"grid": [{"cases": ["three_ball_chain"], "params": {"e": [2.0]}}]}, r"e\[0\] = 2"),
        ({"grid": [{"cases": ["three_ball_chain"], "params": {"colour": [1]}}]}, "colour"),
        ({"grid": [{"speed": 1}]}, "unknown key 'speed'"),
        ({}, "no \\[\\[grid\\]\\]"),
        ({"grid": [{}], "checks": ["vibes"]}, "unknown check 'vibes'"),
        ({"grid": [{"params": {"e": {"spiral": 1}}}]}, "unknown value generator"),
    ],
)
def test_bad_specs_stop_before_any_work(spec, message):
    with pytest.raises(lawbench.InvalidProblem, match=message):
        RunSpec.from_dict(spec).rows()


def test_malformed_toml_is_refused(tmp_path):
    path = tmp_path / "spec.toml"
    path.write_text("[[grid]\nlaws = [")
    with pytest.raises(lawbench.InvalidProblem, match="malformed TOML"):
        RunSpec.from_toml(path)


def without_time(table):
    return table.drop(columns="wall_time_s").reset_index(drop=True)


def test_serial_processes_and_dask_give_the_same_table(tmp_path):
    spec = RunSpec.from_dict(SPEC)
    tables = {
        executor: run(spec, tmp_path / f"{executor}.parquet", executor=executor, workers=2)[0]
        for executor in ("serial", "processes", "dask")
    }
    assert len(tables["serial"]) == len(spec.rows())
    pd.testing.assert_frame_equal(without_time(tables["serial"]), without_time(tables["processes"]))
    pd.testing.assert_frame_equal(without_time(tables["serial"]), without_time(tables["dask"]))
    stored = pd.read_parquet(tmp_path / "serial.parquet")
    pd.testing.assert_frame_equal(without_time(stored), without_time(tables["serial"]))


def test_a_failing_row_is_recorded_and_the_run_goes_on(tmp_path):
    spec = RunSpec.from_dict(
        {
            "grid": [
                {
                    "laws": ["sequential"],
                    "cases": ["two_balls_wall"],
                    "params": {"e": [0.0, 0.5]},
                    "options": {"sequential": {"max_steps": [5]}},
                }
            ]
        }
    )
    table, computed = run(spec, tmp_path / "out.csv", file_format="csv")
    assert computed == 2
    assert list(table["error_class"].fillna("")) == ["BudgetExceeded", ""]
    assert list(table["verdict"]) == ["budget", "holds"]
    assert "after 5 binary impacts" in table["error_message"][0]


def test_resume_computes_only_what_is_missing(tmp_path):
    spec = RunSpec.from_dict(SPEC)
    out = tmp_path / "out.parquet"
    full, _ = run(spec, tmp_path / "reference.parquet")
    partial = RunSpec.from_dict({**SPEC, "grid": SPEC["grid"][:1]})
    run(partial, out, chunk_size=7)
    with pytest.raises(lawbench.InvalidProblem, match="--resume"):
        run(spec, out)
    table, computed = run(spec, out, resume=True)
    assert computed == len(spec.rows()) - len(partial.rows())
    pd.testing.assert_frame_equal(without_time(table), without_time(full))
