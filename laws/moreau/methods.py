"""Which of Moreau's methods answers a frictional problem, in turn, each within its step bound.

``auto`` tries Gauss-Seidel, then the fixed point, on a large impact and in contact space, and
the fixed point alone on a small one (the law's docstring says why); an explicit ``method`` is
tried alone. The solve's open budget bounds each method's steps, counted from zero.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from lawbench.core.errors import BudgetExceeded, SolverFailure
from lawbench.core.guards import current_budget

# Contacts up to which method auto solves an impact by the fixed point: beyond, a sweep costs a
# fraction of a cone QP (82 stacked boxes: 43 sweeps in 0.05 s, 11 cone QPs in 5.6 s).
FIXED_POINT_MAX = 8
# The bounds of max_steps = 0: cone QPs; sweeps per contact, and at least SWEEPS_MIN.
FIXED_POINT_STEPS, SWEEPS_PER_CONTACT, SWEEPS_MIN = 1000, 20, 1000


def methods_for(options: dict[str, Any], m: int, in_contact_space: bool) -> tuple[str, ...]:
    """The methods to try in turn on a frictional problem of ``m`` contacts.

    An explicit ``method`` alone. ``auto``: the fixed point for Anitescu's relaxation (one cone
    QP) and for an impact of 2 to `FIXED_POINT_MAX` contacts; otherwise Gauss-Seidel (at one
    contact its exact local solver: take-off, stick or slip in closed form), then
    the fixed point where the sweeps become stationary above ``tol`` or run out of their bound
    (on a singular Delassus matrix, whose contact states the interior-point steps still find).
    """
    method = options["method"]
    if method != "auto":
        return (method,)
    if options["friction"] == "relaxed" or (not in_contact_space and 1 < m <= FIXED_POINT_MAX):
        return ("fixed_point",)
    return ("nsgs", "fixed_point")


@contextmanager
def bounded(options: dict[str, Any], method: str, m: int) -> Iterator[None]:
    """The solve's open budget bounds ``method`` on ``m`` contacts, its steps counted from 0.

    At ``max_steps`` as given; at its default 0, the problem's size sets the bound.
    """
    steps = options["max_steps"] or FIXED_POINT_STEPS
    if method == "nsgs" and not options["max_steps"]:
        steps = max(SWEEPS_MIN, SWEEPS_PER_CONTACT * m)
    budget = current_budget()
    saved = budget.max_steps, budget.steps
    budget.max_steps, budget.steps = steps, 0
    try:
        yield
    finally:
        budget.max_steps, budget.steps = saved


def out_of_time(failure: SolverFailure) -> bool:
    """Whether ``failure`` is the solve's time running out, which no other method may follow.

    The wall-clock guard's stop (`lawbench.core.guards.stopped`) and ``max_seconds`` end the
    solve; a method's own step bound (``max_steps``) hands the problem on.
    """
    return isinstance(failure, BudgetExceeded) and failure.budget != "max_steps"


def in_turn(
    solvers: dict[str, Callable[[], tuple[np.ndarray, dict[str, Any]]]],
    methods: tuple[str, ...],
    options: dict[str, Any],
    m: int,
) -> tuple[np.ndarray, dict[str, Any]]:
    """The first answer of ``methods`` in turn on ``m`` contacts, each within its step bound.

    A method that fails (`SolverFailure`, or its own step bound ran out) hands the problem to
    the next; the time budget ends the solve. Diagnostics name the ``method`` that answered
    and, under ``after``, the failures of those tried before it.

    Raises
    ------
    SolverFailure
        The last method's failure (a `BudgetExceeded` when a budget ran out), its message
        followed by the earlier ones'.
    """
    failures: list[str] = []
    for method in methods:
        try:
            with bounded(options, method, m):
                P, diagnostics = solvers[method]()
            break
        except SolverFailure as failure:
            if method == methods[-1] or out_of_time(failure):
                if failures:
                    failure.args = (f"{failure} (after {'; '.join(failures)})",)
                raise
            failures.append(f"{method}: {failure}")
    diagnostics["method"] = method
    if failures:
        diagnostics["after"] = failures
    return P, diagnostics
