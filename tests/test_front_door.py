"""Fuzzing the front door: whatever a user types, lawbench answers or says what is wrong.

Hypothesis draws laws, scenes, parameter and option values (numbers of every size and sign,
NaN, infinities, empty lists, words, wrong types) and calls the Python API and the command
line. Every call must end in an outcome or a `LawbenchError` (exit 0, 2, 3 or 4 on the
command line, one line on stderr): never another exception, never an internal error.
"""

import contextlib
import io
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import lawbench
from lawbench.views.cli import main

LAWS = lawbench.LAWS.names()
CASES = lawbench.CASES.names()
# The integrating laws are slow on extreme values; a short budget keeps the fuzz fast, and
# running out of it is an answer (BudgetExceeded) like any other.
BUDGET = {"max_seconds": 0.5}

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.sampled_from([0.0, -0.0, 1e-300, -1e-300, 1e300, 0.5, 1.0, 2.0, -1.0]),
)
values = st.one_of(
    numbers,
    st.lists(numbers, max_size=4),
    st.sampled_from(["", "abc", "1,2", "nan", "inf", "[1]", "true", None, [], {}, ()]),
)


def plausible(spec):
    """Values of a spec: its default, its bounds and points between, or anything at all."""
    inside = [spec.default]
    if spec.kind in ("float", "floats") and spec.low is not None and spec.high is not None:
        inside += [spec.low, spec.high, (spec.low + spec.high) / 2]
    elif spec.kind in ("float", "floats") and spec.low is not None:
        inside += [spec.low, spec.low + 1e-12, spec.low + 1e6]
    if spec.choices:
        inside += list(spec.choices)
    return st.one_of(st.sampled_from(inside), values)


@st.composite
def calls(draw):
    """A law, a scene, some of its parameters and options, and now and then an unknown name."""
    law = lawbench.LAWS.get(draw(st.sampled_from(LAWS)))
    case = lawbench.CASES.get(draw(st.sampled_from(CASES)))
    specs = {spec.name: spec for spec in case.params}
    option_specs = {spec.name: spec for spec in law.options}
    param_names = draw(st.lists(st.sampled_from([*specs, "bogus"]), max_size=3, unique=True))
    option_names = draw(
        st.lists(st.sampled_from([*option_specs, "bogus"]), max_size=2, unique=True)
    )
    params = {n: draw(plausible(specs[n]) if n in specs else values) for n in param_names}
    options = {
        n: draw(plausible(option_specs[n]) if n in option_specs else values) for n in option_names
    }
    return law.name, case.name, params, options


def _options(law, options):
    known = {spec.name for spec in lawbench.LAWS.get(law).options}
    return {**{k: v for k, v in BUDGET.items() if k in known}, **options}


@settings(
    max_examples=100,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(calls())
def test_the_api_answers_or_raises_a_lawbench_error(call):
    law, case, params, options = call
    try:
        trial = lawbench.evaluate(law, case, _options(law, options), **params)
    except lawbench.LawbenchError:
        return
    outcome = trial.outcome
    assert all(math.isfinite(x) for x in outcome.v_plus)
    for result in lawbench.run_checks(trial).values():
        assert isinstance(result.verdict, lawbench.Verdict)


def _text(value):
    if isinstance(value, list | tuple):
        return ",".join(_text(v) for v in value)
    return "" if value is None else str(value)


def run_cli(argv):
    """Exit code and stderr of the command line, run in this process."""
    stderr, stdout = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(stdout):
        code = main(argv)
    return code, stderr.getvalue()


@settings(
    max_examples=100,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(calls(), st.booleans())
def test_the_command_line_exits_with_a_documented_code_and_one_line(call, as_json):
    law, case, params, options = call
    argv = ["solve", law, case]
    for name, value in params.items():
        argv += ["--set", f"{name}={_text(value)}"]
    for name, value in _options(law, options).items():
        argv += ["--option", f"{name}={_text(value)}"]
    if as_json:
        argv.append("--json")
    code, stderr = run_cli(argv)
    assert code in (0, 2, 3, 4), stderr
    if code:
        assert stderr.count("\n") == 1 and stderr.startswith("lawbench: "), stderr
        assert "Traceback" not in stderr


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["solve"],
        ["solve", "newton"],
        ["solve", "nope", "three_ball_chain"],
        ["solve", "newton", "nope"],
        ["solve", "newton", "three_ball_chain", "--set", "e"],
        ["solve", "newton", "three_ball_chain", "--set", "=1"],
        ["describe", "nope"],
        ["run", "--laws", "nope", "--cases", "three_ball_chain"],
        ["frobnicate"],
    ],
    ids=lambda argv: " ".join(argv) or "nothing",
)
def test_malformed_command_lines_exit_2(argv):
    code, stderr = run_cli(argv)
    assert code == 2, stderr
    assert "Traceback" not in stderr
