"""Options that several laws share: bounds on their work, and the path along the impact.

`lawbench.core.law.Budget` reads the bounds by name (``max_steps``, ``max_events``), and a law
that records its path returns it in `lawbench.core.outcome.Outcome.path` when ``path`` is true.
"""

from __future__ import annotations

from lawbench.core.spec import Spec


def bound(name: str, default: int, what: str) -> Spec:
    """A bound on a count of the law's work: ``max_steps`` or ``max_events``, at least 1."""
    return Spec(name, default, what, kind="int", low=1)


def path_option(what: str) -> Spec:
    """Whether the answer carries the path along the impact, and what that path holds."""
    return Spec("path", False, f"return {what}", kind="bool")
