"""``lawbench regress``: every law against its committed baseline (exit 5 on drift)."""

from __future__ import annotations

import argparse
import os

from lawbench.core.case import CASES
from lawbench.core.law import LAWS
from lawbench.views.cli.main import Drift, _names, _workers_argument

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("regress", {"help": "compare every law with its baseline"})


def arguments(regress: argparse.ArgumentParser) -> None:
    """The arguments of the ``regress`` command."""
    regress.add_argument("--update", action="store_true", help="rewrite the baselines")
    regress.add_argument("--laws", help="comma-separated laws")
    regress.add_argument("--cases", help="comma-separated cases")
    _workers_argument(regress, "processes that compute the baseline grid")
    regress.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Compare with (or with ``--update`` rewrite) the baselines; raise `Drift` on drift."""
    from lawbench.studies.baselines import NEW_ROW, regress

    laws = _names(args.laws, "--laws", LAWS)
    cases = _names(args.cases, "--cases", CASES)
    workers = args.workers or os.cpu_count() or 1
    drift = regress(laws, cases, update=args.update, workers=workers)
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
