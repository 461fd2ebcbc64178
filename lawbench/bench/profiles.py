"""The summaries of ``lawbench bench --problems``: solved rows, performance profiles, peer ratios.

A row solves its problem when its status is ok and, where it is measured, its FC3D error is at
most the bench's tolerance; the profiles are Dolan and Moré's (2002) performance ratios.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from lawbench.bench.problems import PEER, SOLVED_FC3D
from lawbench.bench.timing import duration

# The peer's times below this are Python's call overhead as much as the solver's: the ratios
# against the peer are summed up over the files where it takes longer.
PEER_MIN_S = 0.01


def solved(table: pd.DataFrame, tol: float = SOLVED_FC3D) -> pd.Series:
    """Whether each row solved its problem: status ok, FC3D error at most ``tol``."""
    measured = table["fc3d_error"].notna()
    return (table["status"] == "ok") & (~measured | (table["fc3d_error"] <= tol))


def solver_label(law: str, method: str) -> str:
    """A solver's name in summaries and profiles: the law, and its method when it has one."""
    return f"{law} ({method})" if method else law


def performance_profiles(table: pd.DataFrame, tol: float = SOLVED_FC3D) -> dict[str, np.ndarray]:
    """Dolan and Moré's (2002) performance ratios, per solver sorted, one per problem.

    ``r_ps = t_ps / min_s t_ps`` with ``t_ps`` the seconds of solver s on problem p where it
    `solved` it (to ``tol``), infinite otherwise; the profile ``rho_s(tau)`` is the fraction of
    the ratios at most ``tau``, over the files that were read (a damaged file is no problem).
    Solvers that solve no problem are left out.
    """
    frame = table[table["contacts"].notna()].assign(
        solver=lambda f: [solver_label(*pair) for pair in zip(f["law"], f["method"], strict=True)],
        time=lambda f: np.where(solved(f, tol), f["seconds"], np.inf),
    )
    times = frame.pivot_table(index="file", columns="solver", values="time", aggfunc="min")
    best = times.min(axis=1)
    ratios = times.div(best.where(np.isfinite(best)), axis=0).fillna(np.inf)
    return {s: np.sort(ratios[s].to_numpy()) for s in ratios if np.isfinite(ratios[s]).any()}


def peer_ratios(table: pd.DataFrame, tol: float = SOLVED_FC3D) -> dict[str, pd.Series]:
    """Per solver, its time over the peer's on each file the peer solved in over `PEER_MIN_S`.

    The peer's file counts when its status is ok (it met the tolerance it was asked for); a
    solver that did not solve the file to ``tol`` has an infinite ratio there.
    """
    pairs = zip(table["law"], table["method"], strict=True)
    frame = table.assign(solver=[solver_label(*pair) for pair in pairs])
    peer = frame[(frame["solver"] == solver_label(*PEER)) & (frame["status"] == "ok")]
    peer_seconds = peer.set_index("file")["seconds"]
    peer_seconds = peer_seconds[peer_seconds > PEER_MIN_S]
    found = {}
    for name, rows in frame[frame["solver"] != solver_label(*PEER)].groupby("solver", sort=False):
        rows = rows.set_index("file").reindex(peer_seconds.index)
        seconds = np.where(solved(rows.reset_index(), tol), rows["seconds"], np.inf)
        found[name] = pd.Series(seconds / peer_seconds.to_numpy(), index=peer_seconds.index)
    return found


def problems_summary(table: pd.DataFrame, notes: list[str], tol: float = SOLVED_FC3D) -> str:
    """Per solver: the files solved, the median seconds of those and the ratios to the peer.

    The notes follow.
    """
    frame = table.assign(solved=solved(table, tol))
    lines = [f"{len(set(table['file']))} files, {len(table)} rows"]
    for (law, method), rows in frame.groupby(["law", "method"], sort=False):
        done = rows[rows["solved"]]
        median = f", median {duration(done['seconds'].median())}" if len(done) else ""
        statuses = ", ".join(f"{n} {s}" for s, n in rows["status"].value_counts().items())
        lines.append(
            f"  {solver_label(law, method):<28}solved {len(done)}/{len(rows)}{median} ({statuses})"
        )
    for name, ratios in peer_ratios(table, tol).items():
        if len(ratios):
            mean = math.exp(np.log(ratios).mean()) if np.isfinite(ratios).all() else math.inf
            lines.append(
                f"  {name} / siconos over {len(ratios)} files where siconos takes over "
                f"{PEER_MIN_S * 1e3:g} ms: largest {ratios.max():.3g} "
                f"({ratios.idxmax()}), geometric mean {mean:.3g}"
            )
    return "\n".join([*lines, *(f"note: {note}" for note in notes)])
