"""``lawbench run``: a grid of laws x cases x parameters x options into one tidy table."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.files.paths import output_file
from lawbench.views.cli.main import (
    MAX_REPEATS,
    _assignments,
    _count,
    _executor_arguments,
    _names,
    _path,
    add_assignments,
)

# Cells above which ``lawbench run`` asks for --yes.
LARGE_GRID = 10_000
# Cells of a large grid timed for the estimate of its duration.
ESTIMATE_CELLS = 3


# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = (
    "run",
    {
        "help": "run a grid of laws x cases x parameters",
        "description": "Run a grid of laws x cases x parameters x options into one tidy table. "
        "The grid comes from a TOML run file (see README) or from --laws/--cases/--param/--set; "
        "the first line printed is the grid as read. "
        "Grid points: --param e=0,0.5,1 is three rows; a per-contact vector: "
        '--param "e=[0.9,0.8]" is one row.',
    },
)


def arguments(run_: argparse.ArgumentParser) -> None:
    """The arguments of the ``run`` command."""
    run_.add_argument("spec", nargs="?", type=_path, help="a TOML run specification")
    run_.add_argument("--laws", help="comma-separated laws (default: every law that applies)")
    run_.add_argument("--cases", help="comma-separated cases (default: every case)")
    add_assignments(
        run_,
        "--param",
        "--set",
        metavar="NAME=VALUES",
        help="a case parameter's grid points (--set as in solve): commas separate points "
        "(e=0,0.5,1 is three rows), brackets make one per-contact vector (e=[0.9,0.8] is one "
        "row; e=[0.9,0.8],[1,1] two)",
    )
    add_assignments(
        run_,
        "--option",
        metavar="NAME=VALUES",
        help="a law option for every law of --laws (LAW.NAME for one law), with the grid "
        "spelling of --param (tol=1e-6,1e-10 is two rows)",
    )
    run_.add_argument("--seed", type=_count(0, 2**32 - 1), default=0, help="seed of random samples")
    _output_arguments(run_)
    run_.set_defaults(run=run)


def _output_arguments(run_: argparse.ArgumentParser) -> None:
    """Where the table goes, how the cells run, and how a run resumes or waits."""
    run_.add_argument(
        "--out",
        type=_path,
        help="output file: .parquet, .csv or .feather (default results.parquet)",
    )
    run_.add_argument(
        "--format",
        choices=("parquet", "csv", "feather"),
        help="the table format; the extension of --out decides, and this must agree",
    )
    _executor_arguments(run_, "processes")
    run_.add_argument("--address", help="address of a Dask scheduler (default: a local cluster)")
    run_.add_argument("--resume", action="store_true", help="compute only the missing rows")
    run_.add_argument(
        "--wait", action="store_true", help="wait for another run holding --out's lock to end"
    )
    run_.add_argument(
        "--yes", action="store_true", help=f"run a grid of more than {LARGE_GRID} cells"
    )
    run_.add_argument("--quiet", action="store_true", help="no progress bar")
    run_.add_argument(
        "--chunk-size",
        type=_count(1, MAX_REPEATS),
        default=50,
        help="rows written per chunk file",
    )


def run(args: argparse.Namespace) -> None:
    """Run the grid of the spec file or of the inline options, into ``--out``."""
    from lawbench.studies.grid import RunSpec
    from lawbench.studies.runfile import file_format
    from lawbench.studies.runner import run as run_grid

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
        _confirm_large(args, spec, count)
    start = time.perf_counter()
    table, computed = run_grid(
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
    errors = list(table["error_class"].fillna("")) if len(table) else []
    # A law that does not apply to a cell refused it; any other error is a failure.
    refused = errors.count("NotApplicable")
    failed = len(errors) - errors.count("") - refused
    rows = f"{len(table)} row{'s' if len(table) != 1 else ''}"
    print(
        f"{rows} in {out} ({computed} computed now, {refused} refused, {failed} failed)",
        flush=True,
    )
    # The time on stderr: the table and the lines above are the same in every run.
    seconds = time.perf_counter() - start
    rate = f", {computed / seconds:.3g} rows/s" if seconds > 0 else ""
    print(f"run: {computed} rows computed in {seconds:.3g} s{rate}", file=sys.stderr)


def _confirm_large(args: argparse.Namespace, spec: object, count: int) -> None:
    """Print the estimated duration of a large grid; refuse it without ``--yes``."""
    from lawbench.studies.runner import estimate_seconds

    workers = 1 if args.executor == "serial" else args.workers or os.cpu_count() or 1
    seconds = estimate_seconds(spec.plan(sample=ESTIMATE_CELLS), count, workers)
    about = f"about {_duration(seconds)} on {workers} worker{'s' if workers != 1 else ''}"
    print(f"run: {count} cells, {about} ({ESTIMATE_CELLS} cells timed)", flush=True)
    if not args.yes:
        raise InvalidProblem(
            f"run: a grid of {count} cells (more than {LARGE_GRID}), {about}: give --yes to run it"
        )


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
