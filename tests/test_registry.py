"""Registries: names, duplicates, lazy loading, unavailable entries."""

import sys
import types

import pytest

import lawbench
from lawbench.core.errors import BudgetExceeded
from lawbench.core.guards import alarm
from lawbench.core.registry import Registry


def test_the_shipped_laws_and_cases_are_registered():
    assert {"newton", "poisson", "moreau", "sequential"} <= set(lawbench.LAWS.names())
    assert {"three_ball_chain", "two_balls_wall", "ball_chain"} <= set(lawbench.CASES.names())
    assert lawbench.LAWS.unavailable == {}


def test_a_duplicate_name_is_an_error():
    with pytest.raises(ValueError, match="law 'newton' is already registered"):
        lawbench.LAWS.register(lawbench.LAWS.get("newton"))


def test_an_unknown_name_lists_the_known_ones():
    with pytest.raises(lawbench.InvalidProblem, match="unknown case 'cradle'; known: ball_chain"):
        lawbench.CASES.get("cradle")


def test_a_module_with_a_missing_dependency_is_skipped_with_its_reason(tmp_path, monkeypatch):
    """Like Gymnasium's registry: one entry's missing dependency does not break the others."""
    package = tmp_path / "plugin_laws"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "fine.py").write_text(
        "import plugin_registry\n"
        "plugin_registry.REGISTRY.register(type('Entry', (), {'name': 'fine'})())\n"
    )
    (package / "heavy.py").write_text("import a_package_that_is_not_installed\n")
    registry = Registry("law", "plugin_laws", object)
    holder = types.ModuleType("plugin_registry")
    holder.REGISTRY = registry
    monkeypatch.setitem(sys.modules, "plugin_registry", holder)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert registry.names() == ["fine"]
    assert "a_package_that_is_not_installed" in registry.unavailable["heavy"]
    with pytest.raises(lawbench.InvalidProblem, match="missing dependency"):
        registry.get("heavy")


def test_a_time_bound_that_rings_during_the_load_leaves_no_entry_behind(tmp_path, monkeypatch):
    """A solve's alarm that rings while its worker imports the laws stops the solve, not the load.

    Under load, a worker's first cell imported the law modules inside its time bound; the bound
    stopped the import half-way and every later cell of that worker was refused with "unknown
    law" for the modules after the stop. The bound still ends the call, once every module is in.
    """
    package = tmp_path / "slow_laws"
    package.mkdir()
    (package / "__init__.py").write_text("")
    for name, pause in (("first", 0.0), ("second", 0.3), ("third", 0.0)):
        (package / f"{name}.py").write_text(
            "import time, slow_registry\n"
            f"time.sleep({pause})\n"
            f"slow_registry.REGISTRY.register(type('Entry', (), {{'name': {name!r}}})())\n"
        )
    registry = Registry("law", "slow_laws", object)
    holder = types.ModuleType("slow_registry")
    holder.REGISTRY = registry
    monkeypatch.setitem(sys.modules, "slow_registry", holder)
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(BudgetExceeded), alarm(0.1):
        registry.names()
    assert registry.names() == ["first", "second", "third"]
