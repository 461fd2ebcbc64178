"""``lawbench check LAW``: a law held to the common checks (exit 6 when a cell fails)."""

from __future__ import annotations

import argparse
import sys

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem, NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.views.cli.main import MAX_REPEATS, CheckFailed, _count, _names

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = (
    "check",
    {"help": "hold a law to the common checks (exit 6 when a cell is not acceptable)"},
)


def arguments(check: argparse.ArgumentParser) -> None:
    """The arguments of the ``check`` command."""
    check.add_argument("law", help="a law name, or module:attribute of a law not registered")
    check.add_argument("--cases", help="comma-separated scenes (default: every one it treats)")
    check.add_argument(
        "--random",
        type=_count(0, MAX_REPEATS),
        default=3,
        help=f"seeded random problems (3; at most {MAX_REPEATS})",
    )
    check.add_argument("--json", action="store_true", help="print the table as JSON records")
    check.set_defaults(run=run, solves=True)


def run(args: argparse.Namespace) -> None:
    """Print the law's conformance table; raise `CheckFailed` when it does not pass.

    Every solve is bounded from outside (`lawbench.core.trial.make_trial`); a law stuck in
    native code past that bound ends the ``lawbench`` program (``solves``:
    `lawbench.views.cli.main`).
    """
    from lawbench.studies.conformance import check_law

    cases = _names(args.cases, "--cases", CASES)
    report = check_law(_law_object(args.law), cases=cases, random_problems=args.random)
    frame = report.to_frame()
    if frame.empty:
        given = f"the scenes {', '.join(cases)}" if cases else "every scene"
        raise NotApplicable(
            f"{report.law}: treats none of {given}, and no random problem was asked for: "
            "nothing to check"
        )
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


def _short(value: object) -> str:
    return "" if value is None or value != value else f"{value:.3g}"
