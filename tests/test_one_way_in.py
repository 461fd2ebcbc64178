"""One way into every solve: a trace of the calls a command makes.

The trace records every function of lawbench that a command calls, with `sys.setprofile`,
leaving out the code that runs while a module is imported (a module's top level and what it
calls). It shows the path a scene takes into the solver, how often each parameter is checked,
and how many of lawbench's modules a small command involves.
"""

import collections
import sys
from types import FrameType

import pytest

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
