"""``lawbench bench``: the cost of an answer, as ratios against direct solver calls in one run.

Each figure is the fastest of several repetitions (on a shared machine noise only ever adds
time, so the fastest is the steadiest figure of the code itself, as timeit advises), measured in
this process (or as whole processes for the start-up figure), beside a peer measured in the
same run and timed the same way: clarabel called
directly on the same QP (the impulses' LCP as ``min z.G z / 2 + q.z, z >= 0``, sparse), a
plain numpy enumeration of the same LCP's active sets, and Siconos numerics' Lemke solver where
it is installed (``LAWBENCH_SICONOS_PYTHON``, default ``/usr/bin/python3`` with Debian's
python3-siconos). Ratios, not absolute times, are what
carry from one machine to another. This is a benchmark: nothing here asserts a time.

`bench_problems` (``lawbench bench --problems DIR``) is the other bench: every law, and each
method of a law with an option ``method``, on every problem file of a folder, one guarded row
each (file, contacts, law, method, status, FC3D error, seconds), with Dolan and Moré's (2002)
performance ratios (`performance_profiles`) and Siconos' NSGS as a peer where it is importable.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.util
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import clarabel
import numpy as np
import pandas as pd
import scipy.sparse

from lawbench.core.batch import ProblemBatch
from lawbench.core.case import CASES
from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.errors import BudgetExceeded, InvalidProblem, NotApplicable, SolverFailure
from lawbench.core.law import LAWS
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.registry import Registry
from lawbench.core.trial import solve_batch
from lawbench.files.fclib import fclib_form
from lawbench.numerics.chains import chain_problem
from lawbench.numerics.gauss_seidel import in_local_order
from lawbench.numerics.solvers import clarabel_settings, enumerate_lcp
from lawbench.studies.guard import TIME_OUT, WALL_CLOCK, Guard, Result, alarm

# The roles laws and scenes declare (``bench_roles``) to be the bench's subjects:
ROLES = {
    # the law whose impulses solve the frictionless LCP ``0 <= G z + q _|_ z >= 0`` that the
    # peers (clarabel, the numpy enumeration, Siconos' Lemke) solve;
    "lcp": "the law timed against the LCP peers",
    # the law and the scene of the small command whose start-up is timed.
    "start_up": "the law and scene of the timed start-up command",
}


def subject(registry: Registry, role: str) -> str:
    """The name of the first entry of ``registry`` (by name) that declares ``role``.

    Raises
    ------
    InvalidProblem
        When no entry declares it.
    """
    for name, entry in registry.items():
        if role in entry.bench_roles:
            return name
    raise InvalidProblem(f"no {registry.kind} declares the bench role {role!r} ({ROLES[role]})")


def start_up_command() -> tuple[str, ...]:
    """The small command whose start-up is timed: ``solve LAW SCENE`` of the start-up role."""
    return ("solve", subject(LAWS, "start_up"), subject(CASES, "start_up"))


# Chain lengths of the full report: the growth from 1,000 to 10,000 balls shows the cost per ball.
CHAINS = (100, 1000, 10_000)


# The integrating laws (those that restart at events: option ``max_events``) on elastic Hertz
# chains: sizes, the tolerance that keeps a 1000-ball chain's energy to 1e-9, and the
# wall-clock budget of one run.
INTEGRATING_SIZES, QUICK_INTEGRATING_SIZES = (100, 1000), (20, 40)
INTEGRATING_TOL, INTEGRATING_BUDGET_S = 1e-12, 120.0


def best_time(function: Callable[[], Any], repeats: int, number: int = 1) -> float:
    """Fastest over ``repeats`` of the mean wall time of ``number`` calls, in seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            function()
        times.append((time.perf_counter() - start) / number)
    return min(times)


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


def clarabel_direct(M: Any, Wn: Any, v: np.ndarray, e: float) -> np.ndarray:
    """Moreau's frictionless impulses with clarabel, called directly on the sparse LCP's QP.

    ``M`` (diagonal) and ``Wn`` are numpy or scipy.sparse arrays.
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


# Siconos numerics (the reference nonsmooth-mechanics library, C) is measured when the
# interpreter below imports it (Debian: python3-siconos): Lemke on the same chain's LCP (its
# matrix is dense), building its matrix and vector included, ``number`` calls at a time.
SICONOS_PYTHON = os.environ.get("LAWBENCH_SICONOS_PYTHON", "/usr/bin/python3")
SICONOS_SETUP = """
import numpy as np, siconos.numerics as sn
masses, v, e = np.array({masses}), np.array({v}), {e}
n = len(masses); index = np.arange(n - 1)
Wn = np.zeros((n, n - 1)); Wn[index, index] = -1.0; Wn[index + 1, index] = 1.0
def one():
    D = Wn.T @ (Wn / masses[:, None]); q = (1.0 + e) * (Wn.T @ v)
    z, w = np.zeros(n - 1), np.zeros(n - 1)
    sn.lcp_lexicolemke(sn.LCP(D, q), z, w, sn.SolverOptions(sn.SICONOS_LCP_LEMKE))
    return z
"""

# A pure-Python loop timed in two interpreters: a small impact is bound by the interpreter
# (its calls, not its arithmetic), so the ratio of the two times is the part of a ratio
# against Siconos that comes from running on another build of CPython.
PYTHON_LOOP_SETUP = """
def one():
    total = 0
    for i in range(100_000):
        total += i * i
    return total
"""

# How another interpreter times ``one()`` of a setup: the fastest of ``repeats`` means of
# ``number`` calls, after WARM_UP_S seconds of calls (timed at once, a fresh process ran a
# few thousand Lemke solves at two thirds of their steady speed here: 10 us instead of 6.6 us).
WARM_UP_S = 0.3
TIMED = """
import time
warm = time.perf_counter() + {warm_up}
while time.perf_counter() < warm: one()
times = []
for _ in range({repeats}):
    start = time.perf_counter()
    for _ in range({number}): one()
    times.append((time.perf_counter() - start) / {number})
print(min(times))
"""


def siconos_lemke(
    masses: np.ndarray, v: np.ndarray, repeats: int, number: int = 200, e: float = 0.9
) -> float | None:
    """Fastest seconds per Lemke solve of a free chain in Siconos numerics, or None if absent."""
    setup = SICONOS_SETUP.format(masses=masses.tolist(), v=v.tolist(), e=e)
    return _seconds_of_one(SICONOS_PYTHON, setup, repeats, number)


def python_loop(python: str, repeats: int) -> float | None:
    """Fastest seconds of a pure-Python loop in the interpreter ``python``, or None if absent."""
    return _seconds_of_one(python, PYTHON_LOOP_SETUP, repeats, 1)


def _seconds_of_one(python: str, setup: str, repeats: int, number: int) -> float | None:
    """Seconds per call of ``one()`` defined by ``setup``, timed by ``python``; None if it fails."""
    script = setup + TIMED.format(warm_up=WARM_UP_S, repeats=repeats, number=number)
    try:
        done = subprocess.run([python, "-c", script], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return float(done.stdout) if done.returncode == 0 else None


def _row(label: str, seconds: float, peers: dict[str, float]) -> str:
    ratios = ", ".join(f"{seconds / t:.3g}x {name}" for name, t in peers.items())
    return f"  {label:<46}{_time(seconds):>12}   {ratios}"


def _time(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} us"
    return f"{seconds * 1e3:.2f} ms" if seconds < 1 else f"{seconds:.2f} s"


def small_impact(repeats: int, rounds: int = 3) -> list[str]:
    """One three-ball impact of the ``lcp`` law: from a prebuilt problem, and from matrices.

    lawbench's two figures, Siconos' and the pure-Python loop in both interpreters are taken in
    ``rounds`` `alternated` rounds.
    """
    M, Wn, v = chain_arrays(3, np.random.default_rng(0))
    law = LAWS[subject(LAWS, "lcp")]
    problem = ImpactProblem.from_arrays(M, Wn, v, e=0.9)
    peers = {
        "clarabel direct": best_time(lambda: clarabel_direct(M, Wn, v, 0.9), repeats, 200),
        "numpy enumeration": best_time(lambda: numpy_enumeration(M, Wn, v, 0.9), repeats, 200),
    }
    measures: dict[str, Callable[[], float | None]] = {
        "prebuilt": lambda: best_time(lambda: law.resolve(problem), repeats, 1000),
        "built": lambda: best_time(
            lambda: law.resolve(ImpactProblem.from_arrays(M, Wn, v, e=0.9)), repeats, 1000
        ),
        "Siconos Lemke": lambda: siconos_lemke(np.diag(M), v, repeats, 1000),
        "loop here": lambda: python_loop(sys.executable, repeats),
        "loop there": lambda: python_loop(SICONOS_PYTHON, repeats),
    }
    best = alternated(measures, rounds)
    siconos = best["Siconos Lemke"]
    if siconos is not None:
        peers["Siconos Lemke"] = siconos
    lines = [
        f"one three-ball {law.name} impact (e = 0.9):",
        _row("lawbench, prebuilt problem", best["prebuilt"], peers),
        _row("lawbench, from matrices (problem built)", best["built"], peers),
        *(f"  {name:<46}{_time(t):>12}" for name, t in peers.items()),
    ]
    if siconos is None:
        return [*lines, "  Siconos numerics: not found (python3-siconos)"]
    ours, theirs = best["loop here"], best["loop there"]
    if ours is not None and theirs is not None:
        lines.append(
            f"  a pure-Python loop: {_time(ours)} in this interpreter (Python "
            f"{platform.python_version()}), {_time(theirs)} in Siconos' ({SICONOS_PYTHON}): "
            f"{ours / theirs:.2f}x"
        )
    return lines


def batch_of_impacts(size: int, repeats: int) -> list[str]:
    """A batch of random three-ball impacts against the one-by-one path and the peers."""
    rng = np.random.default_rng(1)
    masses = 10.0 ** rng.uniform(-1.0, 1.0, (size, 3))
    M = np.einsum("kn,nl->knl", masses, np.eye(3))
    _, Wn, _ = chain_arrays(3, rng)
    v = rng.normal(size=(size, 3))
    e = rng.uniform(0.0, 1.0, (size, 2))
    law = LAWS[subject(LAWS, "lcp")]
    whole = best_time(lambda: solve_batch(law, ProblemBatch(M, Wn, v, {"e": e})), repeats)
    sample = ProblemBatch(M[:200], Wn, v[:200], {"e": e[:200]})
    one_by_one = (
        best_time(lambda: [law.resolve(sample.problem(k)) for k in range(200)], repeats) / 200
    )
    peers = {
        "one by one": one_by_one,
        "clarabel direct": best_time(lambda: clarabel_direct(M[0], Wn, v[0], 0.9), repeats, 200),
    }
    siconos = siconos_lemke(masses[0], v[0], repeats)
    if siconos is not None:
        peers["Siconos Lemke one by one"] = siconos
    return [
        f"a batch of {size:,} random three-ball {law.name} impacts (validation included):",
        _row("lawbench solve_batch, per impact", whole / size, peers),
    ]


def long_chains(sizes: tuple[int, ...], repeats: int, siconos_up_to: int = 0) -> list[str]:
    """The ``lcp`` law on n-ball chains, built as the chain scenes build them (sparse when long).

    Against clarabel called directly on the sparse QP and, up to ``siconos_up_to`` balls,
    Siconos' Lemke on the dense LCP; the last line is the growth exponent of lawbench's time
    between the two longest chains.
    """
    law = LAWS[subject(LAWS, "lcp")]
    lines = [f"{law.name} on an n-ball chain (e = 0.5):"]
    times = []
    for balls in sizes:
        rng = np.random.default_rng(balls)
        masses = 10.0 ** rng.uniform(-1.0, 1.0, balls)
        v = np.sort(rng.uniform(0.0, 1.0, balls))[::-1].copy()
        ones = [1.0] * (balls - 1)
        pairs = [(i, i + 1) for i in range(balls - 1)]
        problem = chain_problem(masses, v, pairs, [0.5] * (balls - 1), ones, ones)
        peers = {
            "clarabel direct": best_time(
                lambda p=problem: clarabel_direct(p.M, p.Wn, p.v, 0.5), repeats
            )
        }
        siconos = siconos_lemke(masses, v, 3, 1, 0.5) if balls <= siconos_up_to else None
        if siconos is not None:
            peers["Siconos Lemke"] = siconos
        times.append(best_time(lambda p=problem: law.resolve(p), repeats))
        lines.append(_row(f"n = {balls}, prebuilt problem", times[-1], peers))
    if len(sizes) > 1:
        growth = np.log(times[-1] / times[-2]) / np.log(sizes[-1] / sizes[-2])
        lines.append(f"  time grows like n^{growth:.2f} from n = {sizes[-2]} to {sizes[-1]}")
    return lines


def integrating_chains(sizes: tuple[int, ...]) -> list[str]:
    """Each integrating law once on elastic n-ball Hertz chains, one ball striking the rest.

    The laws are the registered ones that restart at events (option ``max_events``), at
    tolerance ``INTEGRATING_TOL`` within ``INTEGRATING_BUDGET_S`` seconds. Each line gives
    the time, the relative energy error ``|T+ - T-| / T-`` (the exact answer keeps the energy),
    the integrator's steps, or the budget that ran out; the last line of a
    law, the growth exponent of its time.
    """
    laws = [law for law in LAWS.values() if any(spec.name == "max_events" for spec in law.options)]
    lines = ["integrating laws on an elastic n-ball Hertz chain (e = 1), one run each:"]
    for law in laws:
        times = []
        for balls in sizes:
            problem = _elastic_chain(balls)
            start = time.perf_counter()
            label = f"  {law.name}, n = {balls}, tol = {INTEGRATING_TOL:g}".ljust(48)
            try:
                outcome = law.resolve(
                    problem, tol=INTEGRATING_TOL, max_seconds=INTEGRATING_BUDGET_S
                )
            except SolverFailure as failure:
                lines.append(f"{label}{_time(time.perf_counter() - start):>12}   {failure}")
                break
            times.append(time.perf_counter() - start)
            error = abs(outcome.T_plus - outcome.T_minus) / outcome.T_minus
            lines.append(
                f"{label}{_time(times[-1]):>12}   energy error {error:.2g}, "
                f"{outcome.diagnostics['steps']} integrator steps"
            )
        if len(times) > 1:
            growth = np.log(times[-1] / times[0]) / np.log(sizes[-1] / sizes[0])
            lines.append(
                f"  {law.name}: time grows like n^{growth:.2f} from n = {sizes[0]} to {sizes[-1]}"
            )
    return lines


def _elastic_chain(balls: int) -> ImpactProblem:
    """Equal balls in contact with Hertz springs, e = 1; the first strikes the others at 1 m/s."""
    ones = [1.0] * (balls - 1)
    pairs = [(i, i + 1) for i in range(balls - 1)]
    velocities = [1.0] + [0.0] * (balls - 1)
    return chain_problem([1.0] * balls, velocities, pairs, ones, ones, [1.5] * (balls - 1))


def start_up(repeats: int) -> list[str]:
    """Whole-process time of the small command `start_up_command` against importing numpy.

    Both with their bytecode cached, as after a first run (in a temporary
    ``PYTHONPYCACHEPREFIX``, so that nothing is written beside the sources), and, when this
    environment sets ``PYTHONDONTWRITEBYTECODE``, as it runs them: every module that has no
    cached bytecode (an editable install's own) compiled at every start.
    """
    command = start_up_command()
    commands = {
        "lawbench": [sys.executable, "-m", "lawbench", *command],
        "numpy": [sys.executable, "-c", "import numpy"],
    }

    def pair(label: str, env: dict[str, str]) -> str:
        def timed(command: list[str]) -> Callable[[], float]:
            def run() -> None:
                subprocess.run(command, capture_output=True, check=True, env=env)

            run()  # a first run fills the cache
            return lambda: best_time(run, 1)

        best = alternated({name: timed(command) for name, command in commands.items()}, repeats)
        return _row(label, best["lawbench"], {'python -c "import numpy"': best["numpy"]})

    lines = [f"start-up, whole process, lawbench {' '.join(command)}:"]
    with tempfile.TemporaryDirectory() as cache:
        cached = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        lines.append(pair("bytecode cached", {**cached, "PYTHONPYCACHEPREFIX": cache}))
    if os.environ.get("PYTHONDONTWRITEBYTECODE"):
        lines.append(pair("no bytecode cache (PYTHONDONTWRITEBYTECODE)", dict(os.environ)))
    return lines


def report(quick: bool = False) -> str:
    """Every figure, as text."""
    repeats = 3 if quick else 7
    threads = {k: os.environ.get(k, "unset") for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")}
    lines = [
        f"lawbench bench on {os.cpu_count()} cores, {platform.machine()}, Python "
        f"{platform.python_version()}, numpy {np.__version__}, clarabel {clarabel.__version__}; "
        + ", ".join(f"{k}={v}" for k, v in threads.items()),
        *small_impact(repeats),
        *batch_of_impacts(10_000 if quick else 100_000, repeats),
        *(long_chains((100, 1000), repeats) if quick else long_chains(CHAINS, repeats, 1000)),
        *integrating_chains(QUICK_INTEGRATING_SIZES if quick else INTEGRATING_SIZES),
        *start_up(repeats),
    ]
    return "\n".join(lines)


# ``lawbench bench --problems DIR``: every law (and method) on every problem file of a folder.

# The extensions of the problem files read (`lawbench.files.problem_files.load_problem`).
PROBLEM_SUFFIXES = (".json", ".npz", ".h5", ".hdf5")
# A row solves its problem when its status is ok and, where it is measured, the FC3D error is
# at most the bench's tolerance (by default this one, the threshold of Acary, Brémond and
# Huber's comparisons).
SOLVED_FC3D = 1e-8
COLUMNS = ("file", "contacts", "law", "method", "status", "fc3d_error", "seconds", "error")
# The guard kills a worker that heeds neither its law's budget nor its alarm by this many times
# the budget, plus a grace (a file read, a loop in compiled code).
KILL_FACTOR, KILL_GRACE_S = 2.0, 2.0
# Step bounds of a bench row: the wall-clock budget decides.
MAX_STEPS = 10**9
# Siconos' NSGS as a peer: its sweeps at most.
SICONOS_SWEEPS = 100_000
PEER = ("siconos", "nsgs")
# The peer's times below this are Python's call overhead as much as the solver's: the ratios
# against the peer are summed up over the files where it takes longer.
PEER_MIN_S = 0.01


def problem_files(folder: str | Path) -> list[Path]:
    """The problem files of ``folder`` (by extension, `PROBLEM_SUFFIXES`), sorted by name.

    Raises
    ------
    InvalidProblem
        For a folder that does not exist or holds no problem file.
    """
    where = Path(folder)
    if not where.is_dir():
        raise InvalidProblem(f"bench --problems {folder}: no such folder")
    found = sorted(p for p in where.iterdir() if p.is_file() and p.suffix in PROBLEM_SUFFIXES)
    if not found:
        raise InvalidProblem(
            f"bench --problems {folder}: no problem file ({', '.join(PROBLEM_SUFFIXES)}) in it"
        )
    return found


def solvers(laws: Sequence[str] | None = None) -> list[tuple[str, str]]:
    """``(law, method)`` of every law of ``laws`` (default every registered one).

    A law with an option ``method`` gives one pair per choice, any other the method ''.
    """
    pairs = []
    for name in laws or LAWS.names():
        methods = [s.choices for s in LAWS[name].options if s.name == "method" and s.choices]
        pairs += [(name, method) for method in (methods[0] if methods else ("",))]
    return pairs


def siconos_available() -> bool:
    """Whether the ``siconos`` package (Siconos numerics' Python interface) is importable."""
    return importlib.util.find_spec("siconos") is not None


def status_of(error: BaseException) -> str:
    """The status of a row whose solve raised ``error``."""
    if isinstance(error, NotApplicable):
        return "not applicable"
    if isinstance(error, BudgetExceeded):
        return "budget"
    if isinstance(error, SolverFailure):
        return "solver failure"
    return "error"


@functools.lru_cache(maxsize=1)
def _loaded(path: str) -> ImpactProblem | ContactProblem:
    """The problem of ``path``, read once per worker for all the laws solved on it."""
    from lawbench.files.problem_files import load_problem

    return load_problem(path)


@functools.cache
def _warmed(law: str, method: str) -> None:
    """Solve a one-contact problem once per worker with ``law`` and ``method``, untimed.

    A compiled kernel (numba) is loaded on its first call: that start-up belongs to no file.
    """
    with contextlib.suppress(Exception):
        _solve(ContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), [0.3]), law, method, 1.0)


def solve_file(
    path: str, law: str, method: str, seconds: float, tol: float = SOLVED_FC3D
) -> dict[str, Any]:
    """The row of ``law`` (with ``method``, '' for none) on the problem file ``path``.

    The law gets ``seconds`` as its ``max_seconds`` and ``tol`` as its ``tol`` where it has
    one, under an `alarm` of as many seconds, and its whole call is timed (the peer's time is
    its solver call alone, `siconos_nsgs`); its step bounds are lifted to `MAX_STEPS`, so that
    time alone decides. A local FCLIB file is solved in contact space (`Law.solve_contact`),
    any other problem as an impact. Never raises: a failure is the row's status and error.
    """
    from lawbench.files.problem_files import file_diagnostics

    row: dict[str, Any] = dict.fromkeys(COLUMNS, math.nan)
    row.update(file=Path(path).name, law=law, method=method, status="ok", error="")
    try:
        problem = _loaded(path)
        row["contacts"] = problem.m
        _warmed(law, method)
        with alarm(seconds):
            start = time.perf_counter()
            answer = _solve(problem, law, method, seconds, tol, path)
            row["seconds"] = time.perf_counter() - start
        if (law, method) == PEER:
            row["seconds"] = answer.diagnostics["wall_time_s"]
        if isinstance(answer, ContactSolution):
            row["fc3d_error"] = answer.fc3d_error
        else:
            row["fc3d_error"] = file_diagnostics(path, answer).get("fc3d_error", math.nan)
    except Exception as exc:  # a row records its failure and the bench goes on
        row["status"], row["error"] = status_of(exc), f"{type(exc).__name__}: {exc}"
    return row


def _solve(
    problem: ImpactProblem | ContactProblem,
    law: str,
    method: str,
    seconds: float,
    tol: float = SOLVED_FC3D,
    path: str = "",
) -> Outcome | ContactSolution:
    """``law`` (or the Siconos peer) on ``problem`` within ``seconds``, to ``tol``."""
    if (law, method) == PEER:
        return siconos_nsgs(problem, tol, path)
    specs = {spec.name for spec in LAWS[law].options}
    options: dict[str, Any] = {"max_seconds": seconds}
    if method:
        options["method"] = method
    if "max_steps" in specs:
        options["max_steps"] = MAX_STEPS
    if "tol" in specs:
        options["tol"] = tol
    if isinstance(problem, ContactProblem):
        return LAWS[law].solve_contact(problem, **options)
    return LAWS[law].resolve(problem, **options)


def siconos_nsgs(
    problem: ImpactProblem | ContactProblem, tol: float, path: str = ""
) -> ContactSolution:
    """Siconos numerics' ``fc3d_nsgs`` on the problem's local form, to ``tol``.

    A local FCLIB file is read by Siconos' own reader (its sparse block storage, as its users
    solve such files); a global one by Siconos' global reader and turned into its local form by
    Siconos' own reformulation; any other problem is given as its dense contact Delassus matrix
    and ``q = W.T v-`` in FCLIB's order. ``diagnostics['wall_time_s']`` is the ``fc3d_nsgs``
    call alone, the peer's time in the bench (a law's row times its whole call); the answer's
    FC3D error is measured here on the problem's own data.

    Raises
    ------
    NotApplicable
        For a problem without spatial friction.
    SolverFailure
        When Siconos reports that it did not converge within `SICONOS_SWEEPS` sweeps.
    """
    import siconos.numerics as sn

    local = _as_contact_problem(problem)
    if local is None:
        raise NotApplicable("siconos: fc3d_nsgs solves spatial frictional problems")
    form = fclib_form(path) if path else None
    if form == "local":
        fcp = sn.frictionContact_fclib_read(path)
    elif form == "global":
        fcp = sn.globalFrictionContact_reformulation_FrictionContact(
            sn.globalFrictionContact_fclib_read(path)
        )
    else:
        fcp = sn.FrictionContactProblem(
            3, local.m, np.asfortranarray(local.W.toarray()), np.array(local.q), local.mu
        )
    options = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS)
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = SICONOS_SWEEPS
    options.dparam[sn.SICONOS_DPARAM_TOL] = tol
    r, u = np.zeros(local.q.size), np.zeros(local.q.size)
    start = time.perf_counter()
    info = sn.fc3d_nsgs(fcp, r, u, options)
    seconds = time.perf_counter() - start
    if info:
        raise SolverFailure(
            f"siconos: fc3d_nsgs info {info} after {options.iparam[sn.SICONOS_IPARAM_ITER_DONE]} "
            f"sweeps, error {options.dparam[sn.SICONOS_DPARAM_RESIDU]:.3g}"
        )
    diagnostics = {"formulation": "siconos nsgs", "wall_time_s": seconds}
    return ContactSolution(r, local.velocity(r), local.error(r), diagnostics)


def _as_contact_problem(problem: ImpactProblem | ContactProblem) -> ContactProblem | None:
    """The spatial frictional problem in contact space, or None for any other."""
    if isinstance(problem, ContactProblem):
        return problem if problem.dim == 3 else None
    if not problem.frictional or problem.d != 2:
        return None
    W, q = in_local_order(problem.contact_delassus, problem.W.T @ problem.v, problem.m, 2)
    return ContactProblem(W, q, problem.mu, 3)


def bench_problems(
    folder: str | Path,
    seconds: float,
    laws: Sequence[str] | None = None,
    tol: float = SOLVED_FC3D,
    peer_tol: float | None = None,
) -> tuple[pd.DataFrame, list[str]]:
    """Every solver (`solvers`, and Siconos' NSGS where importable) on every file of ``folder``.

    One row per file x law x method (`COLUMNS`), each solved in a guarded worker process
    (`lawbench.studies.guard.Guard`, one at a time so that the times do not share the machine):
    a row that runs out of time is a ``budget`` row, a damaged file gives ``error`` rows, and
    neither stops the others. Every law with an option ``tol`` solves to ``tol``, the peer to
    ``peer_tol`` (default ``tol``); a row solves its file when its FC3D error is at most
    ``tol``. Returns the table and its notes.
    """
    files = problem_files(folder)
    pairs = solvers(laws)
    peer_tol = tol if peer_tol is None else peer_tol
    notes = [
        f"budget {seconds:g} s per file and solver; every solver asked for tol {tol:g}; solved: "
        f"status ok and FC3D error <= {tol:g} where the file defines it"
    ]
    if siconos_available():
        pairs.append(PEER)
        if peer_tol != tol:
            notes.append(f"Siconos' NSGS asked for tol {peer_tol:g}")
    else:
        notes.append("Siconos numerics (python package siconos) not available: no peer column")
    tasks = [(str(path), law, method) for path in files for law, method in pairs]
    kill = KILL_FACTOR * seconds + KILL_GRACE_S
    with Guard(1, kill) as guard:
        handles = {
            guard.submit(
                solve_file, *task, seconds, peer_tol if tuple(task[1:]) == PEER else tol
            ): task
            for task in tasks
        }
        rows = [_guarded_row(guard.result(h), task, kill) for h, task in handles.items()]
    return pd.DataFrame(rows, columns=list(COLUMNS)), notes


def _guarded_row(result: Result, task: tuple[str, str, str], kill_s: float) -> dict[str, Any]:
    """The row of a task: its own, or the guard's account of a worker it stopped or lost."""
    if result.status == "ok":
        return result.value
    path, law, method = task
    row: dict[str, Any] = dict.fromkeys(COLUMNS, math.nan)
    status = "budget" if result.status == TIME_OUT else "error"
    message = (
        f"{WALL_CLOCK}: no answer within {kill_s:g} s"
        if status == "budget"
        else (f"{result.error_class}: {result.error_message}")
    )
    row.update(file=Path(path).name, law=law, method=method, status=status, error=message)
    return row


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
        median = f", median {_time(done['seconds'].median())}" if len(done) else ""
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
