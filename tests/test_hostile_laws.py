"""Laws that misbehave: every bound holds and the checks read the velocities.

A law is code from anywhere. Each test below holds one promise of `Law.resolve`, the registry
and the command line against a law (or a plugin) written to break it: one that sleeps, loops,
exits, interrupts, writes into its input, answers in the wrong shape, or reports numbers its
velocities do not hold.
"""

import dataclasses
import os
import re
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from test_plugins import distribution

import lawbench
from lawbench.checks import run_checks
from lawbench.core import guards
from lawbench.core import registry as registry_module
from lawbench.core.errors import BudgetExceeded, SolverFailure
from lawbench.core.guards import WALL_CLOCK, alarm
from lawbench.core.law import Law
from lawbench.core.registry import Registry
from lawbench.core.trial import Trial
from lawbench.views.cli.main import main
from lawbench.views.cli.solve import plain

SHORT = lawbench.Spec("max_seconds", 0.3, "wall-clock budget of one solve", unit="s", low=0.0)


class Plain(Law):
    """Newton's restitution at one contact, the base the broken laws start from."""

    name = "plain_test_law"
    summary = "Newton's restitution at one contact"
    source = "Newton's law of restitution"
    tags = lawbench.Tags()
    options = (SHORT,)

    def _resolve(self, problem, options):
        Pn = -(1 + problem.restitution("kinematic")) * problem.un / np.diag(problem.delassus)
        return lawbench.Outcome.from_impulses(problem, np.maximum(Pn, 0.0))


def ball(e=0.5):
    return lawbench.ImpactProblem.from_arrays(np.eye(1), [[1.0]], [-2.0], e=e)


def broken(body, name="broken_test_law"):
    """A `Plain` law whose `_resolve` is ``body``."""
    return type("Broken", (Plain,), {"name": name, "_resolve": body})()


def test_a_plain_law_passes_the_guards():
    outcome = lawbench.solve(Plain(), ball())
    assert outcome.v_plus.tolist() == [1.0]


@pytest.mark.parametrize(
    "body",
    [
        pytest.param(lambda self, p, o: time.sleep(100), id="sleeps"),
        pytest.param(lambda self, p, o: [None for _ in iter(int, 1)], id="loops"),
    ],
)
def test_a_law_that_ignores_its_budget_is_stopped_from_outside(body):
    start = time.monotonic()
    with pytest.raises(BudgetExceeded, match=WALL_CLOCK):
        lawbench.solve(broken(body), ball())
    assert time.monotonic() - start < 5


def test_an_outer_alarm_rings_first_in_its_own_words():
    with pytest.raises(BudgetExceeded, match=r"within 0\.2 s"):
        with alarm(0.2):
            with alarm(30):
                time.sleep(5)


def _exits(self, problem, options):
    sys.exit(0)


def _interrupts(self, problem, options):
    raise KeyboardInterrupt


def _runs_out_of_memory(self, problem, options):
    raise MemoryError


@pytest.fixture
def python_s_sigint():
    """SIGINT at Python's own handler, whatever this process's earlier work left it at."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_the_users_ctrl_c_still_interrupts(python_s_sigint):
    def pressed(self, problem, options):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(2)

    with pytest.raises(KeyboardInterrupt):
        lawbench.solve(broken(pressed), ball())


def _writes_velocity(self, problem, options):
    problem.v.setflags(write=True)
    problem.v[0] = 0.0
    problem.v.setflags(write=False)
    return Plain._resolve(self, problem, options)


def _writes_contact(self, problem, options):
    object.__setattr__(problem.contacts[0], "e", 1.0)
    return Plain._resolve(self, problem, options)


def _writes_options(self, problem, options):
    options["max_seconds"] = 1e9
    return Plain._resolve(self, problem, options)


@pytest.mark.parametrize(
    ("body", "said"),
    [
        (_exits, "sys.exit"),
        (_interrupts, "KeyboardInterrupt"),
        (_runs_out_of_memory, "memory"),
        (_writes_velocity, "wrote into the problem"),
        (_writes_contact, "wrote into the problem"),
        (_writes_options, "wrote into the options"),
    ],
)
def test_a_law_that_exits_runs_out_of_memory_or_writes_into_its_input_fails(body, said):
    """sys.exit, KeyboardInterrupt and MemoryError in a law, or a write into what it was given,
    are that law's failure, named."""
    with pytest.raises(SolverFailure, match=f"broken_test_law: .*{said}"):
        lawbench.solve(broken(body), ball())


def test_a_write_into_a_shared_contact_reaches_no_later_problem():
    """Problems of the same coefficients share one contact object: a law that forces e = 1
    into it fails, and a problem built afterwards with e = 0.5 still has e = 0.5."""
    with pytest.raises(SolverFailure, match="wrote into the problem"):
        lawbench.solve(broken(_writes_contact), ball(0.5))
    assert ball(0.5).contacts[0].e == 0.5
    assert lawbench.solve("newton", ball(0.5)).v_plus[0] == pytest.approx(1.0)


def test_lawbench_s_own_laws_still_have_their_options_and_problem_identity_checked():
    """A law of lawbench's own packages skips the hash of the numbers (its arrays are
    read-only), not the check of its options, nor of which arrays the problem holds."""
    own = broken(_writes_options)
    type(own).__module__ = "lawbench.laws.own_test_law"
    with pytest.raises(SolverFailure, match="wrote into the options"):
        lawbench.solve(own, ball())

    def swaps_velocity(self, problem, options):
        object.__setattr__(problem, "v", problem.v.copy())
        return Plain._resolve(self, problem, options)

    own = broken(swaps_velocity)
    type(own).__module__ = "lawbench.laws.own_test_law"
    with pytest.raises(SolverFailure, match="wrote into the problem"):
        lawbench.solve(own, ball())


@pytest.mark.parametrize("field", ["v_plus", "Pn"])
def test_a_wrong_output_shape_names_the_field(field):
    def wrong(self, problem, options):
        outcome = Plain._resolve(self, problem, options)
        return dataclasses.replace(outcome, **{field: np.zeros(3)})

    with pytest.raises(SolverFailure, match=f"{field} has shape"):
        lawbench.solve(broken(wrong), ball())


def _reports_less_energy(self, problem, options):
    return dataclasses.replace(Plain._resolve(self, problem, options), T_plus=1.0)


def _hides_a_tensile_impulse(self, problem, options):
    outcome = lawbench.Outcome.from_impulses(problem, np.array([-1.0]))
    return dataclasses.replace(outcome, Pn=np.abs(outcome.Pn))


def _answers_another_problem(self, problem, options):
    heavier = lawbench.ImpactProblem.from_arrays(2 * np.eye(1), [[1.0]], [-2.0], e=1.0)
    return lawbench.Outcome.from_impulses(heavier, np.array([8.0]))


@pytest.mark.parametrize("module", [__name__, "lawbench.laws.own_test_law"])
@pytest.mark.parametrize(
    ("body", "said"),
    [
        (_reports_less_energy, "T_plus = 1 J"),
        (_hides_a_tensile_impulse, "impulses"),
        (_answers_another_problem, "reports T_minus"),
    ],
)
def test_reported_numbers_must_be_those_of_the_velocities(body, said, module):
    """Also for lawbench's own laws, whose outcomes `Outcome.from_impulses` built from the
    problem solved are taken as consistent: a copy with other numbers, or an outcome built
    from another problem, is read number by number."""
    law = broken(body)
    type(law).__module__ = module
    with pytest.raises(SolverFailure, match=said):
        lawbench.solve(law, ball(e=1.0))


def _replaced(**fields):
    def body(self, problem, options):
        return dataclasses.replace(Plain._resolve(self, problem, options), **fields)

    return body


def _raises(error):
    def body(self, problem, options):
        raise error

    return body


@pytest.mark.parametrize(
    ("body", "said"),
    [
        (_replaced(v_plus=np.array([1.0 + 0j])), "v_plus holds complex128, not floats"),
        (_replaced(Pn=[3.0]), "Pn is a list, not an array"),
        (_replaced(T_plus=1j), "T_plus is a complex, not a real number"),
        (_replaced(status="ok\nfine"), "is not one word"),
        (_replaced(diagnostics=[1]), "diagnostics is a list, not a dict"),
        (_replaced(v_minus=np.array([7.0])), "v_minus is not the problem's velocity"),
        (_raises(RecursionError("deep")), "the law raised RecursionError: deep"),
        (_raises(GeneratorExit()), "the law raised GeneratorExit"),
        (_raises(type("Odd", (BaseException,), {})()), "the law raised Odd"),
    ],
    ids=[
        "complex",
        "list",
        "complex-energy",
        "status",
        "diagnostics",
        "v_minus",
        "raises",
        "generator-exit",
        "base-exception",
    ],
)
def test_a_malformed_answer_or_a_raise_is_a_failure_of_that_law(body, said):
    """What the tables, the checks and the JSON output read is of the kind they read, and an
    exception out of a law is that law's failure, never an internal error."""
    with pytest.raises(SolverFailure, match=re.escape(said)):
        lawbench.solve(broken(body), ball())


def test_an_error_raised_by_lawbench_s_own_law_stays_an_internal_error():
    """A bug of lawbench's own is not passed off as a solver's failure."""
    own = broken(_raises(RecursionError("deep")))
    type(own).__module__ = "lawbench.laws.own_test_law"
    with pytest.raises(RecursionError):
        lawbench.solve(own, ball())


def test_the_json_record_holds_what_json_has_no_type_for_as_text():
    record = plain({"s": {1}, "z": 1j, "nan": float("nan"), "f": np.float64(2.0), "n": None})
    assert record == {"s": "{1}", "z": "1j", "nan": None, "f": 2.0, "n": None}


def test_the_checks_read_the_velocities_not_the_reports():
    """A trial built around a lying outcome (no `Law.resolve`) fails the checks it fools."""
    problem = ball(e=1.0)
    honest = lawbench.Outcome.from_impulses(problem, np.array([6.0]))  # v+ = 4: T+ = 8 J
    lying = dataclasses.replace(honest, T_plus=1.0, Pn=np.array([1.0]))
    trial = Trial(Plain(), None, {}, {}, problem, lying)
    results = run_checks(trial, checks=["energy_gain", "impulse_sign"])
    assert results["energy_gain"].passed is False
    assert results["impulse_sign"].passed is False
    assert "velocity change" in results["impulse_sign"].detail


class _Point:
    def __init__(self, name, load):
        self.name, self.value, self.load = name, f"hostile:{name}", load


def _raise(error):
    def load():
        raise error

    return load


def test_a_plugin_that_exits_hangs_raises_or_interrupts_at_import_is_unavailable(monkeypatch):
    points = [
        _Point("exits", _raise(SystemExit(3))),
        _Point("interrupts", _raise(KeyboardInterrupt())),
        _Point("raises", _raise(RuntimeError("no"))),
        _Point("hangs", lambda: time.sleep(100)),
        _Point("fine", lambda: Plain),
    ]
    monkeypatch.setattr(registry_module, "_entry_points", lambda **selection: points)
    monkeypatch.setattr(registry_module, "PLUGIN_IMPORT_S", 0.3)
    laws = Registry("law", "lawbench.laws", Law)
    assert "plain_test_law" in laws  # the others fail, and the good one still loads
    reasons = laws.unavailable
    assert "sys.exit(3)" in reasons["exits"]
    assert "KeyboardInterrupt" in reasons["interrupts"]
    assert "RuntimeError: no" in reasons["raises"]
    assert "longer than 0.3 s" in reasons["hangs"]


def test_memory_error_is_one_line_and_exit_4(monkeypatch, capsys):
    def no_memory(command=None):
        raise MemoryError

    monkeypatch.setattr(sys.modules["lawbench.views.cli.main"], "build_parser", no_memory)
    assert main(["list"]) == 4
    assert capsys.readouterr().err.strip() == "lawbench: out of memory (MemoryError)"


HOSTILE = '''
"""Laws that misbehave, for the command-line tests of lawbench's guards."""

import signal
import threading
import time

import numpy as np

import lawbench

SHORT = lawbench.Spec("max_seconds", 0.3, "wall-clock budget of one solve", unit="s", low=0.0)


class Sleeper(lawbench.Law):
    name, summary, source = "sleeper", "sleeps instead of solving", "none"
    tags, options = lawbench.Tags(), (SHORT,)

    def _resolve(self, problem, options):
        time.sleep(1000)


class Spawner(Sleeper):
    name = "spawner"
    summary = "answers, and leaves a thread running that the interpreter would wait for"

    def _resolve(self, problem, options):
        threading.Thread(target=time.sleep, args=(1000,)).start()
        return lawbench.Outcome.from_impulses(problem, -1.5 * problem.un / problem.delassus[0])


class Deaf(Sleeper):
    name = "deaf"
    summary = "blocks the timer signal, then sleeps: a native call that never returns"

    def _resolve(self, problem, options):
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(1000)


class BallOnWall(lawbench.Case):
    name = "lone_ball"
    summary = "one ball on a wall"
    params = (lawbench.Spec("e", 0.5, "restitution", low=0.0, high=1.0),)
    examples = {"default": {}}

    def _build(self, params):
        return lawbench.ImpactProblem.from_arrays(np.eye(1), [[1.0]], [-1.0], e=params["e"])

    def coordinates(self, params):
        return ["ball (m/s)"]
'''

EXITS = "import sys\nsys.exit(0)\n"
INTERRUPTS = "raise KeyboardInterrupt\n"

ENTRY_POINTS = """
[lawbench.laws]
sleeper = hostile_plugin:Sleeper
deaf = hostile_plugin:Deaf
spawner = hostile_plugin:Spawner
exits = exits_at_import:Nothing
interrupts = interrupts_at_import:Nothing

[lawbench.cases]
lone_ball = hostile_plugin:BallOnWall
"""


@pytest.fixture(scope="module")
def hostile_env(tmp_path_factory):
    modules = {
        "hostile_plugin": textwrap.dedent(HOSTILE),
        "exits_at_import": EXITS,
        "interrupts_at_import": INTERRUPTS,
    }
    return distribution(tmp_path_factory.mktemp("hostile"), "hostile-plugin", modules, ENTRY_POINTS)


def cli(env, *argv, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "lawbench", *argv],
        capture_output=True,
        text=True,
        env=env,
        cwd=cwd,
        timeout=60,
    )


@pytest.mark.parametrize(
    "argv", [("list",), ("describe", "newton"), ("study", "--list")], ids=lambda a: a[0]
)
def test_the_built_in_commands_work_beside_plugins_broken_at_import(hostile_env, argv):
    done = cli(hostile_env, *argv)
    assert done.returncode == 0, done.stderr
    if argv == ("list",):
        assert "sys.exit(0)" in done.stdout and "KeyboardInterrupt" in done.stdout


@pytest.mark.parametrize("law", ["sleeper", "deaf"])
def test_solve_stops_a_law_that_never_answers(hostile_env, law):
    start = time.monotonic()
    done = cli(hostile_env, "solve", law, "lone_ball")
    assert done.returncode == 4, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and WALL_CLOCK in done.stderr
    assert time.monotonic() - start < 20


def test_solve_ends_when_a_law_left_a_thread_running(hostile_env):
    done = cli(hostile_env, "solve", "spawner", "lone_ball")
    assert done.returncode == 0, done.stderr
    assert "status: ok" in done.stdout


def test_main_called_as_a_function_never_ends_its_callers_process(capsys):
    """Only the ``lawbench`` program owns its process: a caller of `main` keeps its own."""
    assert main(["solve", "newton", "three_ball_chain"]) == 0
    capsys.readouterr()
    assert guards._Watchdog.thread is None


def test_check_and_run_stop_a_law_that_sleeps(hostile_env, tmp_path):
    checked = cli(hostile_env, "check", "sleeper", "--cases", "lone_ball", "--random", "0")
    assert "budget" in checked.stdout and "Traceback" not in checked.stderr
    ran = cli(
        hostile_env,
        *("run", "--laws", "sleeper", "--cases", "lone_ball", "--executor", "serial"),
        *("--out", "run.csv", "--format", "csv"),
        cwd=tmp_path,
    )
    assert ran.returncode == 0, ran.stderr
    assert WALL_CLOCK in (tmp_path / "run.csv").read_text()


def test_an_answer_that_breaks_a_promise_is_a_solver_failure_never_ok():
    """A contact left approaching (a promise of every law) is refused by the one way into a
    solve, for `lawbench.solve` as for ``lawbench solve`` (exit 4); `run_checks` classes it."""

    def pulls(self, problem, options):
        return lawbench.Outcome.from_impulses(problem, np.array([-1.0]))

    law = broken(pulls)
    with pytest.raises(SolverFailure, match="admissible fails where it must hold"):
        lawbench.solve(law, ball())
    assert str(run_checks(law, ball())["admissible"].verdict) == "numerical failure"


FIRST_SOLVE_STOPPED = """
import time

import lawbench
from lawbench.core.errors import BudgetExceeded
from lawbench.core.guards import alarm

moreau = lawbench.LAWS.get("moreau")
problem = lawbench.CASES.get("sphere_wall").build()
for seconds in (0.02, 0.05, 0.1):
    start = time.monotonic()
    try:
        with alarm(seconds):
            moreau.resolve(problem)
    except BudgetExceeded:
        continue
    if time.monotonic() - start > seconds + 0.05:
        raise SystemExit(f"answered past its bound of {seconds} s")
print(lawbench.solve("moreau", "sphere_wall").v_plus.tolist())
"""


def test_a_first_solve_stopped_while_numba_loads_leaves_the_process_able_to_solve():
    """The first frictional solve at one contact imports numba and loads Gauss-Seidel's
    compiled kernel, unless the one way into a solve prepared them before its bound (a law's
    own resolve under an alarm does not): stopped there by the alarm, numba was left
    half-imported (every later solve an AttributeError or KeyError), or the stop was swallowed
    and the answer came past its bound. The alarm now rings once numba is whole: each stopped
    solve is a budget, and the next one answers."""
    done = subprocess.run(
        [sys.executable, "-c", FIRST_SOLVE_STOPPED], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]


def test_an_alarm_waits_for_held_code_and_rings_as_it_ends():
    finished = []
    with pytest.raises(BudgetExceeded, match=WALL_CLOCK):
        with alarm(0.05):
            with guards.held():
                time.sleep(0.2)
                finished.append(True)
            time.sleep(5)
    assert finished == [True]
