"""``lawbench bench --problems DIR``: every law (and method) on every problem file of a folder.

Every law, and each method of a law with an option ``method``, on every problem file of a
folder, one guarded row each (file, contacts, law, method, status, FC3D error, seconds), with
Siconos' NSGS as a peer where an interpreter here has Siconos (`lawbench.bench.peer`). The
rows' profiles and summary are `lawbench.bench.profiles`.
"""

from __future__ import annotations

import contextlib
import functools
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.bench.peer import siconos_available, siconos_nsgs, siconos_reads_fclib
from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.errors import BudgetExceeded, InvalidProblem, NotApplicable, SolverFailure
from lawbench.core.guards import WALL_CLOCK, alarm
from lawbench.core.law import LAWS
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.trial import make_trial
from lawbench.files.facts import ProblemFile
from lawbench.studies.guard import TIME_OUT, Guard, Result

# The extensions of the problem files read (`lawbench.files.problem_files.load_problem`).
PROBLEM_SUFFIXES = (".json", ".npz", ".h5", ".hdf5")
# A row solves its problem when its status is ok and, where it is measured, the FC3D error is
# at most the bench's tolerance (by default this one, the threshold of Acary, Brémond and
# Huber's comparisons).
SOLVED_FC3D = 1e-8
COLUMNS = ("file", "contacts", "law", "method", "status", "fc3d_error", "seconds", "error")
# The guard kills a worker that heeds neither its law's budget nor its alarm by this many times
# the budget, plus a grace (a file read, a loop in compiled code).
KILL_FACTOR, KILL_GRACE_S = 2.0, 2.0
# Step bounds of a bench row: the wall-clock budget decides.
MAX_STEPS = 10**9
# The peer's rows: Siconos' NSGS, as a law and a method.
PEER = ("siconos", "nsgs")


def problem_files(folder: str | Path) -> list[Path]:
    """The problem files of ``folder`` (by extension, `PROBLEM_SUFFIXES`), sorted by name.

    Raises
    ------
    InvalidProblem
        For a folder that does not exist or holds no problem file.
    """
    where = Path(folder)
    if not where.is_dir():
        raise InvalidProblem(f"bench --problems {folder}: no such folder")
    found = sorted(p for p in where.iterdir() if p.is_file() and p.suffix in PROBLEM_SUFFIXES)
    if not found:
        raise InvalidProblem(
            f"bench --problems {folder}: no problem file ({', '.join(PROBLEM_SUFFIXES)}) in it"
        )
    return found


def solvers(laws: Sequence[str] | None = None) -> list[tuple[str, str]]:
    """``(law, method)`` of every law of ``laws`` (default every registered one).

    A law with an option ``method`` gives one pair per choice, any other the method ''.
    """
    pairs = []
    for name in laws or LAWS.names():
        methods = [s.choices for s in LAWS[name].options if s.name == "method" and s.choices]
        pairs += [(name, method) for method in (methods[0] if methods else ("",))]
    return pairs


def status_of(error: BaseException) -> str:
    """The status of a row whose solve raised ``error``."""
    if isinstance(error, NotApplicable):
        return "not applicable"
    if isinstance(error, BudgetExceeded):
        return "budget"
    if isinstance(error, SolverFailure):
        return "solver failure"
    return "error"


@functools.lru_cache(maxsize=1)
def _loaded(path: str) -> ProblemFile:
    """The file ``path`` as read, once per worker for all the laws solved on it."""
    from lawbench.files.problem_files import read_problem

    return read_problem(path)


@functools.cache
def _warmed(law: str, method: str) -> None:
    """Solve a one-contact problem once per worker with ``law`` and ``method``, untimed.

    A compiled kernel (numba) is loaded on its first call: that start-up belongs to no file.
    """
    with contextlib.suppress(Exception):
        _solve(ContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), [0.3]), law, method, 1.0)


def solve_file(
    path: str, law: str, method: str, seconds: float, tol: float = SOLVED_FC3D
) -> dict[str, Any]:
    """The row of ``law`` (with ``method``, '' for none) on the problem file ``path``.

    The law gets ``seconds`` as its ``max_seconds`` and ``tol`` as its ``tol`` where it has
    one, under an `alarm` of as many seconds, and its whole call is timed (the peer's time is
    its solver call alone, `siconos_nsgs`); its step bounds are lifted to `MAX_STEPS`, so that
    time alone decides. A local FCLIB file is solved in contact space (`Law.solve_contact`),
    any other problem as an impact. Never raises: a failure is the row's status and error.
    """
    row: dict[str, Any] = dict.fromkeys(COLUMNS, math.nan)
    row.update(file=Path(path).name, law=law, method=method, status="ok", error="")
    try:
        read = _loaded(path)
        problem = read.problem
        row["contacts"] = problem.m
        _warmed(law, method)
        with alarm(seconds):
            start = time.perf_counter()
            answer = _solve(problem, law, method, seconds, tol, path)
            row["seconds"] = time.perf_counter() - start
        if (law, method) == PEER:
            row["seconds"] = answer.diagnostics["wall_time_s"]
        if isinstance(answer, ContactSolution):
            row["fc3d_error"] = answer.fc3d_error
        else:
            row["fc3d_error"] = read.facts.diagnostics(answer).get("fc3d_error", math.nan)
    except Exception as exc:  # a row records its failure and the bench goes on
        row["status"], row["error"] = status_of(exc), f"{type(exc).__name__}: {exc}"
    return row


def _solve(
    problem: ImpactProblem | ContactProblem,
    law: str,
    method: str,
    seconds: float,
    tol: float = SOLVED_FC3D,
    path: str = "",
) -> Outcome | ContactSolution:
    """``law`` (or the Siconos peer) on ``problem`` within ``seconds``, to ``tol``."""
    if (law, method) == PEER:
        return siconos_nsgs(problem, tol, path)
    specs = {spec.name for spec in LAWS[law].options}
    options: dict[str, Any] = {"max_seconds": seconds}
    if method:
        options["method"] = method
    if "max_steps" in specs:
        options["max_steps"] = MAX_STEPS
    if "tol" in specs:
        options["tol"] = tol
    # The bench judges an answer by its FC3D error: the outcome is taken as it is.
    return make_trial(law, problem, options=options, judged=False).outcome


def bench_problems(
    folder: str | Path,
    seconds: float,
    laws: Sequence[str] | None = None,
    tol: float = SOLVED_FC3D,
    peer_tol: float | None = None,
) -> tuple[pd.DataFrame, list[str]]:
    """Every solver (`solvers`, and Siconos' NSGS where importable) on every file of ``folder``.

    One row per file x law x method (`COLUMNS`), each solved in a guarded worker process
    (`lawbench.studies.guard.Guard`, one at a time so that the times do not share the machine):
    a row that runs out of time is a ``budget`` row, a damaged file gives ``error`` rows, and
    neither stops the others. Every law with an option ``tol`` solves to ``tol``, the peer to
    ``peer_tol`` (default ``tol``); a row solves its file when its FC3D error is at most
    ``tol``. Returns the table and its notes.
    """
    files = problem_files(folder)
    pairs = solvers(laws)
    peer_tol = tol if peer_tol is None else peer_tol
    notes = [
        f"budget {seconds:g} s per file and solver; every solver asked for tol {tol:g}; solved: "
        f"status ok and FC3D error <= {tol:g} where the file defines it"
    ]
    if siconos_available():
        pairs.append(PEER)
        if not siconos_reads_fclib():
            notes.append(
                "Siconos numerics here reads no FCLIB file (built without FCLIB): its NSGS "
                "is given each problem's dense local form"
            )
        if peer_tol != tol:
            notes.append(f"Siconos' NSGS asked for tol {peer_tol:g}")
    else:
        notes.append("Siconos numerics (python package siconos) not available: no peer column")
    tasks = [(str(path), law, method) for path in files for law, method in pairs]
    kill = KILL_FACTOR * seconds + KILL_GRACE_S
    with Guard(1, kill) as guard:
        handles = {
            guard.submit(
                solve_file, *task, seconds, peer_tol if tuple(task[1:]) == PEER else tol
            ): task
            for task in tasks
        }
        rows = [_guarded_row(guard.result(h), task, kill) for h, task in handles.items()]
    return pd.DataFrame(rows, columns=list(COLUMNS)), notes


def _guarded_row(result: Result, task: tuple[str, str, str], kill_s: float) -> dict[str, Any]:
    """The row of a task: its own, or the guard's account of a worker it stopped or lost."""
    if result.status == "ok":
        return result.value
    path, law, method = task
    row: dict[str, Any] = dict.fromkeys(COLUMNS, math.nan)
    status = "budget" if result.status == TIME_OUT else "error"
    message = (
        f"{WALL_CLOCK}: no answer within {kill_s:g} s"
        if status == "budget"
        else (f"{result.error_class}: {result.error_message}")
    )
    row.update(file=Path(path).name, law=law, method=method, status=status, error=message)
    return row
