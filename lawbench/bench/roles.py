"""The roles laws and scenes declare (``bench_roles``) to be the bench's subjects.

The bench names no law and no scene: it takes, for each role, the first registered entry that
declares it.
"""

from __future__ import annotations

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.core.registry import Registry

ROLES = {
    # the law whose impulses solve the frictionless LCP ``0 <= G z + q _|_ z >= 0`` that the
    # peers (clarabel, the numpy enumeration, Siconos' Lemke) solve;
    "lcp": "the law timed against the LCP peers",
    # the law and the scene of the small command whose start-up is timed;
    "start_up": "the law and scene of the timed start-up command",
    # the scene of n balls in a row (its parameter ``n``), solved from its parameters;
    "long_chain": "the n-ball chain scene solved from its parameters",
    # the scenes every engine (a law whose ``engine`` is true) is timed on, at each setting.
    "engine_cost": "the scenes the engines' cost per impact is measured on",
}


def subject(registry: Registry, role: str) -> str:
    """The name of the first entry of ``registry`` (by name) that declares ``role``.

    Raises
    ------
    InvalidProblem
        When no entry declares it.
    """
    return subjects(registry, role)[0]


def subjects(registry: Registry, role: str) -> list[str]:
    """The names of every entry of ``registry`` (by name) that declares ``role``.

    Raises
    ------
    InvalidProblem
        When no entry declares it.
    """
    names = [name for name, entry in registry.items() if role in entry.bench_roles]
    if not names:
        raise InvalidProblem(f"no {registry.kind} declares the bench role {role!r} ({ROLES[role]})")
    return names


def start_up_command() -> tuple[str, ...]:
    """The small command whose start-up is timed: ``solve LAW SCENE`` of the start-up role."""
    return ("solve", subject(LAWS, "start_up"), subject(CASES, "start_up"))
