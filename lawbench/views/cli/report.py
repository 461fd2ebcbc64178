"""``lawbench report``: the comparison report, quick or from the large grids."""

from __future__ import annotations

import argparse

from lawbench.files.paths import writable_folder
from lawbench.views.cli.main import _path

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("report", {"help": "write the comparison report"})


def arguments(report: argparse.ArgumentParser) -> None:
    """The arguments of the ``report`` command."""
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
    report.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Write the report into ``--out``."""
    from lawbench.views.report import write_report

    # Known writable before the studies run, not after.
    path = write_report(writable_folder(args.out, "report folder"), mode=args.mode)
    print(f"report written to {path}")
