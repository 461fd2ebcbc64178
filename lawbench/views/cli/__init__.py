"""The ``lawbench`` command line.

Exit codes: 0 done; 2 bad usage or invalid input; 3 the law does not apply; 4 solver failure;
5 a regression drifted past its baseline; 6 a law fails the common checks (``lawbench check``);
1 an unexpected internal error. Errors are one line
on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import logging
import sys
import warnings
from collections.abc import Sequence

from lawbench.core.errors import LawbenchError, LossyExport
from lawbench.views.cli import (
    bench,
    check,
    describe,
    export,
    fit,
    listing,
    measurements,
    regress,
    report,
    run,
    solve,
    study,
)
from lawbench.views.cli.common import EXIT_CODES, _Parser, _Version

# The subcommands in the order ``lawbench --help`` lists them. Each module holds its command's
# ``COMMAND`` (its name and parser settings), ``arguments`` and ``run``.
COMMANDS = (
    listing,
    describe,
    solve,
    export,
    report,
    study,
    run,
    regress,
    check,
    fit,
    bench,
    measurements,
)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``lawbench`` command.

    Every subcommand is listed; only ``command`` is given its arguments (every one when None),
    so that a command's run reads no other command's module.
    """
    parser = _Parser(prog="lawbench", description="Compare impact laws on shared scenes.")
    parser.add_argument("--version", action=_Version, help="print the version and exit")
    parser.add_argument(
        "--verbose",
        action="store_true",
        help="print the warnings of the numerical libraries (a solve keeps its own in its "
        "diagnostics)",
    )
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for module in COMMANDS:
        name, settings = module.COMMAND
        subparser = commands.add_parser(name, **settings)
        if command is None or command in (name, *settings.get("aliases", ())):
            module.arguments(subparser)
    return parser


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option, if any."""
    return next((word for word in argv if not word.startswith("-")), None)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    # The run machinery reports damaged chunks through logging: one line on stderr each.
    logging.basicConfig(format="lawbench: %(message)s", level=logging.WARNING)
    try:
        argv = sys.argv[1:] if argv is None else list(argv)
        args = build_parser(_command(argv)).parse_args(argv)
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
