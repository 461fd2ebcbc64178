"""``lawbench export CASE -o FILE``: a scene's problem in lawbench's format or FCLIB's."""

from __future__ import annotations

import argparse

from lawbench.core.case import CASES
from lawbench.views.cli.main import _assignments, _path, add_assignments

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("export", {"help": "write a scene's problem to a file"})


def arguments(export: argparse.ArgumentParser) -> None:
    """The arguments of the ``export`` command."""
    export.add_argument("case")
    add_assignments(export, "--set", help="a case parameter")
    export.add_argument(
        "-o",
        "--out",
        type=_path,
        required=True,
        metavar="FILE",
        help="the file: .json, .npz, .h5 or .hdf5",
    )
    export.add_argument(
        "--fclib",
        choices=("local", "global"),
        help="write an FCLIB problem (HDF5) in its local or global form instead",
    )
    export.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Build the scene and write its problem where ``--out`` says."""
    from lawbench.files.fclib import write_fclib
    from lawbench.files.problem_files import save_problem

    problem = CASES.get(args.case).build(**_assignments(args.set, "--set"))
    if args.fclib:
        path = write_fclib(problem, args.out, args.fclib)
    else:
        path = save_problem(problem, args.out)
    print(f"problem written to {path}")
