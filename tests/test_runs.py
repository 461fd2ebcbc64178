"""Run specifications, the executor and its guard, records, transforms, chunks and resuming."""

import functools
import math
import os
import time

import numpy as np
import pandas as pd
import pytest

import lawbench
from lawbench.core.transforms import apply, parse, spell
from lawbench.studies.grid import RunSpec, values
from lawbench.studies.guard import Guard
from lawbench.studies.record import budget_text
from lawbench.studies.runfile import untidy
from lawbench.studies.runner import Executor, Task, compute, run, run_many
from lawbench.studies.study import Job, Plan

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


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b'[[grid]]\nlaws = ["n\xe9wton"]\n', "TOML is UTF-8 text"),
        (b"a = " + b"[" * 100_000 + b"]" * 100_000, "nested deeper"),
    ],
    ids=["latin-1", "deep"],
)
def test_a_spec_that_is_not_utf8_or_nests_without_end_is_refused(tmp_path, content, message):
    path = tmp_path / "spec.toml"
    path.write_bytes(content)
    with pytest.raises(lawbench.InvalidProblem, match=message):
        RunSpec.from_toml(path)


def without_time(table):
    return table.drop(columns=["wall_time_s", "spent_s"]).reset_index(drop=True)


def test_serial_processes_and_dask_give_the_same_table(tmp_path):
    spec = RunSpec.from_dict(SPEC)
    plan = spec.plan()
    tables = {
        executor: run(plan, tmp_path / f"{executor}.parquet", executor=executor, workers=2)[0]
        for executor in ("serial", "processes", "dask")
    }
    assert len(tables["serial"]) == len(spec.rows())
    pd.testing.assert_frame_equal(without_time(tables["serial"]), without_time(tables["processes"]))
    pd.testing.assert_frame_equal(without_time(tables["serial"]), without_time(tables["dask"]))
    stored = lawbench.load_run(tmp_path / "serial.parquet")
    records = untidy(stored, stored.attrs["lawbench"])
    pd.testing.assert_frame_equal(without_time(records), without_time(tables["serial"]))


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
    table, computed = run(spec.plan(), tmp_path / "out.csv")
    assert computed == 2
    assert list(table["error_class"].fillna("")) == ["BudgetExceeded", ""]
    assert list(table["verdict"]) == ["budget", "holds"]
    assert "step budget ran out (5 binary impacts" in table["error_message"][0]


def test_resume_computes_only_what_is_missing(tmp_path, monkeypatch):
    """A run interrupted after 7 cells keeps them; resuming the same grid computes the rest
    and gives the table of an uninterrupted run."""
    spec = RunSpec.from_dict(SPEC)
    out = tmp_path / "out.parquet"
    full, _ = run(spec.plan(), tmp_path / "reference.parquet")
    whole = Executor.run

    def interrupted(self, tasks):
        for done, item in enumerate(whole(self, tasks)):
            if done == 7:
                raise KeyboardInterrupt
            yield item

    monkeypatch.setattr(Executor, "run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run(spec.plan(), out, chunk_size=3)
    monkeypatch.setattr(Executor, "run", whole)
    with pytest.raises(lawbench.InvalidProblem, match="--resume"):
        run(spec.plan(), out)
    table, computed = run(spec.plan(), out, resume=True)
    assert computed == len(spec.rows()) - 7
    pd.testing.assert_frame_equal(without_time(table), without_time(full))


def test_a_resume_with_another_grid_is_refused_naming_both(tmp_path):
    """The chunks and the finished table keep their grid's fingerprint: resuming with another
    grid (which would mix two grids' cells and never finish either) stops before any work."""
    spec = RunSpec.from_dict(SPEC)
    partial = RunSpec.from_dict({**SPEC, "grid": SPEC["grid"][:1]})
    out = tmp_path / "out.parquet"
    run(partial.plan(), out)
    cells = len(partial.rows())
    with pytest.raises(
        lawbench.InvalidProblem,
        match=rf"another grid \({cells} cells.*this run's grid is {len(spec.rows())} cells",
    ):
        run(spec.plan(), out, resume=True)
    table, computed = run(partial.plan(), out, resume=True)
    assert computed == 0 and len(table) == cells


def test_a_grid_without_a_cell_writes_nothing_and_says_so(tmp_path):
    with pytest.raises(lawbench.InvalidProblem, match="the grid has no cell"):
        run(Plan("empty", []), tmp_path / "out.csv")
    assert not any(tmp_path.iterdir())


def test_an_output_that_cannot_be_written_is_not_called_locked(tmp_path):
    """A folder that cannot be made is named as such, not as a lock another run holds."""
    (tmp_path / "file").write_text("")
    with pytest.raises(lawbench.InvalidProblem, match=r"cannot be written.*Not a directory"):
        run(RunSpec.from_dict(SPEC).plan(), tmp_path / "file" / "out.csv")


# The per-job guard, in every executor.

SLOW = Job("lzb", "ball_chain", {"n": 100, "e": [0.0]})


def test_the_guard_returns_answers_and_errors_and_stops_a_task_over_its_budget():
    with Guard(workers=1, budget_s=30.0) as guard:
        slow = guard.submit(time.sleep, 60, budget=2.0)
        failing = guard.submit(math.sqrt, -1.0)
        fine = guard.submit(math.sqrt, 4.0)
        start = time.monotonic()
        assert guard.result(slow).status == "time-out"
        assert time.monotonic() - start < 20
        error = guard.result(failing)
        assert (error.status, error.error_class) == ("error", "ValueError")
        assert guard.result(fine).value == 2.0


def test_a_task_that_ends_its_worker_is_an_error_naming_the_exit_code():
    """A law that calls os._exit ends only its worker; the guard says how it ended."""
    with Guard(workers=1, budget_s=30.0) as guard:
        ended = guard.result(guard.submit(os._exit, 3))
        fine = guard.result(guard.submit(math.sqrt, 4.0))
    assert (ended.status, ended.error_class, ended.error_message) == (
        "error",
        "WorkerDied",
        "exit code 3",
    )
    assert fine.value == 2.0


def _loaded_slowly(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


class SlowToLoad:
    """An argument whose unpickling in the worker takes ``seconds`` (an import, say)."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds

    def __reduce__(self):
        return _loaded_slowly, (self.seconds,)


def test_a_task_is_timed_from_when_its_worker_begins_it():
    """A worker's start-up and the imports its task needs are not the task's seconds."""
    with Guard(workers=1, budget_s=30.0) as guard:
        result = guard.result(guard.submit(abs, SlowToLoad(3.0), budget=1.0))
    assert (result.status, result.value) == ("ok", 3.0)


def test_what_a_task_needs_done_once_in_its_process_is_not_its_seconds():
    """A law's preparation (compiling kernels) runs in the worker before the task is timed."""
    with Guard(workers=1, budget_s=30.0) as guard:
        done = guard.submit(abs, -2.0, budget=1.0, before=functools.partial(time.sleep, 3.0))
        result = guard.result(done)
    assert (result.status, result.value) == ("ok", 2.0)
    assert result.seconds < 1.0


@pytest.mark.parametrize("executor", ["serial", "processes"])
def test_a_cell_stopped_by_the_guard_is_a_budget_cell_naming_it(tmp_path, executor):
    plan = Plan("slow", [SLOW, Job("newton", "ball_chain")])
    start = time.monotonic()
    table, _ = run(plan, tmp_path / "slow.csv", executor, budget_s=2.0)
    assert time.monotonic() - start < 30
    stopped, answered = table.to_dict("records")
    assert stopped["verdict"] == "budget" and answered["verdict"] == "holds"
    assert (stopped["budget"], stopped["budget_amount"]) == ("wall-clock guard", 2.0)
    assert stopped["exit_status"] == 4
    assert stopped["reproducer"].endswith("--max-seconds 2")
    assert budget_text(stopped).startswith("budget wall-clock guard = 2 s, after ")


# Records: fixed fields for every cell.


def test_every_record_has_the_same_fields_whatever_happened():
    cells = [
        Job("newton", "three_ball_chain"),  # answered
        Job("brach", "three_ball_chain"),  # refused
        Job("sequential", "two_balls_wall", {"e": [0.0]}, {"max_steps": 5}),  # budget
        Job("newton", "three_ball_chain", {"e": [2.0]}),  # invalid input
    ]
    rows = [compute(Task(k, job, "", ("energy_gain",))) for k, job in enumerate(cells)]
    fields = set(rows[0]) - {"energy_gain_value", "energy_gain_verdict"}
    fields -= {"energy_gain_finding", "energy_gain_detail"}
    for row in rows:
        assert fields <= set(row)
    assert [r["verdict"] for r in rows] == ["holds", "refused", "budget", "unexplained"]
    assert [r["exit_status"] for r in rows] == [0, 3, 4, 2]
    assert rows[2]["budget"] == "max_steps" and rows[2]["budget_amount"] == 5
    assert rows[2]["spent_s"] >= 0
    assert rows[0]["energy_gain_verdict"] == "holds"


def test_a_cell_verdict_is_the_worst_of_its_checks():
    separating = Job("newton", "three_ball_chain", {"velocities": [1.0, 0.0, 0.75]})
    row = compute(Task(0, separating, "", ("energy_gain", "admissible", "friction_cone")))
    assert row["admissible_verdict"] == "law property"
    assert row["friction_cone_verdict"] == "refused"
    assert row["verdict"] == "law property"
    finding = lawbench.LAWS.get("newton").findings[row["admissible_finding"]]
    assert finding.check == "admissible"


# Transforms of the built problem.


@pytest.mark.parametrize("case", ["three_ball_chain", "falling_rod", "sphere_wall"])
def test_grazing_scales_every_gap_rate_and_keeps_what_the_contacts_do_not_see(case):
    problem = lawbench.CASES.get(case).build()
    made = apply("grazing=1e-09", problem)
    fastest = -problem.un.min()
    # Gap rates at rest stay at rest up to the rounding of the velocities they subtract.
    rounding = 1e-15 * np.abs(problem.v).max()
    np.testing.assert_allclose(made.un, problem.un * 1e-9 / fastest, rtol=1e-6, atol=rounding)
    # The change is M^-1 Wn x: invisible to every w with Wn.T w = 0 in the kinetic metric.
    _, _, vt = np.linalg.svd(problem.Wn.T)
    hidden = vt[problem.m :]
    np.testing.assert_allclose(hidden @ problem.M @ made.v, hidden @ problem.M @ problem.v)


@pytest.mark.parametrize("law", ["newton", "moreau", "poisson"])
def test_a_contact_given_twice_changes_no_outcome(law):
    """The same constraint twice is the same set of admissible velocities.

    Moreau's law projects on the tangent cone (Brogliato 2010, eqs. 16-17), Newton's solves
    ``Wn.T v+ = -e Wn.T v-``, Poisson's two complementarity problems: none of these sets
    changes when a column of Wn is repeated, so the post-impact velocity stays.
    """
    problem = lawbench.CASES.get("three_ball_chain").build(e=[0.5])
    twice = apply("duplicated", problem)
    assert twice.m == problem.m + 1
    solver = lawbench.LAWS.get(law)
    once, again = solver.resolve(problem), solver.resolve(twice)
    np.testing.assert_allclose(again.v_plus, once.v_plus, atol=1e-9)
    np.testing.assert_allclose(again.Pn[0] + again.Pn[-1], once.Pn[0], atol=1e-9)


@pytest.mark.parametrize(
    ("spelling", "message"),
    [("spin=2", "unknown transform 'spin'"), ("grazing", "give a value"), ("grazing=x", "x")],
)
def test_a_bad_transform_is_refused(spelling, message):
    with pytest.raises(lawbench.InvalidProblem, match=message):
        parse(spelling)


def test_a_transformed_cell_spells_its_transform_exactly():
    job = Job("newton", "three_ball_chain", {"e": [1.0]}, transform=spell("grazing", 1e-8 / 3))
    assert parse(job.transform)[1] == 1e-8 / 3
    assert job.command() == (
        f"lawbench solve newton three_ball_chain --set e=1.0 --transform grazing={1e-8 / 3!r}"
    )
    assert job.key != Job("newton", "three_ball_chain", {"e": [1.0]}).key


def test_a_grid_can_transform_its_rows():
    grid = {"laws": ["newton"], "cases": ["three_ball_chain"], "transforms": ["duplicated"]}
    spec = RunSpec.from_dict({"grid": [grid]})
    (job,) = spec.rows()
    assert job.transform == "duplicated"
    assert compute(Task(0, job, "", ("momentum",)))["momentum_verdict"] == "holds"


@pytest.mark.parametrize("executor", ["processes", "dask"])
def test_several_plans_through_one_pool_keep_their_cells_apart(tmp_path, executor):
    """Every plan's cells are numbered from 0: the pool must not mix them up."""
    plans = [
        Plan("one", [Job("newton", "three_ball_chain", {"e": [e]}) for e in (0.0, 0.5, 1.0)]),
        Plan("two", [Job("poisson", "two_balls_wall", {"e": [e]}) for e in (0.2, 0.4)]),
    ]
    outs = [(plan, tmp_path / f"{plan.name}.parquet") for plan in plans]
    with Executor(executor, workers=2, chunk_size=2) as pool:
        results = run_many(outs, pool)
    for plan, (table, computed) in zip(plans, results, strict=True):
        assert computed == len(plan.jobs)
        assert list(table["study"]) == [plan.name] * len(plan.jobs)
        assert list(table["key"]) == [job.key for job in plan.jobs]
