"""``lawbench list``: the registered laws and cases, and those that failed to load."""

from __future__ import annotations

import argparse

from lawbench.core.case import CASES
from lawbench.core.law import LAWS

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("list", {"help": "list the laws and cases"})


def arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments of the ``list`` command."""
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Print each registry's entries with their summaries."""
    for registry in (LAWS, CASES):
        print(f"{registry.kind}s:")
        for entry in registry.values():
            print(f"  {entry.name:<16} {entry.summary}")
        if registry.unavailable:
            print(f"{registry.kind}s not loaded:")
            for name, reason in registry.unavailable.items():
                print(f"  {name:<16} {reason}")
