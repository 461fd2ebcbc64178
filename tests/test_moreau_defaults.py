"""Moreau's law at its defaults on the field's frictional contact problems (method ``auto``).

``auto`` keeps the fixed point over cone QPs on impacts of a few contacts (every scene's), and
sweeps contact-space and larger problems by nonsmooth Gauss-Seidel, Siconos' default solver and
the robust one on FCLIB's large problems in Acary, Brémond and Huber's comparison (2018); a
stationary sweep, or one that runs out of its bound, hands the problem to the fixed point. The
bound on each method's steps follows the problem's size at ``max_steps = 0``.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import lawbench
from lawbench.core.contact import ContactProblem
from lawbench.core.errors import BudgetExceeded
from lawbench.files.problem_files import read_problem

pytest.importorskip("h5py")

MOREAU = lawbench.LAWS.get("moreau")
FCLIB = Path(__file__).parent / "data" / "fclib"
# The method auto answers with on each committed file (tests/data/fclib): the fixed point on
# the global files of one and four contacts, Gauss-Seidel on the others; on OneObject's
# singular W the sweeps run out of their bound and the fixed point solves it.
ANSWERED_BY = {
    "LMGC_GFC3D-i00001-1-00000": "nsgs",  # one contact: the exact local solver
    "LMGC_GFC3D-i00501-4-00000": "fixed_point",
    "LMGC_GlobalFrictionContactProblem00046": "nsgs",
    "LMGC_100_PR_PerioBox-i00361-60-03000": "nsgs",
    "Box_Stacks-i0122-82-5": "nsgs",
    "Capsules-i125-1213": "nsgs",
    "OneObject-i100000-499": "fixed_point",
}
# Files whose solve takes more than a few seconds here: 3050 sweeps over 286 capsules, and
# 1000 sweeps then 338 cone QPs on OneObject.
SLOW = {"Capsules-i125-1213", "OneObject-i100000-499"}
SOLVED = 1e-8  # the FC3D error of a solved problem in Acary, Brémond and Huber's comparison


def solved_at_the_defaults(path):
    """The defaults' answer to a file, its FC3D error on the file's own data, its method."""
    read = read_problem(path)
    if isinstance(read.problem, ContactProblem):
        answer = MOREAU.solve_contact(read.problem)
        error = answer.fc3d_error
    else:
        answer = MOREAU.resolve(read.problem)
        error = read.facts.diagnostics(answer)["fc3d_error"]
    return answer, error


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in ANSWERED_BY],
)
def test_the_defaults_solve_every_committed_fclib_file(name):
    answer, error = solved_at_the_defaults(FCLIB / f"{name}.hdf5")
    assert error <= SOLVED
    assert answer.diagnostics["method"] == ANSWERED_BY[name]
    if name == "OneObject-i100000-499":
        assert "step budget ran out (1000 Gauss-Seidel sweeps" in answer.diagnostics["after"][0]


@pytest.mark.slow
def test_the_readme_command_solves_the_capsules_within_ten_seconds():
    """``lawbench solve moreau --problem Capsules-i125-1213.hdf5`` at the defaults (286 contacts,
    an asymmetric W): Gauss-Seidel's sweeps reach the FC3D error of 1e-10 within its bound of
    20 sweeps per contact."""
    path = FCLIB / "Capsules-i125-1213.hdf5"
    done = subprocess.run(
        [sys.executable, "-m", "lawbench", "solve", "moreau", "--problem", str(path), "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    answer = json.loads(done.stdout)
    assert answer["fc3d_error"] <= SOLVED
    assert answer["diagnostics"]["method"] == "nsgs"
    assert answer["diagnostics"]["sweeps"] <= 20 * answer["contacts"]
    assert answer["diagnostics"]["wall_time_s"] <= 10


def test_the_scenes_keep_the_fixed_point():
    """Every frictional scene is an impact of a few contacts: auto solves one of several as
    before, by the fixed point, and one of a single contact by its exact local solver."""
    for name, case in lawbench.CASES.items():
        problem = case.build()
        if problem.frictional:
            expected = "nsgs" if problem.m == 1 else "fixed_point"
            assert MOREAU.resolve(problem).diagnostics["method"] == expected, name


def chain(m):
    """Frictionless contacts in a line, each coupled to its neighbours (a 1D Laplacian in the
    normal directions): every contact pushes, and Gauss-Seidel's error shrinks by only about
    1 - (pi / m)^2 per sweep, a steady descent far slower than the bounds below."""
    normal = 2 * np.eye(m) - np.eye(m, k=1) - np.eye(m, k=-1)
    W = np.kron(normal, np.diag([1.0, 0.0, 0.0])) + np.kron(np.eye(m), np.diag([0.0, 1.0, 1.0]))
    q = np.tile([-1.0, 0.3, -0.2], m)
    return ContactProblem(W, q, np.zeros(m))


def test_the_sweeps_bound_follows_the_size_and_an_explicit_one_holds():
    problem = chain(100)
    with pytest.raises(BudgetExceeded, match=r"ran out \(2000 Gauss-Seidel sweeps") as sized:
        MOREAU.solve_contact(problem, method="nsgs")
    assert (sized.value.budget, sized.value.amount) == ("max_steps", 2000)
    with pytest.raises(BudgetExceeded, match=r"ran out \(50 Gauss-Seidel sweeps"):
        MOREAU.solve_contact(problem, method="nsgs", max_steps=50)


def test_auto_hands_sweeps_that_run_out_to_the_fixed_point():
    answer = MOREAU.solve_contact(chain(100))
    assert answer.fc3d_error <= 1e-10
    assert answer.diagnostics["method"] == "fixed_point"
    assert "nsgs: moreau: step budget ran out (2000" in answer.diagnostics["after"][0]
    plain = MOREAU.solve_contact(chain(100), method="fixed_point")
    np.testing.assert_allclose(answer.r, plain.r, rtol=0, atol=1e-12)


def test_the_time_budget_ends_auto_without_a_second_method():
    with pytest.raises(BudgetExceeded) as failure:
        MOREAU.solve_contact(chain(100), max_seconds=1e-9)
    assert failure.value.budget == "max_seconds"


def test_the_wall_clock_stop_ends_a_one_contact_solve_without_its_exact_state(monkeypatch):
    """At one contact a failed Gauss-Seidel gives way to the contact's exact state, but the
    solve's time running out (here the guard's stop) is no failure of the method: it ends the
    solve, which else answered past its bound."""
    from lawbench.core.guards import stopped
    from lawbench.laws import moreau

    def out_of_time(*args):
        raise stopped(0.1)

    monkeypatch.setattr(moreau, "solve_polished", out_of_time)
    with pytest.raises(BudgetExceeded, match="wall-clock guard"):
        MOREAU.resolve(lawbench.CASES.get("sphere_wall").build())


def test_auto_solves_anitescus_relaxation_by_the_fixed_point():
    """Gauss-Seidel solves Coulomb's law only: auto gives the relaxation to the fixed point,
    where an explicit ``method=nsgs`` is refused."""
    answer = MOREAU.solve_contact(chain(3), friction="relaxed")
    assert answer.diagnostics["method"] == "fixed_point"
    with pytest.raises(lawbench.InvalidProblem, match="method 'nsgs'"):
        MOREAU.solve_contact(chain(3), method="nsgs", friction="relaxed")
