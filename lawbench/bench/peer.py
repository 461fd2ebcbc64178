"""Siconos numerics as the bench's peer: the interpreter that has it, and the calls to it.

Siconos is often installed for another interpreter than lawbench's (Debian's python3-siconos,
for ``/usr/bin/python3``): its solvers run in `lawbench.bench.siconos_peer`, a script started
by file path in that interpreter with JSON in and out. The interpreter is found once per
process (`siconos_python`): ``LAWBENCH_SICONOS_PYTHON`` when it is set, else the first of this
interpreter, the ``python3`` of each folder of ``PATH`` and ``/usr/bin/python3`` that imports
``siconos.numerics``. Every use of the peer (``bench``, ``bench --problems``, the tests) asks
`siconos_python`, so that they agree on whether Siconos is there.
"""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.errors import NotApplicable, SolverFailure
from lawbench.core.problem import ImpactProblem
from lawbench.files.fclib import fclib_form
from lawbench.numerics.gauss_seidel import in_local_order

PEER_SCRIPT = Path(__file__).with_name("siconos_peer.py")
# Seconds of calls before a timed peer measures (a fresh process ran a few thousand Lemke
# solves at two thirds of their steady speed here: 10 us instead of 6.6 us).
WARM_UP_S = 0.3
# The longest a probe or a timed Lemke or loop measure may take before it counts as failed.
PEER_LIMIT_S = 120.0
# Siconos' NSGS as a peer: its sweeps at most.
SICONOS_SWEEPS = 100_000


def ask(python: str, request: dict[str, Any], timeout: float | None) -> dict[str, Any]:
    """The peer's answer to ``request`` from the interpreter ``python``.

    Raises
    ------
    SolverFailure
        When the interpreter cannot be started, runs past ``timeout`` seconds or fails (the
        last line of its error).
    """
    try:
        done = subprocess.run(
            [python, str(PEER_SCRIPT)],
            input=json.dumps(request),
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise SolverFailure(f"siconos peer ({python}): {exc}") from None
    if done.returncode:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise SolverFailure(f"siconos peer ({python}): {last}")
    return json.loads(done.stdout)


def candidates() -> list[str]:
    """The interpreters to probe for Siconos, in order (`siconos_python`), each once."""
    given = os.environ.get("LAWBENCH_SICONOS_PYTHON")
    if given:
        return [given]
    folders = [d for d in os.environ.get("PATH", "").split(os.pathsep) if d]
    found: list[str] = []
    for python in (
        sys.executable,
        *(os.path.join(d, "python3") for d in folders),
        "/usr/bin/python3",
    ):
        # /bin is often a link to /usr/bin: one interpreter under two names is probed once.
        # The file itself is not resolved: a virtual environment's python links to another.
        where = os.path.join(os.path.realpath(os.path.dirname(python)), os.path.basename(python))
        if python and os.access(where, os.X_OK) and where not in found:
            found.append(where)
    return found


@functools.cache
def _probed() -> tuple[str, dict[str, Any]] | None:
    """The first interpreter of `candidates` that imports ``siconos.numerics``, and its probe."""
    for python in candidates():
        try:
            return python, ask(python, {"command": "probe"}, PEER_LIMIT_S)
        except SolverFailure:
            continue
    return None


def siconos_python() -> str | None:
    """The interpreter that imports ``siconos.numerics`` (`candidates`, probed once), or None."""
    probed = _probed()
    return None if probed is None else probed[0]


def siconos_reads_fclib() -> bool:
    """Whether the Siconos found was built with its FCLIB readers."""
    probed = _probed()
    return probed is not None and bool(probed[1]["fclib"])


def siconos_available() -> bool:
    """Whether an interpreter with Siconos numerics was found (`siconos_python`)."""
    return siconos_python() is not None


def timed_by(
    python: str | None, request: dict[str, Any], repeats: int, number: int
) -> float | None:
    """Fastest seconds per call of the peer's timed ``request`` in ``python``; None if it fails."""
    if python is None:
        return None
    timing = {"warm_up": WARM_UP_S, "repeats": repeats, "number": number}
    try:
        return float(ask(python, {**request, **timing}, PEER_LIMIT_S)["seconds"])
    except SolverFailure:
        return None


def siconos_lemke(
    masses: np.ndarray, v: np.ndarray, repeats: int, number: int = 200, e: float = 0.9
) -> float | None:
    """Fastest seconds per Lemke solve of a free chain in Siconos numerics, or None if absent.

    Its matrix (dense) and vector are built in every call, ``number`` calls at a time.
    """
    request = {"command": "lemke", "masses": masses.tolist(), "v": v.tolist(), "e": e}
    return timed_by(siconos_python(), request, repeats, number)


def python_loop(python: str | None, repeats: int) -> float | None:
    """Fastest seconds of a pure-Python loop in the interpreter ``python``, or None if absent."""
    return timed_by(python, {"command": "loop"}, repeats, 1)


def siconos_nsgs(
    problem: ImpactProblem | ContactProblem, tol: float, path: str = ""
) -> ContactSolution:
    """Siconos numerics' ``fc3d_nsgs`` on the problem's local form, to ``tol``.

    Where Siconos reads FCLIB (`siconos_reads_fclib`), a local FCLIB file is read by Siconos' own
    reader (its sparse block storage, as its users solve such files), a global one by Siconos'
    global reader and turned into its local form by Siconos' own reformulation; any other
    problem, and every problem where Siconos reads no FCLIB, is given as its dense contact
    Delassus matrix and ``q = W.T v-`` in FCLIB's order. ``diagnostics['wall_time_s']`` is the
    ``fc3d_nsgs`` call alone, the peer's time in the bench (a law's row times its whole call);
    the answer's FC3D error is measured here on the problem's own data.

    Raises
    ------
    NotApplicable
        For a problem without spatial friction, or where no interpreter has Siconos.
    SolverFailure
        When Siconos reports that it did not converge within `SICONOS_SWEEPS` sweeps.
    """
    local = _as_contact_problem(problem)
    if local is None:
        raise NotApplicable("siconos: fc3d_nsgs solves spatial frictional problems")
    python = siconos_python()
    if python is None:
        raise NotApplicable("siconos: no interpreter here imports siconos.numerics")
    form = fclib_form(path) if path and siconos_reads_fclib() else None
    request = {"command": "nsgs", "tol": tol, "sweeps": SICONOS_SWEEPS, "size": local.q.size}
    with tempfile.TemporaryDirectory() as folder:
        if form in ("local", "global"):
            request.update(fclib=str(Path(path).resolve()), form=form)
        else:
            arrays = Path(folder) / "problem.npz"
            np.savez(arrays, W=local.W.toarray(), q=np.asarray(local.q), mu=np.asarray(local.mu))
            request["arrays"] = str(arrays)
        found = ask(python, request, None)
    if found["info"]:
        raise SolverFailure(
            f"siconos: fc3d_nsgs info {found['info']} after {found['sweeps']} sweeps, error "
            f"{found['residual']:.3g}"
        )
    r = np.array(found["r"])
    diagnostics = {"formulation": "siconos nsgs", "wall_time_s": found["seconds"]}
    return ContactSolution(r, local.velocity(r), local.error(r), diagnostics)


def _as_contact_problem(problem: ImpactProblem | ContactProblem) -> ContactProblem | None:
    """The spatial frictional problem in contact space, or None for any other."""
    if isinstance(problem, ContactProblem):
        return problem if problem.dim == 3 else None
    if not problem.frictional or problem.d != 2:
        return None
    W, q = in_local_order(problem.contact_delassus, problem.W.T @ problem.v, problem.m, 2)
    return ContactProblem(W, q, problem.mu, 3)
