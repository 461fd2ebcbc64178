"""How the bench times: best-of and alternated repetitions, and the peers called directly.

Each figure is the fastest of several repetitions (on a shared machine noise only ever adds
time, so the fastest is the steadiest figure of the code itself, as timeit advises). The peers
measured in this process are clarabel called directly on the impulses' QP (the LCP
``0 <= G z + q _|_ z >= 0`` as ``min z.G z / 2 + q.z, z >= 0``, sparse) and a plain numpy
enumeration of the same LCP's active sets.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import clarabel
import numpy as np
import scipy.sparse

from lawbench.bench.siconos_peer import fastest
from lawbench.numerics.solvers import clarabel_settings, enumerate_lcp


def best_time(function: Callable[[], Any], repeats: int, number: int = 1) -> float:
    """Fastest over ``repeats`` of the mean wall time of ``number`` calls, in seconds.

    Timed as the Siconos peer times its own calls, in whatever interpreter it runs.
    """
    return fastest(function, 0.0, repeats, number)


def alternated(
    measures: dict[str, Callable[[], float | None]], rounds: int
) -> dict[str, float | None]:
    """The fastest of each measure over ``rounds`` rounds that take every measure in turn.

    The machine's speed drifts within a run (the same pure-Python loop took 3.9 ms to 7.3 ms
    here): alternating lets both sides of a ratio meet it in the same states. A measure that
    fails (None) once is None.
    """
    best: dict[str, float | None] = dict.fromkeys(measures, math.inf)
    for _ in range(rounds):
        for name, measure in measures.items():
            seconds, so_far = measure(), best[name]
            best[name] = None if seconds is None or so_far is None else min(so_far, seconds)
    return best


def chain_arrays(balls: int, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """Masses, normal Jacobian and velocities of a free chain with every contact approaching."""
    masses = 10.0 ** rng.uniform(-1.0, 1.0, balls)
    Wn = np.zeros((balls, balls - 1))
    index = np.arange(balls - 1)
    Wn[index, index], Wn[index + 1, index] = -1.0, 1.0
    v = np.sort(rng.uniform(0.0, 1.0, balls))[::-1].copy()
    return np.diag(masses), Wn, v


def clarabel_direct(M: Any, Wn: Any, v: np.ndarray, e: float | np.ndarray) -> np.ndarray:
    """Moreau's frictionless impulses with clarabel, called directly on the sparse LCP's QP.

    ``M`` (diagonal) and ``Wn`` are numpy or scipy.sparse arrays; ``e`` is one restitution
    coefficient or one per contact.
    """
    Wn_sparse = scipy.sparse.csc_matrix(Wn)
    inverse_mass = scipy.sparse.diags(1.0 / M.diagonal())
    G = (Wn_sparse.T @ inverse_mass @ Wn_sparse).tocsc()
    q = (1.0 + e) * (Wn.T @ v)
    m = Wn.shape[1]
    solver = clarabel.DefaultSolver(
        scipy.sparse.triu(G).tocsc(),
        q,
        -scipy.sparse.identity(m, format="csc"),
        np.zeros(m),
        [clarabel.NonnegativeConeT(m)],
        clarabel_settings(1e-10, 200),
    )
    return np.array(solver.solve().x)


def numpy_enumeration(M: np.ndarray, Wn: np.ndarray, v: np.ndarray, e: float) -> np.ndarray:
    """The same impulses by plain active-set enumeration, with G and q built in numpy."""
    G = Wn.T @ np.linalg.solve(M, Wn)
    return enumerate_lcp(G, (1.0 + e) * (Wn.T @ v))[0]


def row(label: str, seconds: float, peers: dict[str, float]) -> str:
    """A figure's line: its label, its time and its ratio to each peer's time."""
    ratios = ", ".join(f"{seconds / t:.3g}x {name}" for name, t in peers.items())
    return f"  {label:<46}{duration(seconds):>12}   {ratios}"


def duration(seconds: float) -> str:
    """``seconds`` in the unit that reads best: us, ms or s."""
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} us"
    return f"{seconds * 1e3:.2f} ms" if seconds < 1 else f"{seconds:.2f} s"
