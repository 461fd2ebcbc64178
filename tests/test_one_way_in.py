"""One way into every solve: a trace of the calls a command makes.

The trace records every function of lawbench that a command calls, with `sys.setprofile`,
leaving out the code that runs while a module is imported (a module's top level and what it
calls). It shows the path a scene takes into the solver, how often each parameter is checked,
and how many of lawbench's modules a small command involves. The one way decides for every
caller whether an answer may be shown: `lawbench.solve` refuses the answers ``lawbench solve``
refuses, those the checks call numerical failures.
"""

import collections
import sys
from types import FrameType

import numpy as np
import pytest

import lawbench
from lawbench.core.verdicts import Verdict
from lawbench.views.cli import main

SOLVE = ["solve", "moreau", "three_ball_chain", "--set", "e=0.5"]
# The modules whose functions a solve of one law on one scene may call, at most: the command
# and its parser (2); the entry point, the scene's parameters, their specs and the registry (4);
# the problem, and its matrices, kinetic metric and units (2); the law with its budget, its
# outcome and its solver (4: the law's module, the outcome, the solver, the law protocol); the
# scene and the chain scenes' shared module (2); the checks (1); the guards a law's code is held
# to from outside it, its time, Ctrl-C and the honesty of its answer (1).
MAX_MODULES = 16


def _importing(frame: FrameType | None) -> bool:
    while frame is not None:
        module = frame.f_globals.get("__name__", "")
        if frame.f_code.co_name == "<module>" and module.startswith("lawbench"):
            return True
        frame = frame.f_back
    return False


def trace(argv: list[str]) -> tuple[collections.Counter, collections.Counter]:
    """Calls of lawbench's functions by (module, name), and `Spec.coerce` calls by spec name."""
    calls: collections.Counter = collections.Counter()
    coerced: collections.Counter = collections.Counter()

    def profile(frame: FrameType, event: str, arg: object) -> None:
        if event != "call":
            return
        module = frame.f_globals.get("__name__", "")
        if not module.startswith("lawbench") or _importing(frame):
            return
        calls[module, frame.f_code.co_qualname] += 1
        if frame.f_code.co_qualname == "Spec.coerce":
            coerced[frame.f_locals["self"].name] += 1

    main(argv)  # a first run imports what the command needs; the trace is of the second
    sys.setprofile(profile)
    try:
        main(argv)
    finally:
        sys.setprofile(None)
    return calls, coerced


@pytest.fixture(scope="module")
def solve_trace() -> tuple[collections.Counter, collections.Counter]:
    return trace(SOLVE)


def test_a_scene_reaches_the_solver_by_one_path(solve_trace, capsys):
    calls, _ = solve_trace
    capsys.readouterr()
    entries = {name: n for (module, name), n in calls.items() if module == "lawbench.core.trial"}
    assert entries.get("make_trial") == 1, entries
    assert calls["lawbench.core.law", "Law.resolve"] == 1
    assert calls["lawbench.core.case", "Case.parameters"] == 1
    assert calls["lawbench.core.case", "Case.build_from"] == 1


def test_every_parameter_is_checked_once(solve_trace, capsys):
    _, coerced = solve_trace
    capsys.readouterr()
    from lawbench.core.case import CASES

    names = {spec.name for spec in CASES["three_ball_chain"].params}
    assert {name: coerced[name] for name in names} == dict.fromkeys(names, 1)


def test_a_small_solve_involves_few_modules(solve_trace, capsys):
    calls, _ = solve_trace
    capsys.readouterr()
    modules = sorted({module for module, _ in calls})
    assert len(modules) <= MAX_MODULES, modules


def granular(seed: int) -> lawbench.ImpactProblem:
    """Up to three point bodies in space with more frictional contacts than coordinates.

    Each contact joins two bodies, or a body and the ground, along a random normal; every
    third seed repeats some contacts. The contact Jacobian is rank-deficient, as in FCLIB's
    granular packings.
    """
    rng = np.random.default_rng(seed)
    bodies = int(rng.integers(1, 4))
    m, n = int(rng.integers(2, 3 * bodies + 4)), 3 * bodies
    Wn, Wt = np.zeros((n, m)), np.zeros((n, 2 * m))
    for j in range(m):
        normal = rng.normal(size=3)
        normal /= np.linalg.norm(normal)
        along = rng.normal(size=3)
        t1 = along - along.dot(normal) * normal
        t1 /= np.linalg.norm(t1)
        frame = np.stack([normal, t1, np.cross(normal, t1)])
        if seed % 3 == 0 and j > 0 and rng.random() < 0.5:
            Wn[:, j], Wt[:, 2 * j : 2 * j + 2] = Wn[:, j - 1], Wt[:, 2 * j - 2 : 2 * j]
            continue
        first, second = int(rng.integers(bodies)), int(rng.integers(-1, bodies))
        for body, sign in ((first, 1.0), (second, -1.0)):
            if body >= 0 and not (body == first and sign < 0):
                rows = slice(3 * body, 3 * body + 3)
                Wn[rows, j] += sign * frame[0]
                Wt[rows, 2 * j : 2 * j + 2] += sign * frame[1:].T
    masses = 10.0 ** rng.uniform(-4.5, 4.5, bodies) if seed % 2 else np.ones(bodies)
    v = rng.normal(size=n)
    mu = rng.choice([0.0, 0.1, 0.5, 1.0, 3.0], size=m)
    e = rng.choice([0.0, 0.5, 1.0], size=m)
    return lawbench.ImpactProblem.from_arrays(np.diag(np.repeat(masses, 3)), Wn, v, Wt, e=e, mu=mu)


# Seeds of `granular` where Moreau's Gauss-Seidel answer at a loose tolerance leaves a contact
# approaching beyond the checks' tolerance and within the law's own: `lawbench.solve` called it
# ok. (At the default tolerance its sweeps go on until no contact approaches.)
REFUSED = [39, 57]
LOOSE = {"method": "nsgs", "tol": 1e-3}


@pytest.mark.parametrize("seed", REFUSED)
def test_the_api_refuses_the_answers_the_command_line_refuses(seed, tmp_path, capsys):
    problem, options = granular(seed), LOOSE
    verdicts = lawbench.run_checks("moreau", problem, options)
    failed = [
        name for name, result in verdicts.items() if result.verdict == Verdict.NUMERICAL_FAILURE
    ]
    assert failed, "the checks find no numerical failure: the input no longer disagrees"
    with pytest.raises(lawbench.SolverFailure, match=f"moreau: {failed[0]} fails") as raised:
        lawbench.solve("moreau", problem, options)
    with pytest.raises(lawbench.SolverFailure, match=f"moreau: {failed[0]} fails"):
        lawbench.evaluate("moreau", problem, options)
    lawbench.save_problem(problem, tmp_path / "problem.json")
    capsys.readouterr()
    argv = ["solve", "moreau", "--problem", str(tmp_path / "problem.json")]
    assert main([*argv, "--option", "method=nsgs", "--option", "tol=1e-3"]) == 4
    assert str(raised.value) in capsys.readouterr().err
