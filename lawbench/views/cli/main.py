"""The ``lawbench`` command line: its parser and dispatch, and what the commands share.

Argument types, options and errors are shared by the commands, one module each in this
package; their exit codes are in the package's docstring.
"""

from __future__ import annotations

import argparse
import importlib
import io
import logging
import os
import resource
import sys
import warnings
from collections.abc import Callable, Sequence

from lawbench.core.errors import (
    BudgetExceeded,
    InvalidProblem,
    LawbenchError,
    LossyExport,
    NotApplicable,
    SolverFailure,
)
from lawbench.core.guards import end_process_when_stuck, watch_interrupts
from lawbench.core.registry import Registry
from lawbench.files.paths import NO_ROOM
from lawbench.studies.guard import BUDGET_S, EXECUTORS
from lawbench.views.room import room_to_solve, unmappable


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


def add_assignments(
    parser: argparse.ArgumentParser, *flags: str, help: str, metavar: str = "NAME=VALUE"
) -> None:
    """Add the repeatable option ``flags`` whose values are ``NAME=VALUE`` assignments."""
    parser.add_argument(*flags, action="append", default=[], metavar=metavar, help=help)


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


def _workers_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """The option ``--workers``: ``what`` runs in that many processes (default one per core)."""
    parser.add_argument(
        "--workers",
        type=_count(1, MAX_WORKERS),
        help=f"{what}, at most {MAX_WORKERS} (default: one per core)",
    )


def _executor_arguments(parser: argparse.ArgumentParser, default: str) -> None:
    """The options of the commands that run many cells: executor, workers, guard."""
    parser.add_argument("--executor", choices=EXECUTORS, default=default)
    _workers_argument(parser, "worker processes")
    parser.add_argument(
        "--max-seconds",
        type=_seconds,
        default=BUDGET_S,
        help=f"wall-clock guard of one cell, in seconds (default {BUDGET_S:g})",
    )


# The subcommands in the order ``lawbench --help`` lists them. Each module holds its command's
# ``COMMAND`` (its name and parser settings), ``arguments`` and ``run``; the names are the
# modules' in this package.
# Commands that solve nothing, which need no room beyond the start's (`room_to_solve`).
NO_SOLVE = ("list", "describe", "export")
COMMANDS = (
    "listing",
    "describe",
    "solve",
    "export",
    "report",
    "study",
    "run",
    "regress",
    "check",
    "fit",
    "bench",
    "measurements",
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
    for module_name in COMMANDS:
        # Imported when the parser is built: the command modules import this one's helpers.
        module = importlib.import_module(f"{__package__}.{module_name}")
        name, settings = module.COMMAND
        subparser = commands.add_parser(name, **settings)
        if command is None or command in (name, *settings.get("aliases", ())):
            module.arguments(subparser)
    return parser


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option, if any."""
    return next((word for word in argv if not word.startswith("-")), None)


def main(argv: Sequence[str] | None = None, *, own_process: bool = False) -> int:
    """Run the command line; return the exit code.

    With ``own_process`` (the ``lawbench`` program), a command that solves ends the process
    when a law stays stuck in native code past its wall-clock bound; called as a function, a
    stuck law is left to the caller's own guard.

    The streams are handled as Python's command-line tools handle them: a character the
    terminal's encoding lacks (or a file name that is not UTF-8) is written escaped; a reader
    that closed the pipe ends the command quietly, exit 1 (Python's advice on SIGPIPE); an
    output that cannot be written (``> /dev/full``) is one line and exit 4; a closed stderr
    is not written to.
    """
    _escaping_streams()
    try:
        code = _main(argv, own_process)
        if sys.stdout is not None and not sys.stdout.closed:
            sys.stdout.flush()  # a full device fails here, not in the interpreter's exit
    except BrokenPipeError:
        _silence_stdout()
        return 1
    except OSError as exc:  # the standard output itself cannot be written
        _silence_stdout()
        return _os_error(exc)
    return code


def _os_error(exc: OSError) -> int:
    """Say what the system refused, in one line; exit 4 out of room, 2 for anything else."""
    where = f"{exc.filename}: " if exc.filename is not None else "the output: "
    _say(f"lawbench: {where}{exc.strerror or exc}")
    return 4 if exc.errno in NO_ROOM else 2


def _escaping_streams() -> None:
    """Standard output and error write what their encoding lacks as backslash escapes."""
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper):
            stream.reconfigure(errors="backslashreplace")


def _silence_stdout() -> None:
    """Point standard output at /dev/null: the interpreter's last flush must not fail again."""
    if sys.stdout is None:
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # a stream with no descriptor (a test's capture)
        pass
    finally:
        os.close(devnull)


def _say(line: str) -> None:
    """Write ``line`` on standard error, unless it is closed (``2>&-``) or cannot be written."""
    if sys.stderr is None:
        return
    try:
        print(line, file=sys.stderr, flush=True)
    except OSError:
        pass


def _main(argv: Sequence[str] | None, own_process: bool) -> int:
    """`main` without its handling of the standard streams."""
    # The run machinery reports damaged chunks through logging: one line on stderr each.
    logging.basicConfig(format="lawbench: %(message)s", level=logging.WARNING)
    watch_interrupts()
    try:
        argv = sys.argv[1:] if argv is None else list(argv)
        args = build_parser(_command(argv)).parse_args(argv)
    except SystemExit as exit_:  # usage errors and --help
        return int(exit_.code or 0)
    except MemoryError:
        return _out_of_memory()
    # Native libraries that run out of address space mid-solve abort, exit or hang; without an
    # address-space limit every mapping is granted and there is nothing to check.
    limited = resource.getrlimit(resource.RLIMIT_AS)[0] != resource.RLIM_INFINITY
    if limited and args.command not in NO_SOLVE:
        short = room_to_solve()
        if short:
            _say(f"lawbench: out of memory: {short}")
            return EXIT_CODES[SolverFailure]
    if own_process and getattr(args, "solves", False):
        # A command that solves: a law stuck in native code past its bound ends the process.
        end_process_when_stuck()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            args.run(args)
        # What an export leaves out is always said; a library's warnings only when asked for.
        for warning in caught:
            if args.verbose or issubclass(warning.category, LossyExport):
                _say(f"lawbench: warning: {warning.message}")
    except LawbenchError as exc:
        _say(f"lawbench: {_one_line(exc)}{_spent(exc)}")
        return next(code for kind, code in EXIT_CODES.items() if isinstance(exc, kind))
    except MemoryError:
        return _out_of_memory()
    except OSError as exc:
        if unmappable(exc):  # a library that the address space left cannot hold
            _say(f"lawbench: out of memory while loading a library ({_one_line(exc)})")
            return EXIT_CODES[SolverFailure]
        if isinstance(exc, BrokenPipeError) or exc.filename is None:
            raise  # the standard streams, which `main` handles
        return _os_error(exc)
    except KeyboardInterrupt:
        _say("lawbench: interrupted; finished rows are kept (rerun with --resume)")
        return 130
    except Exception as exc:  # a bug: still one line, never a traceback
        _say(f"lawbench: internal error: {type(exc).__name__}: {_one_line(exc)}")
        return 1
    return 0


def _spent(exc: LawbenchError) -> str:
    """`` after S s`` for a budget that ran out, whose message leaves the time out.

    The message itself stays deterministic: a run table groups its failed cells by message.
    """
    if isinstance(exc, BudgetExceeded) and exc.spent_s is not None:
        return f" after {exc.spent_s:.3g} s"
    return ""


def _out_of_memory() -> int:
    """One line and a solver failure's exit code: the work needed more memory than it got."""
    _say("lawbench: out of memory (MemoryError)")
    return EXIT_CODES[SolverFailure]


def _one_line(message: object) -> str:
    """``message`` on one line: a library's message or a path may hold line breaks."""
    return " ".join(line.strip() for line in str(message).splitlines() if line.strip())
