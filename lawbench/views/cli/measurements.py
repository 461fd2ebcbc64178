"""``lawbench measurements [SET]``: the sets of measured impacts, or one set's record."""

from __future__ import annotations

import argparse

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = (
    "measurements",
    {"help": "list the sets of measured impacts, or show one set's source, processing and check"},
)


def arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments of the ``measurements`` command."""
    parser.add_argument("set", nargs="?", help="a set name (lawbench measurements lists them)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """List the registered sets, or print one set's source, processing and self-consistency."""
    from lawbench.measurements import MEASUREMENTS

    if args.set is None:
        for measured in MEASUREMENTS.values():
            source = measured.source
            print(f"{measured.name:<10}{len(measured):>6} impacts  {measured.summary}")
            print(f"{'':<10}source:  {source.paper}")
            print(f"{'':<10}data:    {source.repository} @ {source.commit[:12]}")
            print(f"{'':<10}licence: {source.licence}")
        for name, reason in MEASUREMENTS.unavailable.items():
            print(f"not loaded: {name}: {reason}")
        return
    _describe(MEASUREMENTS.get(args.set))


def _describe(measured: object) -> None:
    """One set: what was measured, from where, how it was processed, and how consistent it is."""
    from lawbench.measurements import consistency

    source, processing = measured.source, measured.processing
    print(f"{measured.name}: {measured.summary}")
    print(f"  paper:       {source.paper}")
    print(f"  repository:  {source.repository} @ {source.commit}")
    print(f"  path:        {source.path}")
    print(f"  licence:     {source.licence}")
    print(f"  processing:  {processing.method}")
    dropped = ", ".join(f"{reason}: {count}" for reason, count in processing.dropped.items())
    print(f"  kept:        {processing.kept} (dropped: {dropped or 'none'})")
    if processing.corrected:
        print(f"  corrected:   {processing.corrected}")
    print(f"  split:       {len(measured.train)} to fit, {len(measured.test)} to judge")
    check = consistency(measured.impacts)
    print(
        f"  consistency: |M dv - W P| / |M dv| median {check.median:.3g}, 95th percentile "
        f"{check.p95:.3g}, {check.above} of {check.count} above {check.threshold:g}"
    )
