"""Registries: names, duplicates, lazy loading, unavailable entries."""

import sys
import types

import pytest

import lawbench
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
