"""Studies declared beside their scenes and laws, and ``lawbench study`` (alias ``table``)."""

from __future__ import annotations

import ast
import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import lawbench
from lawbench.cases.rocking_block import housner_ratio
from lawbench.core.verdicts import Verdict
from lawbench.studies.declared import STUDIES
from lawbench.studies.study import Study
from lawbench.studies.tables import Table, study_table


@pytest.fixture(scope="module")
def rocking():
    return study_table("rocking_block")


@pytest.fixture(scope="module")
def sphere():
    return study_table("sphere_wall")


def lawbench_command(*args):
    return subprocess.run(
        [sys.executable, "-m", "lawbench", *args],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_every_declared_study_expands_into_valid_cells():
    """Every study's grid is checked against its scenes and laws (an error names the study)."""
    names = STUDIES.names()
    assert {"rocking_block", "sphere_wall", "dispersion", "summary"} <= set(names)
    for study in STUDIES.values():
        for mode in ("quick", "full"):
            jobs = list(study.preset(mode).jobs())
            assert jobs, study.name
            assert len({job.key for job in jobs}) == len(jobs), study.name


def test_study_cells_are_deterministic():
    study = STUDIES.get("three_ball_chain_grazing")
    assert list(study.jobs()) == list(study.jobs())


def test_rocking_block_table_has_every_law_at_five_aspect_ratios(rocking):
    frame = rocking.frame
    assert list(frame.columns) == [
        "law",
        "mu",
        "width",
        "omega_ratio",
        "housner",
        "difference",
        "verdict",
    ]
    assert not frame.isna().any().any()
    assert set(frame["mu"]) == {0.0, 1.0}
    for (_, _), group in frame.groupby(["law", "mu"]):
        np.testing.assert_allclose(group["width"], np.logspace(-1, 1, 5))
    present = set(frame["law"])
    for law in lawbench.LAWS.names():
        assert law in present or any(note.startswith(f"{law}: refused") for note in rocking.notes)
    np.testing.assert_allclose(frame["housner"], [housner_ratio(w, 1.0) for w in frame["width"]])


def test_every_cell_has_a_verdict_of_the_taxonomy(rocking):
    assert len(rocking.data) == 2 * 5 * len(lawbench.LAWS.names())
    assert set(rocking.data["verdict"]) <= {str(v) for v in Verdict}


def test_a_law_that_cannot_treat_two_contacts_is_refused_with_the_reason(rocking):
    note = next(n for n in rocking.notes if n.startswith("brach:"))
    assert "refused on 10 of 10 cells" in note and "2 closed contacts" in note
    assert "brach" not in set(rocking.frame["law"])


def test_sticking_laws_reproduce_housner_where_it_holds(rocking):
    """Housner 1963: e = 0, mu = 1 sticks; the pivot lifts off while width <= sqrt(2) height."""
    frame = rocking.frame
    rows = frame[(frame["mu"] == 1.0) & (frame["width"] <= math.sqrt(2))]
    for law in {"moreau", "whittaker"} & set(rows["law"]):
        np.testing.assert_allclose(rows[rows["law"] == law]["difference"], 0.0, atol=1e-9)


def test_sphere_table_has_the_three_laws(sphere):
    frame = sphere.frame
    assert list(frame.columns) == [
        "law",
        "angle",
        "ut_minus",
        "ut_plus",
        "spin_plus",
        "impulse_ratio",
        "verdict",
    ]
    assert not frame.isna().any().any()
    assert list(dict.fromkeys(frame["law"])) == ["brach", "whittaker", "darboux_keller"]
    for _, rows in frame.groupby("law"):
        np.testing.assert_allclose(rows["angle"], np.linspace(5, 85, 9))


def test_sphere_table_brach_rows_follow_equation_11(sphere):
    """Eq. (11), spinless sphere: ut+ = -e_t ut- below tan(a) = 7 mu (1 + e) / (2 (1 + e_t)),
    impulse ratio mu above; the contact point velocity is vt - radius spin (rolling: equal)."""
    params = lawbench.CASES.get("sphere_wall").parameters()
    e, e_t, mu, radius = params["e"], params["e_t"], params["mu"], params["radius"]
    critical = math.degrees(math.atan(3.5 * mu * (1 + e) / (1 + e_t)))
    rows = sphere.frame[sphere.frame["law"] == "brach"]
    for row in rows.itertuples():
        if row.angle < critical:
            assert row.ut_plus == pytest.approx(-e_t * row.ut_minus, abs=1e-12)
            assert row.impulse_ratio < mu
        else:
            assert row.impulse_ratio == pytest.approx(mu, rel=1e-12)
        vt = params["speed"] * math.sin(math.radians(row.angle))
        normal = (1 + e) * params["speed"] * math.cos(math.radians(row.angle))
        centre = row.ut_plus + radius * row.spin_plus  # tangential velocity of the centre
        assert centre == pytest.approx(vt - row.impulse_ratio * normal)


def test_a_mapping_measure_is_spread_over_one_column_per_key():
    table = study_table("dispersion", {"stiffness_ratio": "1"})
    frame = table.frame
    shares = ["energy_shares[ball 1]", "energy_shares[ball 2]", "energy_shares[ball 3]"]
    assert [*shares, "dispersion_index", "verdict"] == list(frame.columns[-5:])
    np.testing.assert_allclose(frame[shares].sum(axis=1), 1.0)
    sequential = frame[frame["law"] == "sequential"].iloc[0]
    assert sequential["energy_shares[ball 3]"] == pytest.approx(1.0)


def test_failed_cells_are_notes_once_per_law_and_reason():
    study = Study(
        "budgets",
        "sequential with a tiny impact budget",
        cases=("two_balls_wall",),
        laws=("sequential",),
        grid={"e": [[0.0], [0.5], [0.0, 0.5]]},
        options={"sequential": {"max_steps": [5]}},
    )
    from lawbench.studies.runner import Executor, collect

    with Executor() as pool:
        table = Table(study, collect(study.plan(), pool))
    assert list(table.data["verdict"]) == ["budget", "holds", "budget"]
    (note,) = table.notes
    assert note.startswith("sequential: budget on 2 of 3 cells, first: `lawbench solve ")
    assert "(budget max_steps = 5, after " in note
    assert len(table.frame) == 1


def test_an_unknown_study_or_parameter_is_refused():
    with pytest.raises(lawbench.InvalidProblem, match="unknown study 'nope'"):
        study_table("nope")
    with pytest.raises(lawbench.InvalidProblem, match="--set colour: no scene"):
        study_table("sphere_wall", {"colour": "red"})


def test_the_command_writes_the_table_and_prints_the_view(tmp_path):
    out = tmp_path / "sub" / "sphere.csv"
    result = lawbench_command("study", "sphere_wall", "--set", "angle=30", "--out", str(out))
    assert result.returncode == 0, result.stderr
    written = lawbench.load_run(out)
    assert len(written) == 3 and set(written["verdict"]) == {"holds"}
    assert {"reproducer", "exit_status", "ut_plus", "energy_gain_verdict"} <= set(written)
    assert "impulse_ratio" in result.stdout and str(out) in result.stdout
    again = lawbench_command(*written["reproducer"][0].split()[1:], "--json")
    assert again.returncode == int(written["exit_status"][0])


@pytest.mark.parametrize("suffix", [".parquet", ".csv", ".feather"])
def test_a_study_is_written_in_the_tidy_format_of_a_run(tmp_path, suffix):
    """One writer for runs and studies: typed parameter columns, list columns for the vectors
    (and the vector parameter ``spin``), categorical verdicts, the study in the metadata."""
    from lawbench.views.cli import main

    out = tmp_path / f"sphere{suffix}"
    assert main(["study", "sphere_wall", "--set", "angle=30", "--out", str(out)]) == 0
    table = lawbench.load_run(out)
    assert table["angle"].dtype == float and list(table["angle"]) == [30.0] * 3
    assert all(len(v) == 3 for v in table["spin"])
    assert all(len(v) == 6 for v in table["v_plus"]) and all(len(v) == 1 for v in table["Pn"])
    assert isinstance(table["verdict"].dtype, pd.CategoricalDtype)
    assert list(table["verdict"].cat.categories) == [str(v) for v in Verdict]
    assert table.attrs["lawbench"]["study"] == "sphere_wall"
    assert table.attrs["lawbench"]["set"] == {"angle": "30"}
    assert "numpy" in table.attrs["lawbench"]["versions"]
    if suffix == ".csv":
        assert {"v_plus_0", "v_plus_5", "Pn_0"} <= set(pd.read_csv(out).columns)


def test_a_study_refuses_an_unknown_extension_before_any_work(tmp_path, capsys, monkeypatch):
    from lawbench.studies import tables
    from lawbench.views import cli

    monkeypatch.setattr(tables, "study_table", lambda *a, **k: pytest.fail("the study ran"))
    out = tmp_path / "sphere.txt"
    assert cli.main(["study", "sphere_wall", "--out", str(out)]) == 2
    assert "unknown extension '.txt'" in capsys.readouterr().err
    assert not out.exists()


def test_table_is_study_and_list_names_every_study():
    listed = lawbench_command("study", "--list")
    assert listed.returncode == 0, listed.stderr
    for name in STUDIES.names():
        assert f"  {name} " in listed.stdout, name
    result = lawbench_command("table", "nope")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "unknown study 'nope'" in result.stderr


def test_the_engine_names_no_law_or_scene():
    """Every module of lawbench/ (core, numerics, files, checks, studies, views) learns laws
    and scenes from the registries and from the data declared with them; a name may appear in
    a docstring only."""
    root = Path(lawbench.__file__).parent
    names = set(lawbench.LAWS.names()) | set(lawbench.CASES.names())
    paths = sorted(root.rglob("*.py"))
    hits = []
    for path in paths:
        tree = ast.parse(path.read_text())
        docs = {
            id(node.body[0].value)
            for node in ast.walk(tree)
            if isinstance(getattr(node, "body", None), list)
            and node.body
            and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)
        }
        hits += [
            f"{path.relative_to(root)}:{node.lineno} {node.value!r}"
            for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and node.value in names and id(node) not in docs
        ]
    assert not hits


def test_a_sweep_draws_each_measure_against_its_axis_per_law():
    """The billiard sweep: one row per answered cell with the elevation and every numeric
    measure (the spin vector expanded), one panel per measure, one line per law (here the
    cone projection's alone, the cheapest that treats two spatial frictional contacts)."""
    from lawbench.studies.runner import Executor, collect
    from lawbench.views.report import sweeps

    study = STUDIES.get("billiard")
    with Executor() as pool:
        table = collect(study.plan(laws=["moreau"]), pool)
    frame = sweeps._tidy(table, "elevation", list(study.measures), [])
    assert set(frame["law"]) == {"moreau"}
    assert sorted(frame["elevation"]) == list(study.grid["elevation"])
    assert {"ball_speed", "spin[wx]", "spin[wz]", "spin_tilt"} <= set(frame.columns)
    units = {**study.units, "elevation": "deg"}
    figure = sweeps._figure("billiard", study.title, frame, "elevation", units)
    shown = [ax for ax in figure.figure.axes if ax.get_visible()]
    # Each component is named as the captions name it; a component that is zero is drawn as 0.
    velocity = [f"velocity[{k}]" for k in ("vx", "vy", "vz")]
    spin = [f"spin[{k}]" for k in ("wx", "wy", "wz")]
    titles = [*velocity, "ball_speed", *spin, "spin_tilt", "curvature"]
    assert [ax.get_title() for ax in shown] == titles
    assert {ax.get_xlabel() for ax in shown} == {"elevation [deg]"}
    ylabels = [ax.get_ylabel() for ax in shown]
    assert ylabels[:4] == [f"{c} [m/s]" for c in [*velocity, "ball_speed"]]
    assert ylabels[4:] == [f"{c} [rad/s]" for c in spin] + ["spin_tilt [deg]", "curvature [1/m]"]
    for ax in shown:
        for line in ax.get_lines():
            values = np.abs(line.get_ydata())
            assert not ((values > 0) & (values < 1e-12 * max(values.max(), 1e-300))).any()


def test_every_sweep_states_the_unit_of_what_it_draws():
    """Each panel of a sweep holds one quantity with its unit: the study declares a unit for
    every measure it draws, and its abscissa is a scene parameter with a unit."""
    for study in STUDIES.values():
        if study.shape != "sweep":
            continue
        drawn = list(study.axes[1:]) or list(study.measures)
        assert set(drawn) <= set(study.units), study.name
        case = lawbench.CASES.get(study.case_names()[0])
        assert study.axes[0] in {spec.name for spec in case.params}, study.name


def test_a_sweep_over_decades_draws_a_log_abscissa():
    """ping_pong over k2/k1 from 1/10 to 10: a log abscissa, dimensionless rebound ratios."""
    from lawbench.studies.runner import Executor, collect
    from lawbench.views.report import sweeps

    study = STUDIES.get("ping_pong").with_params({}).preset("quick")
    study = dataclasses.replace(study, laws=("sequential",))
    with Executor() as pool:
        table = collect(study.plan(), pool)
    frame = sweeps._tidy(table, "stiffness_ratio", list(study.measures), [])
    units = {**study.units, "stiffness_ratio": ""}
    figure = sweeps._figure("ping_pong", study.title, frame, "stiffness_ratio", units)
    shown = [ax for ax in figure.figure.axes if ax.get_visible()]
    assert {ax.get_xscale() for ax in shown} == {"log"}
    assert [ax.get_ylabel() for ax in shown] == ["v1_over_v0 [-]", "v2_over_v0 [-]"]


def test_laws_with_the_same_answers_are_drawn_as_one_line_named_after_them_all():
    """moreau and newton give the same answers along the axis: one line, 'moreau = newton',
    never one hidden under the other; lzb differs by more than 1e-9 and keeps its own."""
    import matplotlib.pyplot as plt

    from lawbench.views.report import sweeps

    axis = [0.1, 1.0, 10.0]
    frame = pd.DataFrame(
        {
            "law": ["moreau"] * 3 + ["newton"] * 3 + ["lzb"] * 3,
            "e": axis * 3,
            "v": [1.0, 2.0, 3.0, 1.0, 2.0, 3.0, 1.0, 2.0, 3.0 + 1e-6],
            "verdict": "holds",
        }
    )
    assert sweeps.coinciding(frame, "e", ["v"]) == {"lzb": ["lzb"], "moreau": ["moreau", "newton"]}
    figure = sweeps._figure("demo", "demo", frame, "e")
    labels = [line.get_label() for line in figure.figure.axes[0].get_lines()]
    assert sorted(labels) == ["lzb", "moreau = newton"]
    plt.close(figure.figure)


def test_a_study_whose_every_cell_ran_out_of_time_prints_its_notes(capsys):
    """No cell answered, so no measure column exists: the table says so and the notes say why
    (it raised a KeyError on the first missing measure)."""
    from lawbench.views import cli

    argv = ["study", "rocking_block", "--set", "mu=0", "--max-seconds", "0.0001"]
    assert cli.main(argv) == 0
    out = capsys.readouterr().out
    assert "(no cell gave an answer)" in out and "budget on" in out
