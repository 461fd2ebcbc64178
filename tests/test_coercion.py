"""Each parameter of a scene is checked and converted once per solve."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

import lawbench
from lawbench.core.errors import InvalidProblem
from lawbench.core.spec import Spec


@pytest.fixture
def coerced(monkeypatch: pytest.MonkeyPatch) -> Counter:
    """Count `Spec.coerce` calls by parameter name."""
    counts: Counter = Counter()
    coerce = Spec.coerce

    def counted(self: Spec, value: object) -> object:
        counts[self.name] += 1
        return coerce(self, value)

    monkeypatch.setattr(Spec, "coerce", counted)
    return counts


def test_solving_the_1000_ball_chain_coerces_each_parameter_once(coerced):
    outcome = lawbench.solve("moreau", "ball_chain", n=1000)
    assert outcome.v_plus.shape == (1000,)
    scene = {spec.name for spec in lawbench.CASES["ball_chain"].params}
    assert {name: coerced[name] for name in scene} == dict.fromkeys(scene, 1)


def test_building_coerces_each_parameter_once(coerced):
    case = lawbench.CASES["three_ball_chain"]
    case.build(e=0.5)
    assert set(coerced.values()) == {1}


def test_a_list_of_1000_floats_is_checked_without_a_call_per_item(monkeypatch):
    spec = Spec("masses", [1.0], "ball masses", unit="kg", kind="floats", low=0.0, low_open=True)
    calls = Counter()
    number = Spec._number

    def counted(self: Spec, *args: object) -> object:
        calls["number"] += 1
        return number(self, *args)

    monkeypatch.setattr(Spec, "_number", counted)
    assert spec.coerce(list(np.linspace(1.0, 2.0, 1000))) == list(np.linspace(1.0, 2.0, 1000))
    assert calls["number"] == 0


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ([1.0, 2.0, 3.0, "x"], r"masses\[3\] = 'x': not a number"),
        ([1.0, True], r"masses\[1\] = True: not a number"),
        ("1,2,0", r"masses\[2\] = 0: must lie in \(0, inf\)"),
        ([1.0, float("inf")], r"masses\[1\] = inf: must be a finite number"),
    ],
)
def test_a_bad_item_of_a_list_is_named_by_its_index(value, message):
    spec = Spec("masses", [1.0], "ball masses", unit="kg", kind="floats", low=0.0, low_open=True)
    with pytest.raises(InvalidProblem, match=message):
        spec.coerce(value)


def test_a_build_error_names_only_the_parameters_that_differ_from_the_defaults():
    case = lawbench.CASES["billiard"]
    straight = {"offset_side": 0.0, "offset_height": 0.0}
    given = r"radius = 1e-308, offset_side = 0.0, offset_height = 0.0"
    with pytest.raises(InvalidProblem, match=rf"^billiard: {given}: "):
        case.build_from(case.parameters(radius=1e-308, **straight))
