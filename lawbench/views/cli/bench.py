"""``lawbench bench``: the laws timed against their solvers, or on a folder of problem files."""

from __future__ import annotations

import argparse

from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.files.paths import output_file, replaced
from lawbench.views.cli.main import _names, _path, _seconds, _tolerance

# Seconds one law may spend on one file of ``lawbench bench --problems``.
PROBLEM_BUDGET_S = 60.0


# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("bench", {"help": "time the laws against clarabel and numpy called directly (ratios)"})


def arguments(bench: argparse.ArgumentParser) -> None:
    """The arguments of the ``bench`` command."""
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
    bench.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Print the timing report, or with ``--problems`` bench the folder's files."""
    if args.problems is None:
        from lawbench.bench import report

        print(report(quick=args.quick))
        return
    _bench_problems(args)


def _bench_problems(args: argparse.Namespace) -> None:
    """Every law on every file of ``--problems``: the CSV table and its performance profiles."""
    from lawbench.bench import (
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
    figure = out.with_suffix(".png")
    # Both files' temporaries are created before the work: a folder that cannot be written is
    # known before every law has run on every file.
    with replaced(out, "bench --out") as table_file, replaced(figure, "bench --out") as drawn:
        table, notes = bench_problems(
            args.problems,
            args.max_seconds,
            None if laws == ["*"] else laws,
            tol,
            args.peer_tol,
        )
        with table_file.open("w", encoding="utf-8") as handle:
            handle.writelines(f"# {note}\n" for note in notes)
            table.to_csv(handle, index=False)
        from lawbench.views.plotting import plot_profiles

        profiles = plot_profiles(performance_profiles(table, tol)).figure
        # A tight box keeps the legend, drawn right of the axes.
        profiles.savefig(drawn, dpi=120, format="png", bbox_inches="tight")
    print(problems_summary(table, notes, tol))
    print(f"table written to {out}, performance profiles to {figure}")
