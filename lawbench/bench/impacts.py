"""``lawbench bench``: the cost of an answer, as ratios against direct solver calls in one run.

Each figure is measured in this process (or as whole processes for the start-up figure) beside
a peer measured in the same run and timed the same way (`lawbench.bench.timing`): clarabel
called directly on the same QP, a plain numpy enumeration of the same LCP's active sets, and
Siconos numerics' Lemke solver where an interpreter here has it (`lawbench.bench.peer`).
Ratios, not absolute times, are what carry from one machine to another. This is a benchmark:
nothing here asserts a time.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from typing import Any

import clarabel
import numpy as np

from lawbench.bench.peer import python_loop, siconos_lemke, siconos_python
from lawbench.bench.roles import start_up_command, subject, subjects
from lawbench.bench.timing import (
    alternated,
    best_time,
    chain_arrays,
    clarabel_direct,
    duration,
    numpy_enumeration,
    row,
)
from lawbench.cases._chains import chain_problem
from lawbench.core.batch import ProblemBatch
from lawbench.core.case import CASES
from lawbench.core.errors import LawbenchError, SolverFailure
from lawbench.core.law import LAWS, Law
from lawbench.core.problem import ImpactProblem
from lawbench.core.trial import solve, solve_batch

# Chain lengths of the full report: the growth from 1,000 to 10,000 balls shows the cost per ball.
CHAINS = (100, 1000, 10_000)
# Balls of the long-chain scene solved from its parameters.
SCENE_CHAIN = 1000
# The integrating laws (those that restart at events: option ``max_events``) on elastic Hertz
# chains: sizes, the tolerance that keeps a 1000-ball chain's energy to 1e-9, and the
# wall-clock budget of one run.
INTEGRATING_SIZES, QUICK_INTEGRATING_SIZES = (100, 1000), (20, 40)
INTEGRATING_TOL, INTEGRATING_BUDGET_S = 1e-12, 120.0


def small_impact(repeats: int, rounds: int = 3) -> list[str]:
    """One three-ball impact of the ``lcp`` law: from a prebuilt problem, and from matrices.

    lawbench's two figures, Siconos' and the pure-Python loop in both interpreters are taken in
    ``rounds`` `alternated` rounds.
    """
    M, Wn, v = chain_arrays(3, np.random.default_rng(0))
    law = LAWS[subject(LAWS, "lcp")]
    problem = ImpactProblem.from_arrays(M, Wn, v, e=0.9)
    there = siconos_python()
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
        "loop there": lambda: python_loop(there, repeats),
    }
    best = alternated(measures, rounds)
    siconos = best["Siconos Lemke"]
    if siconos is not None:
        peers["Siconos Lemke"] = siconos
    lines = [
        f"one three-ball {law.name} impact (e = 0.9):",
        row("lawbench, prebuilt problem", best["prebuilt"], peers),
        row("lawbench, from matrices (problem built)", best["built"], peers),
        *(f"  {name:<46}{duration(t):>12}" for name, t in peers.items()),
    ]
    if siconos is None:
        return [*lines, "  Siconos numerics: not found (python3-siconos)"]
    ours, theirs = best["loop here"], best["loop there"]
    if ours is not None and theirs is not None:
        lines.append(
            f"  a pure-Python loop: {duration(ours)} in this interpreter (Python "
            f"{platform.python_version()}), {duration(theirs)} in Siconos' ({there}): "
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
        row("lawbench solve_batch, per impact", whole / size, peers),
    ]


# Problems of a frictional batch solved one by one for the per-impact figure: the slowest laws
# take tens of milliseconds each. The first PROBE of them tell whether the batch path takes any.
ONE_BY_ONE_SAMPLE, PROBE = 20, 5


def ellipse_bounces(size: int, rng: np.random.Generator) -> ProblemBatch:
    """Planar one-contact impacts like a thrown ellipse's bounces on a rough floor.

    Mass 36.4 g and inertia 1.68e-5 kg m^2 (coordinates x, y, angle); the contact point at
    lever arms ``(x, y)`` within 3 cm of the centre gives the normal row ``(0, 1, x)`` and the
    tangent row ``(1, 0, y)``; falling at 1 to 3 m/s, sliding at up to 1 m/s, spinning at up
    to 50 rad/s; e in [0, 1], mu in [0, 1].
    """
    M = np.diag([0.0364, 0.0364, 1.68e-5])
    x, y = rng.uniform(-0.03, 0.03, (2, size))
    Wn = np.stack([np.zeros(size), np.ones(size), x], axis=1)[:, :, None]
    Wt = np.stack([np.ones(size), np.zeros(size), y], axis=1)[:, :, None]
    v = np.stack(
        [rng.uniform(-1, 1, size), -rng.uniform(1, 3, size), rng.uniform(-50, 50, size)], axis=1
    )
    coefficients = {"e": rng.uniform(0, 1, (size, 1)), "mu": rng.uniform(0, 1, (size, 1))}
    return ProblemBatch(M, Wn, v, coefficients, Wt)


def cube_corners(size: int, rng: np.random.Generator) -> ProblemBatch:
    """Spatial one-contact impacts of a 0.37 kg cube of 10 cm landing on a corner.

    Coordinates: the centre's velocity, then the angular velocity; the corner at ``r`` from
    the centre (below it) gives the rows ``(n, r x n)`` of the normal ``n = z`` and of the
    tangents x and y.
    """
    M = np.diag([0.37] * 3 + [6.773e-4] * 3)
    r = rng.uniform(-0.05, 0.05, (size, 3))
    r[:, 2] = -np.abs(r[:, 2]) - 0.02
    axes = np.eye(3)
    rows = [np.concatenate([np.broadcast_to(a, (size, 3)), np.cross(r, a)], axis=1) for a in axes]
    v = np.concatenate(
        [
            rng.uniform(-1, 1, (size, 2)),
            -rng.uniform(1, 3, (size, 1)),
            rng.normal(0, 10, (size, 3)),
        ],
        axis=1,
    )
    coefficients = {"e": rng.uniform(0, 1, (size, 1)), "mu": rng.uniform(0, 1, (size, 1))}
    return ProblemBatch(M, rows[2][:, :, None], v, coefficients, np.stack(rows[:2], axis=2))


def frictional_batches(size: int, repeats: int) -> list[str]:
    """Laws with a vectorized path on ``size`` one-contact frictional impacts, planar and spatial.

    The batch (validation included) against the same impacts one by one, timed on
    `ONE_BY_ONE_SAMPLE` of them; the laws are the registered ones that treat friction and
    override `Law._resolve_batch`.
    """
    laws = [
        law
        for law in LAWS.values()
        if law.tags.friction and type(law)._resolve_batch is not Law._resolve_batch
    ]
    lines = []
    scenes = (("planar, ellipse", ellipse_bounces), ("spatial, cube corner", cube_corners))
    for label, build in scenes:
        batch = build(size, np.random.default_rng(2))
        lines.append(f"{size:,} one-contact frictional impacts ({label}), per impact:")
        lines += [_batch_against_alone(law, batch, repeats) for law in laws]
    return lines


def _batch_against_alone(law: Law, batch: ProblemBatch, repeats: int) -> str:
    """One law's line: a batch built from its arrays and solved, against solves one by one.

    A law whose batch path leaves every problem of a `PROBE` to the one-by-one path (spatial
    slip that the law integrates, 0.4 s an impact) is timed on the probe only: its batch would
    cost as much.
    """
    coefficients = {name: values[:PROBE] for name, values in batch.coefficients.items()}
    head = (batch.M[:PROBE], batch.Wn[:PROBE], batch.v[:PROBE], coefficients, batch.Wt[:PROBE])
    probe = solve_batch(law, ProblemBatch(*head))
    if probe.diagnostics["one_by_one"] == PROBE:
        per_impact = probe.diagnostics["wall_time_s"] / PROBE
        return f"  {law.name}: one by one here, {duration(per_impact)} per impact"
    count = ONE_BY_ONE_SAMPLE
    arrays = (batch.M, batch.Wn, batch.v, batch.coefficients, batch.Wt)
    sample = [batch.problem(k) for k in range(count)]
    whole = best_time(lambda: solve_batch(law, ProblemBatch(*arrays)), repeats)
    alone = best_time(lambda: [law.resolve(problem) for problem in sample], 1)
    left = solve_batch(law, batch).diagnostics["one_by_one"]
    return row(
        f"{law.name} solve_batch ({left} one by one)",
        whole / len(batch),
        {"one by one": alone / count},
    )


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
        lines.append(row(f"n = {balls}, prebuilt problem", times[-1], peers))
    if len(sizes) > 1:
        growth = np.log(times[-1] / times[-2]) / np.log(sizes[-1] / sizes[-2])
        lines.append(f"  time grows like n^{growth:.2f} from n = {sizes[-2]} to {sizes[-1]}")
    return lines


def chain_from_scene(balls: int, repeats: int) -> list[str]:
    """The ``lcp`` law on the long-chain scene, from its parameters, against clarabel direct.

    lawbench's time is that of `lawbench.solve` on the scene at ``n = balls``: parameters
    checked, scene built, solved. clarabel is called directly on the same QP (the built
    problem's matrices and restitutions), building its matrix and vector included. The law and
    the scene are those that declare the roles ``lcp`` and ``long_chain``.
    """
    law, scene = subject(LAWS, "lcp"), subject(CASES, "long_chain")
    problem = CASES[scene].build(n=balls)
    e = np.array([contact.e for contact in problem.contacts])
    best = alternated(
        {
            "scene": lambda: best_time(lambda: solve(law, scene, n=balls), 1),
            "clarabel direct": lambda: best_time(
                lambda: clarabel_direct(problem.M, problem.Wn, problem.v, e), 1
            ),
        },
        repeats,
    )
    return [
        f"{law} on the {scene} scene from its parameters (n = {balls}, lawbench.solve):",
        row(
            "parameters checked, scene built, solved",
            best["scene"],
            {"clarabel direct": best["clarabel direct"]},
        ),
    ]


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
                lines.append(f"{label}{duration(time.perf_counter() - start):>12}   {failure}")
                break
            times.append(time.perf_counter() - start)
            error = abs(outcome.T_plus - outcome.T_minus) / outcome.T_minus
            lines.append(
                f"{label}{duration(times[-1]):>12}   energy error {error:.2g}, "
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


def engine_impacts(repeats: int) -> list[str]:
    """Each engine's median cost per impact, at each of its settings, on the engines' scenes.

    The engines are the registered laws whose ``engine`` is true, their settings the choices of
    their option ``settings``; the scenes those of the role ``engine_cost``, at their defaults. Each
    figure is the median of ``repeats`` solves after one untimed solve (an engine's first
    loads its package), against the ``lcp`` law's solve of the same problem (the rigid law the
    tuned engines aim at), timed in the same alternated rounds. A solve that fails prints its
    error in place of a time.
    """
    engines = [law for law in LAWS.values() if law.engine]
    if not engines:
        return ["engines: none installed"]
    peer = LAWS[subject(LAWS, "lcp")]
    lines = []
    for scene in subjects(CASES, "engine_cost"):
        problem = CASES[scene].build()
        calls: dict[str, Callable[[], object]] = {peer.name: lambda p=problem: peer.resolve(p)}
        for law in engines:
            settings = next(spec for spec in law.options if spec.name == "settings")
            for setting in settings.choices:
                calls[f"{law.name} {setting}"] = lambda p=problem, e=law, s=setting: e.resolve(
                    p, settings=s
                )
        medians = _median_alternated(calls, repeats)
        lines.append(f"engines on {scene} (median cost per impact; timed solves each: {repeats}):")
        reference = medians.pop(peer.name)
        for label, median in medians.items():
            if isinstance(median, str) or isinstance(reference, str):
                lines.append(f"  {label:<46}{median if isinstance(median, str) else reference}")
            else:
                lines.append(row(label, median, {peer.name: reference}))
        if not isinstance(reference, str):
            lines.append(f"  {peer.name:<46}{duration(reference):>12}")
    return lines


def _median_alternated(calls: dict[str, Callable[[], object]], repeats: int) -> dict[str, Any]:
    """The median wall time of each call over ``repeats`` rounds that make every call in turn.

    Each is made once untimed first; a call that raises gives its error's line instead.
    """
    times: dict[str, Any] = {}
    for name, call in calls.items():
        try:
            call()
            times[name] = []
        except LawbenchError as error:
            times[name] = f"{type(error).__name__}: {error}"
    for _ in range(repeats):
        for name, call in calls.items():
            if isinstance(times[name], list):
                start = time.perf_counter()
                call()
                times[name].append(time.perf_counter() - start)
    return {name: t if isinstance(t, str) else float(np.median(t)) for name, t in times.items()}


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
        return row(label, best["lawbench"], {'python -c "import numpy"': best["numpy"]})

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
        *frictional_batches(1000 if quick else 10_000, repeats),
        *(long_chains((100, 1000), repeats) if quick else long_chains(CHAINS, repeats, 1000)),
        *chain_from_scene(SCENE_CHAIN, repeats),
        *integrating_chains(QUICK_INTEGRATING_SIZES if quick else INTEGRATING_SIZES),
        *engine_impacts(repeats),
        *start_up(repeats),
    ]
    return "\n".join(lines)
