"""``lawbench solve LAW CASE``: one law on one scene or problem file, with the checks' verdicts."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from typing import Any

import numpy as np

from lawbench.checks import CheckResult, run_checks
from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.errors import InvalidProblem
from lawbench.core.trial import Trial, make_trial
from lawbench.files.facts import ProblemFile
from lawbench.views.cli.main import _assignments, _path, _seconds, add_assignments

# Contacts whose impulses the text output of a contact-space solve lists (--json gives all).
SHOWN_CONTACTS = 10

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("solve", {"help": "solve one case (or a problem file) with one law"})


def arguments(solve: argparse.ArgumentParser) -> None:
    """The arguments of the ``solve`` command."""
    solve.add_argument("law")
    solve.add_argument("case", nargs="?", help="a scene name (or give --problem FILE)")
    solve.add_argument(
        "--problem",
        type=_path,
        metavar="FILE",
        help="a problem file (.json, .npz, .h5): see lawbench export",
    )
    add_assignments(solve, "--set", help="a case parameter; a comma-separated value is a list")
    add_assignments(solve, "--option", help="a law option")
    solve.add_argument(
        "--transform",
        metavar="NAME=VALUE",
        help="a transform of the built problem (grazing=SPEED, duplicated=CONTACT)",
    )
    solve.add_argument(
        "--max-seconds",
        type=_seconds,
        metavar="S",
        help="stop the solve after S seconds of wall time (exit code 4)",
    )
    solve.add_argument("--json", action="store_true", help="print one JSON object")
    solve.set_defaults(run=run, solves=True)


def run(args: argparse.Namespace) -> None:
    """Solve, then print the record (text, or one JSON object under ``--json``).

    The solve is bounded from outside (`lawbench.core.trial.make_trial`); a law stuck in
    native code past that bound ends the ``lawbench`` program (``solves``:
    `lawbench.views.cli.main`).
    """
    case, params = _scene_or_problem(args)
    options = _assignments(args.option, "--option")
    if isinstance(case, ProblemFile) and isinstance(case.problem, ContactProblem):
        _solve_contact(args, case, options)
        return
    record = _solve(args, case, params, options)
    if _printed_as_json(args, record):
        return
    _print_record(record)


def _scene_or_problem(
    args: argparse.Namespace,
) -> tuple[str | ProblemFile, dict[str, str]]:
    """The scene name and its parameters, or the problem file ``--problem FILE`` as read."""
    params = _assignments(args.set, "--set")
    if (args.case is None) == (args.problem is None):
        raise InvalidProblem("give a scene name or --problem FILE (one of the two)")
    if args.problem is None:
        return args.case, params
    if params:
        raise InvalidProblem("--set gives scene parameters; a problem file is solved as it is")
    from lawbench.files.problem_files import read_problem

    return read_problem(args.problem), {}


def _solve(
    args: argparse.Namespace,
    case: str | ProblemFile,
    params: dict[str, str],
    options: dict[str, str],
) -> dict:
    """The record of ``args.law`` on a scene, or on an impact read from a problem file.

    A file's own data add what they say of the outcome (a global FCLIB form's FC3D error). An
    answer that breaks a promise raises `SolverFailure` in the solve (`make_trial`).
    """
    trial = make_trial(
        args.law,
        case,
        params=params,
        options=options,
        transform=args.transform or "",
        max_seconds=args.max_seconds,
    )
    checks = run_checks(trial)
    record = trial_record(trial, checks)
    if isinstance(case, ProblemFile):
        record["diagnostics"].update(case.facts.diagnostics(trial.outcome))
    return record


def _print_record(record: dict) -> None:
    """The text output of an impact's solve."""
    print(f"{record['law']} on {record['case']}  (status: {record['status']})")
    print(f"{'coordinate':<16}{'v_minus':>14}{'v_plus':>14}")
    for name, before, after in zip(
        record["coordinates"], record["v_minus"], record["v_plus"], strict=True
    ):
        print(f"{name:<16}{before:>14.6g}{after:>14.6g}")
    print("Pn: " + ", ".join(f"{p:.6g}" for p in record["Pn"]))
    if record["Pt"]:
        print("Pt: " + ", ".join(f"{p:.6g}" for p in record["Pt"]))
    print(f"T_minus = {record['T_minus']:.6g} J, T_plus = {record['T_plus']:.6g} J")
    print(f"formulation: {record['diagnostics'].get('formulation')}")
    if "fc3d_error" in record["diagnostics"]:
        print(f"FC3D error on the file's own W and q: {record['diagnostics']['fc3d_error']:.3g}")
    for name, result in record["checks"].items():
        print(f"  {name:<14}{result['verdict']:<19}{result['detail']}")
        if result["claim"]:
            print(f"  {'':<14}{'':<19}{result['claim']}")


def _printed_as_json(args: argparse.Namespace, record: dict) -> bool:
    """Print a solve's warnings under --verbose, and the record under --json: whether it was."""
    if args.verbose:
        for heard in record["diagnostics"].get("warnings", ()):
            print(f"lawbench: warning: {heard}", file=sys.stderr)
    if args.json:
        print(json.dumps(record, indent=2, allow_nan=False))
    return bool(args.json)


def _solve_contact(args: argparse.Namespace, read: ProblemFile, options: dict[str, str]) -> None:
    """``solve LAW --problem FILE`` of a local FCLIB file: the contact-space problem as given."""
    problem = read.problem
    if args.transform:
        raise InvalidProblem(
            "--transform changes an impact problem; a contact-space problem (FCLIB's local "
            "form) is solved as it is"
        )
    solution = make_trial(args.law, read, options=options, max_seconds=args.max_seconds).outcome
    record = contact_record(args.law, problem, solution)
    if _printed_as_json(args, record):
        return
    diagnostics = record["diagnostics"]
    print(f"{record['law']} on {record['case']}  ({problem.m} contacts, dimension {problem.dim})")
    print(f"{'contact':<10}{'r (normal, tangents)':<44}{'u (normal, tangents)'}")
    for j in range(min(problem.m, SHOWN_CONTACTS)):
        span = slice(j * problem.dim, (j + 1) * problem.dim)
        print(f"{j:<10}{_numbers(solution.r[span]):<44}{_numbers(solution.u[span])}")
    if problem.m > SHOWN_CONTACTS:
        print(f"... {problem.m - SHOWN_CONTACTS} more contacts (--json gives all)")
    print(f"formulation: {diagnostics.get('formulation')}")
    print(f"FC3D error on the file's own W and q: {record['fc3d_error']:.3g}")
    print(f"W's asymmetry max|W - W.T| / max|W|: {read.facts.asymmetry:.3g}")
    print(f"wall time: {diagnostics['wall_time_s']:.3g} s")


def _numbers(values: Sequence[float]) -> str:
    return ", ".join(f"{value:.6g}" for value in values)


def plain(value: Any) -> Any:
    """Return ``value`` as JSON holds it: numpy arrays and scalars as lists, floats and ints.

    A number that is not finite is null (JSON has none); anything JSON has no type for (a set,
    a complex number, an object a plugin left in its diagnostics) is its text.
    """
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return plain(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if value is None or isinstance(value, str | int):
        return value
    return str(value)


def trial_record(trial: Trial, checks: dict[str, CheckResult]) -> dict[str, Any]:
    """The JSON object of ``lawbench solve --json``."""
    outcome = trial.outcome
    record = {
        "law": trial.law.name,
        "case": trial.scene,
        "params": trial.params,
        "coordinates": (
            trial.case.coordinates(trial.params)
            if trial.case is not None
            else [f"v[{i}]" for i in range(trial.problem.n)]
        ),
        "v_minus": trial.problem.v,
        "v_plus": outcome.v_plus,
        "Pn": outcome.Pn,
        "Pt": outcome.Pt,
        "T_minus": outcome.T_minus,
        "T_plus": outcome.T_plus,
        "checks": {name: result.as_dict() for name, result in checks.items()},
        "status": outcome.status,
        "diagnostics": outcome.diagnostics,
    }
    if outcome.path is not None:
        record["path"] = outcome.path
    return plain(record)


def contact_record(law: str, problem: ContactProblem, solution: ContactSolution) -> dict[str, Any]:
    """The JSON object of ``lawbench solve --json`` on a contact-space problem (FCLIB local)."""
    return plain(
        {
            "law": law,
            "case": problem.name,
            "contacts": problem.m,
            "dim": problem.dim,
            "status": "ok",
            "r": solution.r,
            "u": solution.u,
            "fc3d_error": solution.fc3d_error,
            "diagnostics": solution.diagnostics,
        }
    )
