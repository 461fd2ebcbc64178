"""Moreau's law by nonsmooth Gauss-Seidel with an exact solver per contact (method 'nsgs').

Sources: Jean (CMAME 177, 1999) for the method; Acary, Brémond and Huber (2018), "On solving
contact problems with Coulomb friction: formulations and numerical comparisons", for the local
problem's states and the FC3D error; De Saxce and Feng (1991) for Coulomb's law in the modified
velocity, ``K ∋ P _|_ (un + mu |ut|, ut) ∈ K*``.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import lawbench
from lawbench.core.case import CASES
from lawbench.core.errors import BudgetExceeded, InvalidProblem, SolverFailure
from lawbench.core.guards import Budget
from lawbench.files.fclib import read_fclib
from lawbench.files.problem_files import read_problem
from lawbench.numerics.gauss_seidel import error_of, in_local_order, solve_nsgs

pytest.importorskip("h5py")

MOREAU = lawbench.LAWS.get("moreau")
FCLIB = sorted((Path(__file__).parent / "data" / "fclib").glob("*.hdf5"))
FRICTIONAL = [name for name, case in CASES.items() if case.requires.friction]
# Scenes where Coulomb's law has several solutions: both methods must solve it, each its own.
SEVERAL_SOLUTIONS = {
    ("billiard", 1.0): "the straight shot's ball either wedges between cue and table by "
    "friction or leaves along the cue; both satisfy De Saxce's conditions to rounding",
}


# The shot whose two answers at mu = 1 are known (the default is a masse shot, with one answer).
SHOTS = {"billiard": CASES["billiard"].examples["straight"]}


def with_friction(name, mu):
    """The scene built with every friction coefficient it has set to ``mu``."""
    case = CASES[name]
    frictions = {p.name: mu for p in case.params if p.name.split("_")[0] == "mu"}
    return case.build(**SHOTS.get(name, {}), **frictions)


def impulses(outcome):
    return np.concatenate([outcome.Pn, outcome.Pt])


def local_problem(problem):
    """``G``, ``q`` (restitution of the unilateral rule included), mu and d of Moreau's law."""
    q = problem.W.T @ problem.v
    q[: problem.m] += problem.restitution("kinematic") * np.minimum(problem.un, 0.0)
    return problem.contact_delassus, q, problem.mu, problem.d


def fclib_order(problem):
    """``W``, ``q``, mu and dim of Moreau's law in FCLIB's order (per contact n, t1[, t2])."""
    G, q, mu, d = local_problem(problem)
    W, local_q = in_local_order(G, q, len(mu), d)
    return W, local_q, mu, d + 1


@pytest.mark.parametrize("mu", [0.0, 0.3, 1.0])
@pytest.mark.parametrize("name", FRICTIONAL)
def test_nsgs_agrees_with_the_fixed_point_on_the_frictional_scenes(name, mu):
    """Both methods solve the same law (De Saxce and Feng 1991): the same impulses to 1e-10,
    or, where the law has several solutions, two answers that each satisfy it.
    """
    problem = with_friction(name, mu)
    fixed_point = impulses(MOREAU.resolve(problem))
    nsgs = impulses(MOREAU.resolve(problem, method="nsgs"))
    scale = max(np.abs(fixed_point).max(), 1e-300)
    if (name, mu) in SEVERAL_SOLUTIONS:
        G, q, mus, d = local_problem(problem)
        assert error_of(G, q, mus, d, fixed_point) <= 1e-10
        assert error_of(G, q, mus, d, nsgs) <= 1e-10
        assert np.abs(nsgs - fixed_point).max() > 1e-3 * scale
        return
    np.testing.assert_allclose(nsgs, fixed_point, rtol=0, atol=1e-10 * scale)


# Granular problems take thousands of sweeps, above Moreau's default bound.
GRANULAR_SWEEPS = 100_000
# Gauss-Seidel settles away from any solution on this file's singular W (tests/data/fclib).
STALLS = "OneObject-i100000-499"


@pytest.mark.parametrize("path", [p for p in FCLIB if p.stem != STALLS], ids=lambda p: p.stem)
def test_nsgs_solves_the_committed_fclib_files(path):
    """The FC3D error on the file's own W and q (Acary, Brémond and Huber 2018) is <= 1e-8:
    a global file solved as an impact, a local one in contact space, W as given."""
    problem = read_fclib(path)
    if isinstance(problem, lawbench.ContactProblem):
        answer = MOREAU.solve_contact(problem, method="nsgs", tol=1e-8, max_steps=GRANULAR_SWEEPS)
        error = answer.fc3d_error
    else:
        answer = MOREAU.resolve(problem, method="nsgs", tol=1e-8, max_steps=GRANULAR_SWEEPS)
        error = read_problem(path).facts.diagnostics(answer)["fc3d_error"]
    assert error <= 1e-8
    assert answer.diagnostics["formulation"].startswith("NSGS")
    assert answer.diagnostics["sweeps"] >= 1


def test_a_stationary_iteration_on_a_singular_w_fails_naming_the_rank():
    """Siconos' test problem OneObject-i100000-499, written by Siconos' FCLIB writer: its W has
    rank 49 of 72, and nonsmooth Gauss-Seidel settles at an FC3D error of 4.3e-5 (Siconos'
    fc3d_nsgs ends at 9.9e-4 after 100000 sweeps). The sweeps stop once the error has found no
    new low for a thousand sweeps (and as many as the last low took), and the failure says
    why."""
    problem = read_fclib(next(path for path in FCLIB if path.stem == STALLS))
    with pytest.raises(SolverFailure, match=r"stationary after \d+ sweeps at FC3D error") as e:
        MOREAU.solve_contact(problem, method="nsgs", tol=1e-8, max_steps=GRANULAR_SWEEPS)
    assert "W is singular, rank 49 of 72" in str(e.value)
    sweeps = int(str(e.value).split("after ")[1].split(" sweeps")[0])
    assert 1000 <= sweeps <= 5000


# One contact, by hand. Planar: W = [[2, 1/2], [1/2, 1]], mu = 1/2; W^-1 = [[1, -1/2], [-1/2,
# 2]] / (7/4). Stick at b = (-1, -1/10): P = -W^-1 b = (19/35, -6/35), |Pt| <= Pn / 2. Slip at
# b = (-1, -2): the stick answer (0, 2) leaves the cone; with ut < 0, Pt = Pn / 2, so
# un = (2 + 1/4) Pn - 1 = 0 gives P = (4/9, 2/9) and ut = 1/2 4/9 + 2/9 - 2 = -14/9 < 0.
# Spatial: the same block with a decoupled second tangent gives the same slip (and Pt2 = 0); an
# isotropic block diag(2, 1, 1) slips against bt = (3, 4): Pn = 1/2, Pt = -(1/4) (3, 4) / 5.
PLANAR = np.array([[2.0, 0.5], [0.5, 1.0]])
COUPLED = np.array([[2.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 1.0]])
ISOTROPIC = np.diag([2.0, 1.0, 1.0])
ONE_CONTACT = {
    "planar take-off": (PLANAR, [0.3, -1.0], 0.5, [0.0, 0.0]),
    "planar stick": (PLANAR, [-1.0, -0.1], 0.5, [19 / 35, -6 / 35]),
    "planar slip": (PLANAR, [-1.0, -2.0], 0.5, [4 / 9, 2 / 9]),
    "planar frictionless": (PLANAR, [-1.0, -2.0], 0.0, [0.5, 0.0]),
    "spatial take-off": (ISOTROPIC, [0.2, 1.0, 1.0], 0.5, [0.0, 0.0, 0.0]),
    "spatial stick": (ISOTROPIC, [-1.0, 0.1, -0.2], 0.5, [0.5, -0.1, 0.2]),
    "spatial slip": (ISOTROPIC, [-1.0, 3.0, 4.0], 0.5, [0.5, -0.15, -0.2]),
    "spatial coupled slip": (COUPLED, [-1.0, -2.0, 0.0], 0.5, [4 / 9, 2 / 9, 0.0]),
    "spatial frictionless": (ISOTROPIC, [-1.0, 3.0, 4.0], 0.0, [0.5, 0.0, 0.0]),
}


@pytest.mark.parametrize("case", ONE_CONTACT)
def test_one_contact_is_solved_exactly_in_each_state(case):
    """Take-off, stick and slip of one contact (Acary, Brémond and Huber 2018, section 4.1)
    against the hand calculation above; one sweep solves it and the second confirms it.
    """
    W, b, mu, expected = ONE_CONTACT[case]
    result = solve_nsgs(W, np.array(b), np.array([mu]), len(b), 1e-12)
    np.testing.assert_allclose(result.P, expected, rtol=0, atol=1e-14)
    assert result.sweeps <= 2
    assert result.error <= 1e-15


def test_a_sparse_delassus_matrix_gives_the_dense_answer():
    """The sweep reads G's non-zero entries only: dense and CSR agree to rounding."""
    W, q, mu, dim = fclib_order(with_friction("disk_ball", 0.3))
    dense = solve_nsgs(W.toarray(), q, mu, dim, 1e-12)
    sparse = solve_nsgs(W, q, mu, dim, 1e-12)
    np.testing.assert_allclose(sparse.P, dense.P, rtol=0, atol=1e-14)
    assert sparse.sweeps == dense.sweeps


def test_the_budget_stops_the_sweeps():
    """A problem that needs tens of sweeps stops at a bound of 5 sweeps, or of 1 ms, with
    `BudgetExceeded` naming the bound (lawbench.core.law.Budget).
    """
    problem = read_fclib(next(path for path in FCLIB if path.stem.startswith("Box_Stacks")))
    with pytest.raises(BudgetExceeded, match="5 Gauss-Seidel sweeps") as raised:
        MOREAU.resolve(problem, method="nsgs", max_steps=5)
    assert raised.value.budget == "max_steps"
    W, q, mu, dim = fclib_order(problem)
    with Budget("moreau", max_seconds=1e-3), pytest.raises(BudgetExceeded) as raised:
        solve_nsgs(W, q, mu, dim, 0.0)
    assert raised.value.budget == "max_seconds"


def test_nsgs_refuses_the_relaxed_cone():
    """Anitescu's relaxation (friction 'relaxed') is the fixed point's convex problem only."""
    with pytest.raises(InvalidProblem, match="method 'nsgs'"):
        MOREAU.resolve(with_friction("rocking_block", 0.3), method="nsgs", friction="relaxed")


PLAIN_PYTHON = """
import sys
sys.modules["numba"] = None
import numpy as np
from lawbench.numerics import gauss_seidel
assert not gauss_seidel.compiled()
G = np.array({G})
print(gauss_seidel.solve_nsgs(G, np.array({q}), np.array({mu}), 3, 1e-12).P.tolist())
"""


def test_plain_python_runs_the_same_sweeps():
    """Without numba the same functions run uncompiled and give the same impulses."""
    problem = with_friction("billiard", 0.3)
    W, q, mu, dim = fclib_order(problem)
    script = PLAIN_PYTHON.format(G=W.toarray().tolist(), q=q.tolist(), mu=mu.tolist())
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    plain = np.array(json.loads(done.stdout))
    np.testing.assert_allclose(plain, solve_nsgs(W, q, mu, dim, 1e-12).P, rtol=0, atol=1e-14)


def test_a_solve_gives_the_kernels_the_types_they_were_compiled_for():
    """`compiled` compiles each kernel for the types a solve gives it (a problem's read-only
    arrays made writable): a solve compiles nothing, so no solve's budget pays for it."""
    numba = pytest.importorskip("numba")
    from lawbench.numerics import gauss_seidel

    assert gauss_seidel.compiled()
    kernels = [getattr(gauss_seidel, name) for name in gauss_seidel._KERNELS]
    assert all(isinstance(kernel, numba.core.registry.CPUDispatcher) for kernel in kernels)
    before = [list(kernel.signatures) for kernel in kernels]
    assert all(before[gauss_seidel._KERNELS.index(name)] for name in ("_sweep", "_in_a_state"))
    for name in FRICTIONAL:
        MOREAU.resolve(with_friction(name, 0.3), method="nsgs")
    assert [list(kernel.signatures) for kernel in kernels] == before


COLD_SOLVE = """
import lawbench
outcome = lawbench.solve("moreau", "sphere_wall", {"max_seconds": 5})
print(outcome.status, outcome.diagnostics["formulation"])
"""


@pytest.mark.slow
def test_a_cold_compile_is_no_part_of_a_solve_budget(tmp_path):
    """With numba's cache empty, compiling the kernels (30 s and more on one core) is a cost of
    the process, paid before the solve's budget starts: a 5 s solve that sweeps ends ok."""
    pytest.importorskip("numba")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    done = subprocess.run(
        [sys.executable, "-c", COLD_SOLVE], env=env, capture_output=True, text=True, timeout=900
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[0] == "ok"
    assert "(numba)" in done.stdout
    assert any(tmp_path.rglob("*.nbi")), "the kernels were not compiled in this process"
