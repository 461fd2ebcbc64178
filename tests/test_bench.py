"""The benchmark command prints its figures (a smoke test: no time is asserted)."""

import ast
import os
import sys

import numpy as np
import pytest

from lawbench.bench import report, start_up_command, subject, subjects
from lawbench.bench.impacts import engine_impacts
from lawbench.bench.peer import (
    PEER_SCRIPT,
    ask,
    candidates,
    siconos_available,
    siconos_nsgs,
    siconos_python,
    timed_by,
)
from lawbench.core.case import CASES
from lawbench.core.contact import ContactProblem
from lawbench.core.errors import InvalidProblem, SolverFailure
from lawbench.core.law import LAWS


# A benchmark run end to end (about 13 s): a study of cost, not of correctness.
@pytest.mark.slow
def test_the_benchmark_prints_every_figure_with_its_peer():
    text = report(quick=True)
    assert text.startswith("lawbench bench on ")
    lines = (
        "one three-ball",
        "a batch of",
        "frictional impacts",
        "n-ball chain",
        "bytecode cached",
    )
    for line in (*lines, "from its parameters", "engines on "):
        assert line in text
    integrating = [
        law.name for law in LAWS.values() if any(s.name == "max_events" for s in law.options)
    ]
    assert {"compliant", "jia", "lzb"} <= set(integrating)
    for law in integrating:
        assert f"{law}: time grows like n^" in text
    assert text.count("energy error") == 2 * len(integrating)
    assert "x clarabel direct" in text and "x numpy enumeration" in text
    # `bench --problems` asks the same function whether Siconos is there.
    assert ("x Siconos Lemke" in text) == siconos_available()


def test_the_bench_prints_each_engine_s_cost_per_impact_at_each_setting():
    """One timed solve each (about 2 s): a line per engine, setting and scene, with its ratio to
    the rigid law's solve of the same problem."""
    engines = [law for law in LAWS.values() if law.engine]
    if not engines:
        pytest.skip("no engine installed")
    lines = engine_impacts(1)
    peer = subject(LAWS, "lcp")
    scenes = subjects(CASES, "engine_cost")
    assert {"three_ball_chain", "rocking_block"} <= set(scenes)
    for scene in scenes:
        start = lines.index(f"engines on {scene} (median cost per impact; timed solves each: 1):")
        block = lines[start + 1 : start + 1 + 2 * len(engines)]
        labels = {line.split()[0] + " " + line.split()[1] for line in block}
        assert labels == {f"{law.name} {s}" for law in engines for s in ("default", "tuned")}
        assert all(line.endswith(f"x {peer}") for line in block), block


def test_the_bench_subjects_are_the_ones_laws_and_scenes_declare(monkeypatch):
    """The engine names no law or scene: each role goes to the first entry declaring it."""
    lcp = subject(LAWS, "lcp")
    assert "lcp" in LAWS[lcp].bench_roles
    law, scene = start_up_command()[1:]
    assert "start_up" in LAWS[law].bench_roles and "start_up" in CASES[scene].bench_roles
    assert "long_chain" in CASES[subject(CASES, "long_chain")].bench_roles
    monkeypatch.setattr(type(LAWS[lcp]), "bench_roles", ())
    with pytest.raises(InvalidProblem, match="no law declares the bench role 'lcp'"):
        subject(LAWS, "lcp")


def test_the_siconos_peer_imports_nothing_of_lawbench():
    """It runs by path in an interpreter where lawbench is not installed."""
    tree = ast.parse(PEER_SCRIPT.read_text(encoding="utf-8"))
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
    assert {name.split(".")[0] for name in imported} <= {
        *sys.stdlib_module_names,
        "numpy",
        "siconos",
    }


def test_the_peer_answers_by_path_in_json_and_a_failure_says_where():
    assert timed_by(sys.executable, {"command": "loop"}, 1, 1) > 0.0
    with pytest.raises(SolverFailure, match="unknown command 'nothing'"):
        ask(sys.executable, {"command": "nothing"}, 60.0)


def test_the_siconos_interpreter_given_is_the_only_one_probed(monkeypatch):
    monkeypatch.setenv("LAWBENCH_SICONOS_PYTHON", "/no/such/python3")
    assert candidates() == ["/no/such/python3"]
    with pytest.raises(SolverFailure, match="/no/such/python3"):
        ask("/no/such/python3", {"command": "probe"}, 60.0)
    monkeypatch.delenv("LAWBENCH_SICONOS_PYTHON")
    assert os.path.samefile(candidates()[0], sys.executable)


def test_siconos_nsgs_solves_one_contact_where_siconos_is_found():
    if siconos_python() is None:
        pytest.skip("no interpreter here imports siconos.numerics")
    problem = ContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), [0.3])
    answer = siconos_nsgs(problem, 1e-12)
    assert answer.fc3d_error <= 1e-10
    assert answer.diagnostics["wall_time_s"] >= 0.0
