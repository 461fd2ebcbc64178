"""``lawbench fit LAW CASE --data CSV``: a law's coefficients from measured velocities."""

from __future__ import annotations

import argparse
import json

from lawbench.core.errors import InvalidProblem
from lawbench.views.cli.main import (
    MAX_REPEATS,
    _assignments,
    _count,
    _fraction,
    _path,
    add_assignments,
)

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = (
    "fit",
    {"help": "identify a law's coefficients from measured pre/post-impact velocities"},
)


def arguments(fitp: argparse.ArgumentParser) -> None:
    """The arguments of the ``fit`` command."""
    fitp.add_argument("law", help="a law, or several comma-separated to compare them")
    fitp.add_argument("case", help="the scene of the experiment")
    fitp.add_argument(
        "--data",
        type=_path,
        required=True,
        metavar="CSV",
        help="one row per trial; columns COORD_minus and COORD_plus per coordinate (v1_minus,...)",
    )
    fitp.add_argument(
        "--free",
        required=True,
        metavar="NAMES",
        help="comma-separated coefficients to fit: a parameter (e, mu, stiffness_ratio) or one "
        "entry of a list (e[1])",
    )
    add_assignments(fitp, "--set", help="a fixed parameter")
    add_assignments(fitp, "--option", help="a law option")
    add_assignments(fitp, "--start", help="a starting value, in the parameter's range")
    fitp.add_argument(
        "--noise",
        type=float,
        help="standard deviation of a measured velocity, in [1e-12, 1e6] (judges the fit)",
    )
    fitp.add_argument(
        "--holdout", type=_fraction, default=0.0, metavar="FRACTION", help="trials held back"
    )
    fitp.add_argument(
        "--bootstrap",
        type=_count(0, MAX_REPEATS),
        default=0,
        metavar="N",
        help=f"bootstrap refits (at most {MAX_REPEATS})",
    )
    fitp.add_argument(
        "--seed",
        type=_count(0, 2**32 - 1),
        default=0,
        help="seed of the holdout and bootstrap",
    )
    fitp.add_argument("--json", action="store_true", help="print the results as JSON")
    fitp.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Fit each law of ``args.law``; print the results, compared on held-back trials."""
    from lawbench.fitting import fit

    laws = [name.strip() for name in args.law.split(",") if name.strip()]
    if not laws:
        raise InvalidProblem("fit: give a law (or several, comma-separated)")
    start = _assignments(args.start, "--start")
    results = [
        fit(
            law,
            args.case,
            args.data,
            free=args.free.split(","),
            params=_assignments(args.set, "--set"),
            options=_assignments(args.option, "--option") if len(laws) == 1 else None,
            start=start,
            noise=args.noise,
            holdout=args.holdout,
            bootstrap=args.bootstrap,
            seed=args.seed,
        )
        for law in laws
    ]
    if args.json:
        print(json.dumps([r.to_dict() for r in results], indent=1, allow_nan=False))
        return
    print("\n\n".join(r.text() for r in results))
    if len(results) > 1 and args.holdout:
        print("\nlaws on the held-back trials (rms residual, best first):")
        for r in sorted(results, key=lambda r: r.holdout_rms or 0.0):
            print(f"  {r.law:<16}{r.holdout_rms:.4g}")
