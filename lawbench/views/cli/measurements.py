"""``lawbench measurements [SET]``: the sets of measured impacts, one set's record, or a study.

Without a study option the command lists the sets, or shows one set's source, processing and
self-consistency. With ``--study``, ``--laws``, ``--quick`` or ``--out`` it fits each law on
the set's training impacts, judges it with the baselines on the test impacts
(`lawbench.fitting.measured`), and prints the table ranked by held-out median error.
"""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

from lawbench.core.errors import InvalidProblem
from lawbench.views.cli.main import _path, _workers_argument

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = (
    "measurements",
    {
        "help": "list the sets of measured impacts, show one set, or fit the laws on its "
        "training impacts and rank them on its test impacts",
        "description": "Without a study option: list the sets, or show one set's source, "
        "processing and self-consistency. With --study, --laws, --quick or --out: fit each "
        "law's contact coefficients (the fields it declares) on the set's training half by "
        "least squares in the kinetic metric, judge it on the test half (relative kinetic "
        "error: median, 95% bootstrap interval, interquartile range), beside the published "
        "coefficients and two baselines (a ratio per coordinate, an affine map), and print "
        "the table ranked by held-out median error. A law that integrates the impact in time "
        "is fitted and judged on evenly spaced subsamples of the halves (columns fitted_on, "
        "judged_on).",
    },
)
# The columns the printed table shows of the study's table, with their headers and widths.
SHOWN = (
    ("common_error", "common", 9),
    ("median_error", "median", 9),
    ("ci_low", "ci 2.5%", 9),
    ("ci_high", "97.5%", 9),
    ("iqr", "iqr", 9),
    ("normal_error", "normal", 9),
    ("tangential_error", "tangent", 9),
    ("cost_s", "cost [s]", 9),
)


def arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments of the ``measurements`` command."""
    parser.add_argument("set", nargs="?", help="a set name (lawbench measurements lists them)")
    parser.add_argument(
        "--study", action="store_true", help="fit and judge every law on the set (the study)"
    )
    parser.add_argument(
        "--laws",
        nargs="+",
        metavar="LAW",
        help="the laws of the study, comma- or space-separated (default: every law)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="the study on 40 evenly spaced impacts of each half (fewer for the laws that "
        "integrate in time)",
    )
    _workers_argument(parser, "processes that study the laws side by side")
    parser.add_argument(
        "--out",
        type=_path,
        metavar="FILE",
        help="write the study's table to FILE: .csv, or .parquet (needs pyarrow)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """List the sets, print one set's record, or run and print the study on one set."""
    from lawbench.measurements import MEASUREMENTS

    if args.study or args.laws or args.quick or args.out or args.workers:
        _study(args)
        return
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


def _study(args: argparse.Namespace) -> None:
    """Run the study on ``args.set`` and print (and with ``--out`` write) its table."""
    from lawbench.core.law import LAWS
    from lawbench.fitting.measured import measured_study
    from lawbench.measurements import MEASUREMENTS

    if args.set is None:
        raise InvalidProblem("measurements: a study needs a set (lawbench measurements lists them)")
    measured = MEASUREMENTS.get(args.set)
    laws = None
    if args.laws:
        laws = [name.strip() for item in args.laws for name in item.split(",") if name.strip()]
        if not laws:
            raise InvalidProblem("measurements --laws: give law names")
        for name in laws:
            LAWS.get(name)
    out = _output(args.out) if args.out else None
    workers = args.workers or os.cpu_count() or 1
    study = measured_study(measured, laws, quick=args.quick, workers=workers)
    _print(study)
    if out is not None:
        _write(study.table, out)
        print(f"table written to {out}")


def _output(text: str) -> Path:
    """The output file, its format read from its suffix, checked before the study runs."""
    from lawbench.files.paths import output_file

    out = output_file(text, "measurements --out")
    if out.suffix not in (".csv", ".parquet"):
        raise InvalidProblem(f"measurements --out {text}: write a .csv or a .parquet file")
    if out.suffix == ".parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise InvalidProblem(
                f"measurements --out {text}: writing parquet needs pyarrow (pip install "
                "pyarrow); write a .csv file instead"
            ) from None
    return out


def _write(table: object, out: Path) -> None:
    """Write the tidy table as CSV or parquet, by the file's suffix."""
    if out.suffix == ".parquet":
        table.to_parquet(out, index=False)
    else:
        table.to_csv(out, index=False)


def _print(study: object) -> None:
    """The study's table, best first: the law, its coefficients, its errors and its cost."""
    table = study.table
    fields = [c[: -len("_se")] for c in table.columns if c.endswith("_se")]
    print(
        f"{study.set_name}: laws and baselines ranked by median relative kinetic error on the "
        f"{study.common_count} test impacts every row solved (common); median and its 95% "
        "interval on all the impacts each row judged"
    )
    header = f"{'rank':>4}  {'law':<31}{'coefficients':<16}{'fitted (+- std error)':<50}"
    print(header + "".join(f"{title:>{width}}" for _, title, width in SHOWN) + "  impacts")
    notes = []
    for rank, row in enumerate(table.itertuples(index=False), start=1):
        values = " ".join(
            _fitted(name, getattr(row, name), getattr(row, f"{name}_se"))
            for name in fields
            if not math.isnan(getattr(row, name))
        )
        cells = "".join(_cell(getattr(row, column), width) for column, _, width in SHOWN)
        print(
            f"{rank:>4}  {row.law:<31}{row.coefficients:<16}{values:<50}{cells}"
            f"  fitted on {row.fitted_on}; judged on {row.judged_on}"
        )
        if row.reason:
            notes.append(
                f"  {row.law} ({row.coefficients}): {row.refused} refused, "
                f"{row.failed} failed: {row.reason}"
            )
    if notes:
        print("refused or failed impacts:")
        print("\n".join(notes))


def _fitted(name: str, value: float, error: float) -> str:
    """A coefficient with its standard error where it has one (a fitted, not a published one)."""
    short = "eta0^2" if name == "tangential_stiffness_ratio" else name
    spread = "" if math.isnan(error) else f"+-{error:.2g}"
    return f"{short}={value:.3g}{spread}"


def _cell(value: float, width: int) -> str:
    """A number in ``width`` characters; an undefined one (NaN) as ``-``."""
    return " " + f"{'-' if math.isnan(value) else format(value, '.3g'):>{width - 1}}"


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
