"""``lawbench study NAME`` (alias ``table``): one declared study and its table."""

from __future__ import annotations

import argparse
from pathlib import Path

from lawbench.core.errors import InvalidProblem
from lawbench.files.paths import output_file
from lawbench.studies.declared import STUDIES
from lawbench.views.cli.main import _assignments, _executor_arguments, _path, add_assignments

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = (
    "study",
    {"aliases": ["table"], "help": "run one study and print its table (table: the same)"},
)


def arguments(study: argparse.ArgumentParser) -> None:
    """The arguments of the ``study`` command."""
    study.add_argument("name", nargs="?", help="a study (lawbench study --list)")
    study.add_argument("--list", action="store_true", help="list the studies with their titles")
    add_assignments(study, "--set", help="fix a scene parameter (a swept one is no longer swept)")
    study.add_argument(
        "--out",
        type=_path,
        metavar="FILE",
        help="write the whole table to FILE as lawbench run does (.parquet, .csv or .feather)",
    )
    _executor_arguments(study, "serial")
    study.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """List the studies, or run one and print (and with ``--out`` write) its table."""
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
