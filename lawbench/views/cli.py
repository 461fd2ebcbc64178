"""The ``lawbench`` command line.

Exit codes: 0 done; 2 bad usage or invalid input; 3 the law does not apply; 4 solver failure;
5 a regression drifted past its baseline; 6 a law fails the common checks (``lawbench check``);
1 an unexpected internal error. Errors are one line
on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

from lawbench.checks import run_checks
from lawbench.core.case import CASES, Case
from lawbench.core.contact import ContactProblem
from lawbench.core.errors import (
    InvalidProblem,
    LawbenchError,
    LossyExport,
    NotApplicable,
    SolverFailure,
)
from lawbench.core.law import LAWS, Law
from lawbench.core.problem import ImpactProblem
from lawbench.core.registry import Registry
from lawbench.core.transforms import apply
from lawbench.core.trial import evaluate
from lawbench.files.paths import output_file, output_folder
from lawbench.studies.declared import STUDIES
from lawbench.studies.guard import BUDGET_S, EXECUTORS, alarm
from lawbench.studies.study import Job
from lawbench.views.serialize import contact_record, trial_record


class Drift(LawbenchError):
    """Outcomes moved past their baseline tolerance."""


class CheckFailed(LawbenchError):
    """A law fails the common checks (a numerical failure or an unexplained verdict)."""


EXIT_CODES = {
    InvalidProblem: 2,
    NotApplicable: 3,
    SolverFailure: 4,
    CheckFailed: 6,
    LawbenchError: 5,
}


# Seconds one law may spend on one file of ``lawbench bench --problems``.
PROBLEM_BUDGET_S = 60.0
# Cells above which ``lawbench run`` asks for --yes.
LARGE_GRID = 10_000
# Cells of a large grid timed for the estimate of its duration.
ESTIMATE_CELLS = 3


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line and exit code 2."""

    def error(self, message: str) -> None:
        self.exit(2, f"lawbench: {message} (see lawbench --help)\n")


# The bounds of the command line's numbers: a count beyond them is a typo or an attack, and a
# wall-clock limit must be a finite number of seconds.
MAX_WORKERS = 256
MAX_REPEATS = 100_000
MAX_SECONDS = 1e6


def _count(low: int, high: int) -> Callable[[str], int]:
    """An argparse type: an integer within [low, high]."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{value} is outside {low}..{high}")
        return value

    return parse


def _real(accepts: Callable[[float], bool], what: str) -> Callable[[str], float]:
    """An argparse type: a number that ``accepts`` (``what`` says which, in its message)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not accepts(value):
            raise argparse.ArgumentTypeError(f"{text}: {what}")
        return value

    return parse


# A wall-clock limit: finite and positive, at most MAX_SECONDS (NaN fails both comparisons).
_seconds = _real(
    lambda value: 0 < value <= MAX_SECONDS,
    f"a wall-clock limit is a number of seconds in (0, {MAX_SECONDS:g}]",
)
_tolerance = _real(lambda value: 0 < value < 1, "a tolerance is in (0, 1)")
_fraction = _real(lambda value: 0 <= value < 1, "a fraction is in [0, 1)")


def _path(text: str) -> str:
    """An argparse type: a path, never empty (an empty one names the current folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path")
    return text


class _Version(argparse.Action):
    """``--version``: the installed version, looked up only when asked for."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs=0, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *args: object) -> None:
        from importlib.metadata import version

        print(f"lawbench {version('lawbench')}")
        parser.exit()


def _assignments(items: Sequence[str], flag: str) -> dict[str, str]:
    values: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise InvalidProblem(f"{flag} {item!r}: expected NAME=VALUE")
        if name in values:
            raise InvalidProblem(f"{flag} {name} is given twice")
        values[name] = value.strip()
    return values


def _list(args: argparse.Namespace) -> None:
    for registry in (LAWS, CASES):
        print(f"{registry.kind}s:")
        for entry in registry.values():
            print(f"  {entry.name:<16} {entry.summary}")
        if registry.unavailable:
            print(f"{registry.kind}s not loaded:")
            for name, reason in registry.unavailable.items():
                print(f"  {name:<16} {reason}")


def _law_object(text: str) -> Law:
    """A registered law's name, or ``module:attribute`` naming a law (class or instance)."""
    if ":" not in text:
        return LAWS.get(text)
    import importlib

    module, _, attribute = text.partition(":")
    if not (module and attribute):
        raise InvalidProblem(f"{text!r}: name a law as MODULE:ATTRIBUTE, both non-empty")
    try:
        loaded = getattr(importlib.import_module(module), attribute)
    except (ImportError, AttributeError, TypeError) as exc:
        # TypeError: a relative module name ('..x'), which has no package to start from.
        raise InvalidProblem(f"{text}: cannot be imported ({exc})") from None
    if isinstance(loaded, type):
        if not issubclass(loaded, Law):
            raise InvalidProblem(f"{text} is not a lawbench.Law")
        try:
            loaded = loaded()
        except TypeError as exc:  # an abstract class, or one whose constructor takes arguments
            raise InvalidProblem(f"{text}: cannot be made a law ({exc})") from None
    if not isinstance(loaded, Law):
        raise InvalidProblem(f"{text} is not a lawbench.Law")
    return loaded


def _check(args: argparse.Namespace) -> None:
    from lawbench.studies.conformance import check_law

    cases = _names(args.cases, "--cases", CASES)
    report = check_law(_law_object(args.law), cases=cases, random_problems=args.random)
    frame = report.to_frame()
    if args.json:
        print(frame.to_json(orient="records", indent=1))
    else:
        with_values = frame.assign(value=frame["value"].map(_short))
        print(with_values.drop(columns=["law", "claim"]).to_string(index=False, max_colwidth=70))
        print(", ".join(f"{n} {v}" for v, n in report.counts().items()))
    for problem in report.declaration:
        print(f"declaration: {problem}", file=sys.stderr)
    if not report.passed:
        names = sorted({f"{r['check']} on {r['scene']}" for r in report.failures})
        raise CheckFailed(
            f"{report.law} fails the common checks: {', '.join(names) or 'declaration'}"
        )


def _names(text: str | None, option: str, registry: Registry) -> list[str] | None:
    """The names of a comma-separated option, each known to ``registry``; None when not given.

    ``*`` stands for every registered name.

    Raises
    ------
    InvalidProblem
        For an empty name (``--cases ''``), or `UnknownName` for one the registry does not know.
    """
    if text is None:
        return None
    names = [name.strip() for name in text.split(",")]
    if not all(names):
        raise InvalidProblem(f"{option} {text!r}: an empty name (give names, or leave it out)")
    for name in names:
        if name != "*":
            registry.get(name)
    return names


def _short(value: object) -> str:
    return "" if value is None or value != value else f"{value:.3g}"


def _describe_law(law: Law) -> None:
    tags = law.tags
    print(f"law {law.name}: {law.summary}")
    print(f"source: {law.source}")
    print(
        f"tags: friction={tags.friction} several_contacts={tags.several_contacts} "
        f"spatial={tags.spatial} stiffness={tags.stiffness} "
        f"accuracy_knob={tags.accuracy_knob}"
    )
    print("options:" if law.options else "options: none")
    for spec in law.options:
        print(f"  {spec.name} = {spec.default!r}  ({spec.describe_range()}) {spec.doc}")
    for title, claims in (("findings", law.findings), ("guarantees", law.guarantees)):
        print(f"{title}:" if claims else f"{title}: none")
        for claim in claims:
            print(f"  {claim.check}: {claim.reason}")
            print(f"    where: {claim.region.text}; source: {claim.source}")


def _describe_case(case: Case) -> None:
    params = case.parameters()
    print(f"case {case.name}: {case.summary}")
    print(f"coordinates (defaults): {', '.join(case.coordinates(params))}")
    print("parameters:")
    for spec in case.params:
        unit = f" [{spec.unit}]" if spec.unit else ""
        print(f"  {spec.name} = {spec.default!r}{unit}  ({spec.describe_range()}) {spec.doc}")
    truth = case.ground_truth
    print(f"ground truth: {truth.describe()}: {truth.why}" if truth else "ground truth: none")
    print("references:" if case.references else "references: none")
    for ref in case.references:
        options = "".join(f" {k}={v}" for k, v in ref.options.items())
        print(f"  {ref.name} [{ref.law}{options}]: {ref.source}")


def _describe(args: argparse.Namespace) -> None:
    if args.name in LAWS:
        _describe_law(LAWS.get(args.name))
    elif args.name in CASES:
        _describe_case(CASES.get(args.name))
    else:
        known = ", ".join(LAWS.names() + CASES.names())
        raise InvalidProblem(f"unknown law or case {args.name!r}; known: {known}")


def _scene_or_problem(
    args: argparse.Namespace,
) -> tuple[str | ImpactProblem | ContactProblem, dict[str, str]]:
    """The scene name and its parameters, or the problem of ``--problem FILE``."""
    params = _assignments(args.set, "--set")
    if (args.case is None) == (args.problem is None):
        raise InvalidProblem("give a scene name or --problem FILE (one of the two)")
    if args.problem is None:
        return args.case, params
    if params:
        raise InvalidProblem("--set gives scene parameters; a problem file is solved as it is")
    from lawbench.files.problem_files import load_problem

    return load_problem(args.problem), {}


def _export(args: argparse.Namespace) -> None:
    from lawbench.files.fclib import write_fclib
    from lawbench.files.problem_files import save_problem

    problem = CASES.get(args.case).build(**_assignments(args.set, "--set"))
    if args.fclib:
        path = write_fclib(problem, args.out, args.fclib)
    else:
        path = save_problem(problem, args.out)
    print(f"problem written to {path}")


def _solve(args: argparse.Namespace) -> None:
    case, params = _scene_or_problem(args)
    options = _assignments(args.option, "--option")
    if isinstance(case, ContactProblem):
        _solve_contact(args, case, options)
        return
    with alarm(args.max_seconds):
        if isinstance(case, str):
            trial = Job(args.law, case, params, options, args.transform or "").solve()
        else:
            trial = evaluate(args.law, apply(args.transform or "", case), options)
        record = trial_record(trial, run_checks(trial))
    if args.problem is not None:
        from lawbench.files.problem_files import file_diagnostics

        record["diagnostics"].update(file_diagnostics(args.problem, trial.outcome))
    if _printed_as_json(args, record):
        return
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


# Contacts whose impulses the text output of a contact-space solve lists (--json gives all).
SHOWN_CONTACTS = 10


def _solve_contact(
    args: argparse.Namespace, problem: ContactProblem, options: dict[str, str]
) -> None:
    """``solve LAW --problem FILE`` of a local FCLIB file: the contact-space problem as given."""
    if args.transform:
        raise InvalidProblem(
            "--transform changes an impact problem; a contact-space problem (FCLIB's local "
            "form) is solved as it is"
        )
    with alarm(args.max_seconds):
        solution = LAWS.get(args.law).solve_contact(problem, **options)
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
    print(f"W's asymmetry max|W - W.T| / max|W|: {diagnostics['W_asymmetry']:.3g}")
    print(f"wall time: {diagnostics['wall_time_s']:.3g} s")


def _numbers(values: Sequence[float]) -> str:
    return ", ".join(f"{value:.6g}" for value in values)


def _report(args: argparse.Namespace) -> None:
    from lawbench.views.report import write_report

    path = write_report(output_folder(args.out, "report folder"), mode=args.mode)
    print(f"report written to {path}")


def _study(args: argparse.Namespace) -> None:
    from lawbench.studies.runfile import file_format, metadata, save_run
    from lawbench.studies.tables import study_table

    if args.list:
        for study in STUDIES.values():
            print(f"  {study.name:<32} {study.title}")
        return
    if not args.name:
        raise InvalidProblem("study: give a study's name, or --list")
    given = _assignments(args.set, "--set")
    if args.out:
        # A bad extension or a path that is not a file stops before any cell is computed.
        file_format(output_file(args.out, "table"))
    table = study_table(args.name, given, args.executor, args.workers, args.max_seconds)
    print(table.text())
    if args.out:
        meta = {**metadata(), "study": args.name, "set": given}
        print(f"table written to {save_run(table.data, Path(args.out), meta)}")


def _run(args: argparse.Namespace) -> None:
    from lawbench.studies.grid import RunSpec
    from lawbench.studies.runfile import file_format
    from lawbench.studies.runner import estimate_seconds, run

    spec = RunSpec.from_toml(Path(args.spec)) if args.spec else None
    inline = _inline_spec(args)
    if spec is not None and inline is not None:
        raise InvalidProblem("run: give a spec file or --laws/--cases/--param/--set, not both")
    spec = spec or inline
    if spec is None:
        raise InvalidProblem("run: give a spec file or --laws/--cases/--param")
    out = output_file(args.out or f"results.{args.format or 'parquet'}", "run output")
    file_format(out, args.format)
    # Counted from the grid's sizes: a grid too large to run is refused before it is built.
    count = spec.count()
    print(f"run: {count} cell{'s' if count != 1 else ''}; {spec.describe()}", flush=True)
    if count > LARGE_GRID and not args.resume:
        workers = 1 if args.executor == "serial" else args.workers or os.cpu_count() or 1
        seconds = estimate_seconds(spec.plan(sample=ESTIMATE_CELLS), count, workers)
        about = f"about {_duration(seconds)} on {workers} worker{'s' if workers != 1 else ''}"
        print(f"run: {count} cells, {about} ({ESTIMATE_CELLS} cells timed)", flush=True)
        if not args.yes:
            raise InvalidProblem(
                f"run: a grid of {count} cells (more than {LARGE_GRID}), {about}: "
                "give --yes to run it"
            )
    table, computed = run(
        spec.plan(),
        out,
        args.executor,
        args.address,
        args.resume,
        args.chunk_size,
        args.workers,
        args.max_seconds,
        wait=args.wait,
        quiet=args.quiet,
        seed=spec.seed,
    )
    if args.resume and computed == 0:
        print(f"{out} is complete: {len(table)} rows, nothing left to compute")
        return
    failed = int((table["error_class"].fillna("") != "").sum()) if len(table) else 0
    rows = f"{len(table)} row{'s' if len(table) != 1 else ''}"
    print(f"{rows} in {out} ({computed} computed now, {failed} failed)")


def _duration(seconds: float) -> str:
    """A duration in the unit a reader expects: seconds, minutes or hours."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _inline_spec(args: argparse.Namespace) -> object:
    from lawbench.studies.grid import RunSpec, parse_values

    if args.laws is None and args.cases is None and not (args.param or args.option):
        return None
    params = {
        name: parse_values(name, text) for name, text in _assignments(args.param, "--param").items()
    }
    laws = _names(args.laws, "--laws", LAWS) or ["*"]
    options: dict[str, dict[str, list]] = {}
    for name, text in _assignments(args.option, "--option").items():
        law, dot, option = name.rpartition(".")
        targets = [law] if dot else laws
        if targets == ["*"]:
            raise InvalidProblem(f"--option {name}: name the laws (--laws), or give LAW.{name}")
        for target in targets:
            options.setdefault(target, {})[option] = parse_values(name, text, "--option")
    grid = {
        "laws": laws,
        "cases": _names(args.cases, "--cases", CASES) or ["*"],
        "params": params,
        "options": options,
    }
    return RunSpec.from_dict({"grid": [grid], "seed": args.seed})


def _bench(args: argparse.Namespace) -> None:
    if args.problems is None:
        from lawbench.studies.bench import report

        print(report(quick=args.quick))
        return
    from lawbench.studies.bench import (
        SOLVED_FC3D,
        bench_problems,
        performance_profiles,
        problems_summary,
    )

    out = output_file(args.out, "bench table")
    if out.suffix.lower() != ".csv":
        raise InvalidProblem(f"bench --out {args.out}: the table is CSV (.csv)")
    laws = _names(args.laws, "--laws", LAWS)
    tol = SOLVED_FC3D if args.tol is None else args.tol
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InvalidProblem(f"bench --out {args.out}: cannot be written ({exc})") from None
    table, notes = bench_problems(
        args.problems,
        args.max_seconds,
        None if laws == ["*"] else laws,
        tol,
        args.peer_tol,
    )
    with out.open("w", encoding="utf-8") as handle:
        handle.writelines(f"# {note}\n" for note in notes)
        table.to_csv(handle, index=False)
    from lawbench.views.plotting import plot_profiles

    figure = out.with_suffix(".png")
    plot_profiles(performance_profiles(table, tol)).figure.savefig(figure, dpi=120)
    print(problems_summary(table, notes, tol))
    print(f"table written to {out}, performance profiles to {figure}")


def _regress(args: argparse.Namespace) -> None:
    from lawbench.studies.baselines import NEW_ROW, regress

    laws = _names(args.laws, "--laws", LAWS)
    cases = _names(args.cases, "--cases", CASES)
    drift = regress(laws, cases, update=args.update)
    if args.update:
        print(f"baselines rewritten; {len(drift)} quantities changed")
        if len(drift):
            print(drift.to_string(index=False, float_format=lambda x: f"{x:.3g}"))
        return
    new = drift["baseline"] == NEW_ROW if len(drift) else []
    if len(drift) and new.any():
        # A law or scene added since the baselines were written has no baseline yet: not drift.
        pairs = sorted({f"{r.law} on {r.case}" for r in drift[new].itertuples()})
        print(f"no baseline yet for {', '.join(pairs)} (lawbench regress --update writes it)")
        drift = drift[~new]
    if len(drift):
        print(drift.to_string(index=False, float_format=lambda x: f"{x:.3g}"))
        raise Drift(f"regress: {len(drift)} quantities drifted past their tolerance")
    print("regress: every law holds its baseline")


def _fit(args: argparse.Namespace) -> None:
    from lawbench.studies.fitting import fit

    laws = [name.strip() for name in args.law.split(",") if name.strip()]
    if not laws:
        raise InvalidProblem("fit: give a law (or several, comma-separated)")
    start = _assignments(args.start, "--start")
    results = [
        fit(
            law,
            args.case,
            args.data,
            free=args.free.split(","),
            params=_assignments(args.set, "--set"),
            options=_assignments(args.option, "--option") if len(laws) == 1 else None,
            start=start,
            noise=args.noise,
            holdout=args.holdout,
            bootstrap=args.bootstrap,
            seed=args.seed,
        )
        for law in laws
    ]
    if args.json:
        print(json.dumps([r.to_dict() for r in results], indent=1, allow_nan=False))
        return
    print("\n\n".join(r.text() for r in results))
    if len(results) > 1 and args.holdout:
        print("\nlaws on the held-back trials (rms residual, best first):")
        for r in sorted(results, key=lambda r: r.holdout_rms or 0.0):
            print(f"  {r.law:<16}{r.holdout_rms:.4g}")


def _executor_arguments(parser: argparse.ArgumentParser, default: str) -> None:
    """The options of the commands that run many cells: executor, workers, guard."""
    parser.add_argument("--executor", choices=EXECUTORS, default=default)
    parser.add_argument(
        "--workers",
        type=_count(1, MAX_WORKERS),
        help=f"worker processes, at most {MAX_WORKERS} (default: one per core)",
    )
    parser.add_argument(
        "--max-seconds",
        type=_seconds,
        default=BUDGET_S,
        help=f"wall-clock guard of one cell, in seconds (default {BUDGET_S:g})",
    )


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``lawbench`` command."""
    parser = _Parser(prog="lawbench", description="Compare impact laws on shared scenes.")
    parser.add_argument("--version", action=_Version, help="print the version and exit")
    parser.add_argument(
        "--verbose",
        action="store_true",
        help="print the warnings of the numerical libraries (a solve keeps its own in its "
        "diagnostics)",
    )
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    commands.add_parser("list", help="list the laws and cases").set_defaults(run=_list)
    describe = commands.add_parser("describe", help="describe a law or a case")
    describe.add_argument("name", help="a law or case name")
    describe.set_defaults(run=_describe)
    solve = commands.add_parser("solve", help="solve one case (or a problem file) with one law")
    solve.add_argument("law")
    solve.add_argument("case", nargs="?", help="a scene name (or give --problem FILE)")
    solve.add_argument(
        "--problem",
        type=_path,
        metavar="FILE",
        help="a problem file (.json, .npz, .h5): see lawbench export",
    )
    solve.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a case parameter; a comma-separated value is a list",
    )
    solve.add_argument(
        "--option", action="append", default=[], metavar="NAME=VALUE", help="a law option"
    )
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
    solve.set_defaults(run=_solve)
    export = commands.add_parser("export", help="write a scene's problem to a file")
    export.add_argument("case")
    export.add_argument(
        "--set", action="append", default=[], metavar="NAME=VALUE", help="a case parameter"
    )
    export.add_argument(
        "-o",
        "--out",
        type=_path,
        required=True,
        metavar="FILE",
        help="the file: .json, .npz, .h5 or .hdf5",
    )
    export.add_argument(
        "--fclib",
        choices=("local", "global"),
        help="write an FCLIB problem (HDF5) in its local or global form instead",
    )
    export.set_defaults(run=_export)
    report = commands.add_parser("report", help="write the comparison report")
    report.add_argument("--out", type=_path, default="reports/latest", help="output folder")
    size = report.add_mutually_exclusive_group()
    size.add_argument(
        "--quick",
        dest="mode",
        action="store_const",
        const="quick",
        help="the default: every section, small grids (minutes)",
    )
    size.add_argument(
        "--full",
        dest="mode",
        action="store_const",
        const="full",
        help="the large grids, through the run machinery (resumable)",
    )
    report.set_defaults(mode="quick")
    report.set_defaults(run=_report)
    study = commands.add_parser(
        "study", aliases=["table"], help="run one study and print its table (table: the same)"
    )
    study.add_argument("name", nargs="?", help="a study (lawbench study --list)")
    study.add_argument("--list", action="store_true", help="list the studies with their titles")
    study.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="fix a scene parameter (a swept one is no longer swept)",
    )
    study.add_argument(
        "--out",
        type=_path,
        metavar="FILE",
        help="write the whole table to FILE as lawbench run does (.parquet, .csv or .feather)",
    )
    _executor_arguments(study, "serial")
    study.set_defaults(run=_study)
    run = commands.add_parser(
        "run",
        help="run a grid of laws x cases x parameters",
        description="Run a grid of laws x cases x parameters x options into one tidy table. "
        "The grid comes from a TOML run file (see README) or from --laws/--cases/--param/--set; "
        "the first line printed is the grid as read. "
        "Grid points: --param e=0,0.5,1 is three rows; a per-contact vector: "
        '--param "e=[0.9,0.8]" is one row.',
    )
    run.add_argument("spec", nargs="?", type=_path, help="a TOML run specification")
    run.add_argument("--laws", help="comma-separated laws (default: every law that applies)")
    run.add_argument("--cases", help="comma-separated cases (default: every case)")
    run.add_argument(
        "--param",
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUES",
        help="a case parameter's grid points (--set as in solve): commas separate points "
        "(e=0,0.5,1 is three rows), brackets make one per-contact vector (e=[0.9,0.8] is one "
        "row; e=[0.9,0.8],[1,1] two)",
    )
    run.add_argument(
        "--option",
        action="append",
        default=[],
        metavar="NAME=VALUES",
        help="a law option for every law of --laws (LAW.NAME for one law), with the grid "
        "spelling of --param (tol=1e-6,1e-10 is two rows)",
    )
    run.add_argument("--seed", type=_count(0, 2**32 - 1), default=0, help="seed of random samples")
    run.add_argument(
        "--out",
        type=_path,
        help="output file: .parquet, .csv or .feather (default results.parquet)",
    )
    run.add_argument(
        "--format",
        choices=("parquet", "csv", "feather"),
        help="the table format; the extension of --out decides, and this must agree",
    )
    _executor_arguments(run, "processes")
    run.add_argument("--address", help="address of a Dask scheduler (default: a local cluster)")
    run.add_argument("--resume", action="store_true", help="compute only the missing rows")
    run.add_argument(
        "--wait", action="store_true", help="wait for another run holding --out's lock to end"
    )
    run.add_argument(
        "--yes", action="store_true", help=f"run a grid of more than {LARGE_GRID} cells"
    )
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument(
        "--chunk-size",
        type=_count(1, MAX_REPEATS),
        default=50,
        help="rows written per chunk file",
    )
    run.set_defaults(run=_run)
    regress = commands.add_parser("regress", help="compare every law with its baseline")
    regress.add_argument("--update", action="store_true", help="rewrite the baselines")
    regress.add_argument("--laws", help="comma-separated laws")
    regress.add_argument("--cases", help="comma-separated cases")
    regress.set_defaults(run=_regress)
    check = commands.add_parser(
        "check", help="hold a law to the common checks (exit 6 when a cell is not acceptable)"
    )
    check.add_argument("law", help="a law name, or module:attribute of a law not registered")
    check.add_argument("--cases", help="comma-separated scenes (default: every one it treats)")
    check.add_argument(
        "--random",
        type=_count(0, MAX_REPEATS),
        default=3,
        help=f"seeded random problems (3; at most {MAX_REPEATS})",
    )
    check.add_argument("--json", action="store_true", help="print the table as JSON records")
    check.set_defaults(run=_check)
    fitp = commands.add_parser(
        "fit", help="identify a law's coefficients from measured pre/post-impact velocities"
    )
    fitp.add_argument("law", help="a law, or several comma-separated to compare them")
    fitp.add_argument("case", help="the scene of the experiment")
    fitp.add_argument(
        "--data",
        type=_path,
        required=True,
        metavar="CSV",
        help="one row per trial; columns COORD_minus and COORD_plus per coordinate (v1_minus,...)",
    )
    fitp.add_argument(
        "--free",
        required=True,
        metavar="NAMES",
        help="comma-separated coefficients to fit: a parameter (e, mu, stiffness_ratio) or one "
        "entry of a list (e[1])",
    )
    fitp.add_argument(
        "--set", action="append", default=[], metavar="NAME=VALUE", help="a fixed parameter"
    )
    fitp.add_argument(
        "--option", action="append", default=[], metavar="NAME=VALUE", help="a law option"
    )
    fitp.add_argument(
        "--start",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a starting value, in the parameter's range",
    )
    fitp.add_argument(
        "--noise",
        type=float,
        help="standard deviation of a measured velocity, in [1e-12, 1e6] (judges the fit)",
    )
    fitp.add_argument(
        "--holdout", type=_fraction, default=0.0, metavar="FRACTION", help="trials held back"
    )
    fitp.add_argument(
        "--bootstrap",
        type=_count(0, MAX_REPEATS),
        default=0,
        metavar="N",
        help=f"bootstrap refits (at most {MAX_REPEATS})",
    )
    fitp.add_argument(
        "--seed",
        type=_count(0, 2**32 - 1),
        default=0,
        help="seed of the holdout and bootstrap",
    )
    fitp.add_argument("--json", action="store_true", help="print the results as JSON")
    fitp.set_defaults(run=_fit)
    bench = commands.add_parser(
        "bench", help="time the laws against clarabel and numpy called directly (ratios)"
    )
    bench.add_argument("--quick", action="store_true", help="fewer repetitions, smaller sizes")
    bench.add_argument(
        "--problems",
        type=_path,
        metavar="DIR",
        help="instead: solve every problem file in DIR (FCLIB .hdf5/.h5, lawbench .json/.npz/.h5) "
        "with every law and method, into a CSV table and performance profiles",
    )
    bench.add_argument("--laws", help="with --problems: comma-separated laws (default: every law)")
    bench.add_argument(
        "--out",
        type=_path,
        default="bench-problems.csv",
        metavar="FILE",
        help="with --problems: the CSV table; the profiles go beside it as a .png",
    )
    bench.add_argument(
        "--max-seconds",
        type=_seconds,
        default=PROBLEM_BUDGET_S,
        metavar="S",
        help=f"with --problems: budget of one law on one file (default {PROBLEM_BUDGET_S:g})",
    )
    bench.add_argument(
        "--tol",
        type=_tolerance,
        metavar="TOL",
        help="with --problems: every solver's tolerance, and the FC3D error a solved file has at "
        "most (default 1e-8, the threshold of Acary, Brémond and Huber's comparisons)",
    )
    bench.add_argument(
        "--peer-tol",
        type=_tolerance,
        metavar="TOL",
        help="with --problems: Siconos' tolerance, where it differs from --tol (the field often "
        "asks 1e-6)",
    )
    bench.set_defaults(run=_bench)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    # The run machinery reports damaged chunks through logging: one line on stderr each.
    logging.basicConfig(format="lawbench: %(message)s", level=logging.WARNING)
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exit_:  # usage errors and --help
        return int(exit_.code or 0)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            args.run(args)
        # What an export leaves out is always said; a library's warnings only when asked for.
        for warning in caught:
            if args.verbose or issubclass(warning.category, LossyExport):
                print(f"lawbench: warning: {warning.message}", file=sys.stderr)
    except LawbenchError as exc:
        print(f"lawbench: {_one_line(exc)}", file=sys.stderr)
        return next(code for kind, code in EXIT_CODES.items() if isinstance(exc, kind))
    except BrokenPipeError:
        return 0
    except KeyboardInterrupt:
        print(
            "lawbench: interrupted; finished rows are kept (rerun with --resume)", file=sys.stderr
        )
        return 130
    except Exception as exc:  # a bug: still one line, never a traceback
        print(f"lawbench: internal error: {type(exc).__name__}: {_one_line(exc)}", file=sys.stderr)
        return 1
    return 0


def _one_line(message: object) -> str:
    """``message`` on one line: a library's message or a path may hold line breaks."""
    return " ".join(line.strip() for line in str(message).splitlines() if line.strip())
