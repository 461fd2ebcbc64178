"""Siconos numerics' solvers timed where they are installed: the bench's peer, run by path.

Siconos (the reference nonsmooth-mechanics library, C) is often installed for an interpreter
other than lawbench's (Debian's python3-siconos, for ``/usr/bin/python3``), so this module runs
as a script in that interpreter, ``python siconos_peer.py``, and imports numpy and siconos
only: lawbench need not be installed there. Run by path, it has its own folder at the head of
``sys.path``: no module of that folder may bear the name of one it imports (``siconos``). It
reads one JSON request on stdin and writes one JSON answer on stdout; its ``command`` is one of

- ``probe``: ``{"fclib"}``, whether Siconos reads FCLIB files (it is built without FCLIB
  when not), and the exit status says whether ``siconos.numerics`` imports;
- ``lemke``: ``{"seconds"}``, the fastest seconds per Lemke solve of a free chain's LCP
  (``masses``, ``v``, ``e``; its dense matrix and vector built in every call);
- ``loop``: ``{"seconds"}``, the fastest seconds of a pure-Python loop, the interpreter's own
  speed;
- ``nsgs``: ``{"r", "seconds", "info", "sweeps", "residual"}``, ``fc3d_nsgs`` to ``tol`` within
  ``sweeps`` sweeps on an FCLIB file (``fclib``, of ``form`` local or global, the global one
  turned into its local form by Siconos' own reformulation; only where Siconos reads FCLIB), or
  on the dense Delassus matrix, ``q`` and ``mu`` of an ``.npz`` file (``arrays``); ``seconds`` is
  the solver call alone.

numpy is imported where a command needs it, so that a probe where Siconos is missing costs
little more than the interpreter's start. ``lemke`` and ``loop`` take ``repeats`` means of
``number`` calls after ``warm_up`` seconds of calls (a fresh process runs its first few
thousand Lemke solves slower than its later ones).
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np


def fastest(one: Callable[[], object], warm_up: float, repeats: int, number: int) -> float:
    """Fastest over ``repeats`` of the mean seconds of ``number`` calls, after a warm-up."""
    warm = time.perf_counter() + warm_up
    while time.perf_counter() < warm:
        one()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            one()
        times.append((time.perf_counter() - start) / number)
    return min(times)


def lemke(masses: list[float], v: list[float], e: float) -> Callable[[], np.ndarray]:
    """One Lemke solve of the free chain's impulses, building its LCP as the call's first step."""
    import numpy as np
    import siconos.numerics as sn

    masses_, v_ = np.array(masses), np.array(v)
    n = len(masses_)
    index = np.arange(n - 1)
    Wn = np.zeros((n, n - 1))
    Wn[index, index], Wn[index + 1, index] = -1.0, 1.0

    def one() -> np.ndarray:
        D = Wn.T @ (Wn / masses_[:, None])
        q = (1.0 + e) * (Wn.T @ v_)
        z, w = np.zeros(n - 1), np.zeros(n - 1)
        sn.lcp_lexicolemke(sn.LCP(D, q), z, w, sn.SolverOptions(sn.SICONOS_LCP_LEMKE))
        return z

    return one


def loop() -> int:
    """A pure-Python loop: a small impact is bound by the interpreter's calls, as this is."""
    total = 0
    for i in range(100_000):
        total += i * i
    return total


def nsgs(request: dict[str, Any]) -> dict[str, Any]:
    """``fc3d_nsgs`` on the request's problem; the answer's impulses in Siconos' order."""
    import numpy as np
    import siconos.numerics as sn

    form = request.get("form")
    if form == "local":
        problem = sn.frictionContact_fclib_read(request["fclib"])
    elif form == "global":
        problem = sn.globalFrictionContact_reformulation_FrictionContact(
            sn.globalFrictionContact_fclib_read(request["fclib"])
        )
    else:
        with np.load(request["arrays"]) as arrays:
            W, q, mu = arrays["W"], arrays["q"], arrays["mu"]
        problem = sn.FrictionContactProblem(3, len(mu), np.asfortranarray(W), q, mu)
    options = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS)
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = request["sweeps"]
    options.dparam[sn.SICONOS_DPARAM_TOL] = request["tol"]
    r, u = np.zeros(request["size"]), np.zeros(request["size"])
    start = time.perf_counter()
    info = sn.fc3d_nsgs(problem, r, u, options)
    seconds = time.perf_counter() - start
    return {
        "r": r.tolist(),
        "seconds": seconds,
        "info": int(info),
        "sweeps": int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
        "residual": float(options.dparam[sn.SICONOS_DPARAM_RESIDU]),
    }


def reads_fclib(sn: Any) -> bool:
    """Whether Siconos numerics ``sn`` was built with its FCLIB readers."""
    return hasattr(sn, "frictionContact_fclib_read")


def answer(request: dict[str, Any]) -> dict[str, Any]:
    """The answer to one request (see the module's commands)."""
    command = request["command"]
    if command == "probe":
        import siconos.numerics as sn

        return {"fclib": reads_fclib(sn)}
    if command == "nsgs":
        return nsgs(request)
    if command == "lemke":
        one = lemke(request["masses"], request["v"], request["e"])
    elif command == "loop":
        one = loop
    else:
        raise ValueError(f"unknown command {command!r}")
    timing = (request["warm_up"], request["repeats"], request["number"])
    return {"seconds": fastest(one, *timing)}


if __name__ == "__main__":
    # Siconos' C code may print on the standard output: it goes to the standard error, and the
    # answer alone to the standard output, through a copy of it made first.
    out = os.fdopen(os.dup(sys.stdout.fileno()), "w")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
    json.dump(answer(json.load(sys.stdin)), out)
    out.close()
