"""The public API shows itself, and its entry points share one calling convention."""

import pydoc
import subprocess
import sys

import numpy as np
import pytest

import lawbench
from lawbench.core.registry import Registry

LISTED = [
    "solve",
    "evaluate",
    "run_checks",
    "solve_batch",
    "ImpactProblem",
    "ProblemBatch",
    "load_problem",
    "save_problem",
    "load_run",
    "fit",
    "check_law",
    "LAWS",
    "CASES",
]


def test_dir_and_all_list_every_public_name_lazy_ones_included():
    for name in LISTED:
        assert name in lawbench.__all__ and name in dir(lawbench), name
    for name in lawbench.__all__:
        assert getattr(lawbench, name) is not None, name


def test_help_lists_every_public_name():
    text = pydoc.render_doc(lawbench, renderer=pydoc.plaintext)
    for name in LISTED:
        assert f"\n    {name}" in text or f"\n    class {name}" in text, name


def test_the_lazy_names_load_only_when_asked_for():
    code = (
        "import sys, lawbench; "
        "print(sorted(m for m in ('lawbench.views.plotting', 'lawbench.fitting', "
        "'lawbench.files.problem_files', 'lawbench.core.batch') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "[]", done.stderr


def test_registries_are_read_only_mappings():
    assert lawbench.LAWS["newton"].name == "newton"
    assert "newton" in lawbench.LAWS and "nolaw" not in lawbench.LAWS
    assert list(lawbench.LAWS) == lawbench.LAWS.names() == list(lawbench.LAWS.keys())
    assert len(lawbench.CASES) == len(lawbench.CASES.names())
    assert dict(lawbench.CASES.items())["lamina"] is lawbench.CASES["lamina"]
    with pytest.raises(KeyError, match="unknown law 'nolaw'; known: brach"):
        lawbench.LAWS["nolaw"]
    with pytest.raises(lawbench.InvalidProblem, match="unknown case 'noscene'"):
        lawbench.CASES.get("noscene")
    assert not hasattr(Registry, "__setitem__") and not hasattr(Registry, "__delitem__")


def test_run_checks_takes_the_convention_of_solve_and_evaluate():
    by_name = lawbench.run_checks("newton", "three_ball_chain", e=0.5)
    trial = lawbench.evaluate("newton", "three_ball_chain", e=0.5)
    by_trial = lawbench.run_checks(trial)
    assert list(by_name) == list(by_trial)
    assert {n: r.verdict for n, r in by_name.items()} == {n: r.verdict for n, r in by_trial.items()}
    chosen = lawbench.run_checks(
        "sequential", "two_balls_wall", {"order": "right_to_left"}, checks=["momentum"], e=0.5
    )
    assert list(chosen) == ["momentum"]
    assert list(lawbench.run_checks(trial, checks="admissible")) == ["admissible"]


def test_run_checks_on_a_problem_of_your_own():
    problem = lawbench.ImpactProblem.from_arrays(np.eye(2), [[-1.0], [1.0]], v=[1.0, 0.0], e=1.0)
    assert lawbench.run_checks("poisson", problem)["energy_gain"].passed


@pytest.mark.parametrize(
    ("call", "named"),
    [
        (lambda: lawbench.solve(None, "three_ball_chain"), "law must be"),
        (lambda: lawbench.evaluate("newton", 3), "case must be"),
        (lambda: lawbench.solve("newton", "three_ball_chain", ["tol"]), "options must be"),
        (lambda: lawbench.solve_batch(42, []), "law must be"),
        (lambda: lawbench.run_checks("newton"), "needs the argument case"),
        (
            lambda: lawbench.run_checks(
                lawbench.evaluate("newton", "three_ball_chain"), "admissible"
            ),
            "case was given with it",
        ),
        (lambda: lawbench.run_checks("newton", "three_ball_chain", checks=[1]), "checks must be"),
        (lambda: lawbench.load_problem(123), r"problem file: a path \(str or os.PathLike\)"),
        (
            lambda: lawbench.save_problem(lawbench.CASES["three_ball_chain"].build(), None),
            "problem file: a path",
        ),
        (lambda: lawbench.check_law(None), "law must be a law name"),
        (lambda: lawbench.CASES.get(7), "case must be a case name"),
        (lambda: lawbench.LAWS.get("newton").resolve(None), "problem must be an ImpactProblem"),
        (lambda: lawbench.solve_batch("newton", "abc"), r"problems\[0\] is str"),
        (lambda: lawbench.plot_outcome(None), "outcome must be an Outcome or a Trial"),
        (lambda: lawbench.plot_path("x"), "outcome must be an Outcome or a Trial"),
        (lambda: lawbench.plot_sweep("table", "x", "y"), "frame must be a pandas DataFrame"),
        (lambda: lawbench.save_problem(None, "p.json"), "problem must be an ImpactProblem"),
        (
            lambda: lawbench.ProblemBatch(np.eye(2), [[-1.0], [1.0]], [[1.0, 0.0]], "x"),
            "coefficients must be a mapping",
        ),
        (lambda: lawbench.check_law("newton", random_problems=1.5), "random_problems must be"),
        (
            lambda: lawbench.ImpactProblem.from_arrays(
                np.eye(2), [[-1.0], [1.0]], [1, 0], bodies=1
            ),
            "bodies must be a mapping",
        ),
        (
            lambda: lawbench.plot_outcome(lawbench.solve("newton", "three_ball_chain"), ax="x"),
            "ax must be matplotlib Axes",
        ),
    ],
)
def test_a_wrong_argument_is_a_type_error_that_names_it(call, named):
    with pytest.raises(TypeError, match=named):
        call()


def test_an_unknown_check_is_named_with_the_known_ones():
    with pytest.raises(
        lawbench.InvalidProblem, match=r"unknown check 'colour'; known: .*energy_gain"
    ):
        lawbench.run_checks("newton", "three_ball_chain", checks=["colour"])


def test_a_problem_with_a_vector_that_is_not_numeric_is_invalid_naming_it():
    """Not a bare ValueError from numpy: the field is named."""
    with pytest.raises(lawbench.InvalidProblem, match="v: not an array of numbers"):
        lawbench.ImpactProblem.from_arrays(np.eye(2), np.array([[-1.0], [1.0]]), v=["a", "b"])
    with pytest.raises(lawbench.InvalidProblem, match="v: not an array of numbers"):
        lawbench.ProblemBatch(np.eye(2), np.array([[-1.0], [1.0]]), "x", {})
    with pytest.raises(lawbench.InvalidProblem, match=r"coefficients\['e'\]: not an array"):
        lawbench.ProblemBatch(np.eye(2), np.array([[-1.0], [1.0]]), [[1.0, 0.0]], {"e": "a"})


@pytest.mark.parametrize(
    ("call", "named"),
    [
        (lambda: lawbench.solve("newton", "three_ball_chain", e=10**400), r"e\[0\] = 1000"),
        (lambda: lawbench.solve("newton", "three_ball_chain", masses=b"abc"), "masses"),
        (lambda: lawbench.Verdict("nope"), "verdict 'nope': must be one of holds"),
        (lambda: lawbench.load_problem("a\x00b.json"), "cannot hold a NUL"),
        (lambda: lawbench.check_law("newton", random_problems=-1), "random_problems = -1"),
        (
            lambda: lawbench.ImpactProblem.from_arrays(np.eye(2) * 1j, [[-1.0], [1.0]], [1, 0]),
            "M: complex numbers",
        ),
        (
            lambda: lawbench.ImpactProblem.from_arrays(np.eye(2), [[-1.0, 0.0], [1.0]], [1, 0]),
            "Wn: not an array of numbers",
        ),
        (
            lambda: lawbench.ImpactProblem.from_arrays(
                [[1.0, 0.0], [0.0]], [[-1.0], [1.0]], [1, 0]
            ),
            "M: not an array of numbers",
        ),
        (
            lambda: lawbench.ImpactProblem.from_arrays(
                np.eye(2), [[-1.0], [1.0]], [1, 0], bodies={"a": "xyz"}
            ),
            r"bodies\['a'\] = 'xyz': not indices",
        ),
    ],
)
def test_a_bad_value_is_invalid_naming_it(call, named):
    """Never a bare ValueError, OverflowError or a silent conversion: the argument is named."""
    with pytest.raises(lawbench.InvalidProblem, match=named):
        call()
