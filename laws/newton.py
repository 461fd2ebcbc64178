"""Newton's kinematic restitution law, at every closed contact at once.

Source: Newton's law of restitution ``un+ = -e un-``; for several contacts the generalized
Newton law (Brogliato, *An introduction to impact dynamics*, 2010, three-ball chain,
equation 29): every closed contact is active and ``Wn.T v+ = -E Wn.T v-`` with ``E`` the
diagonal of the contacts' kinematic coefficients. The impulses solve ``G Pn = -(1 + E) un-``
with ``G = Wn.T M^-1 Wn`` the Delassus matrix.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart. The law is applied as stated to
every closed contact, including one that is already separating (``un- > 0``), which then is
asked to approach at ``-e un-``; the impulses are whatever the linear system gives, negative
(tensile) ones included. Both are defects of the law, reported by the checks (``impulse_sign``,
``admissible``, ``energy_gain``) and never corrected here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.checks.regions import lifting_contacts, resting_contact, separating_contact
from lawbench.core.errors import NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.core.metric import is_diagonal
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.tags import Tags
from lawbench.core.verdicts import Claim
from lawbench.laws._claims import PAOLI_DISCONTINUITY, RIGID_DISPERSION, keeps_energy

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch

_SOURCE = "Brogliato 2010, eq. (29) and the discussion of separating contacts after it"
_ASKS_APPROACH = (
    "every closed contact is active: the wall or ball contact that separates before the "
    "impact is asked to approach at -e un- after it"
)


class Newton(Law):
    """Generalized Newton law: ``un+ = -e un-`` at every closed contact."""

    name = "newton"
    summary = "Newton's kinematic restitution at every closed contact at once"
    source = "Newton's law; generalized Newton law, Brogliato 2010, eq. (29)"
    tags = Tags(several_contacts=True)
    # A closed form with no accuracy knob: its start-up is the cost of the smallest command.
    bench_roles = ("start_up",)
    separating_rule = (
        "every closed contact is restituted, un+ = -e un-: a separating contact is asked "
        "to approach and may take a tensile impulse (tensile_contacts)"
    )

    findings = (
        PAOLI_DISCONTINUITY,
        RIGID_DISPERSION,
        Claim(
            "admissible",
            separating_contact,
            _SOURCE,
            _ASKS_APPROACH,
            (("three_ball_chain", "separating contact"), ("two_balls_wall", "separating ball")),
        ),
        Claim(
            "impulse_sign",
            separating_contact,
            _SOURCE,
            "holding a separating contact to un+ = -e un- needs a tensile impulse",
            (("three_ball_chain", "separating contact"),),
        ),
        Claim(
            "impulse_sign",
            resting_contact,
            "Brogliato 2010, eq. (29) and the rocking block (Housner 1963): the pivot that "
            "does not separate before the landing",
            "a contact at rest is held at un+ = -e un- = 0: where the impact of another "
            "contact would lift it (the rocking block's pivot) only a tensile impulse keeps it "
            "down, -5.8 N s on the elastic frictionless block",
            (("rocking_block", "elastic frictionless"),),
        ),
        Claim(
            "impulse_sign",
            lifting_contacts,
            _SOURCE,
            "every closed contact is held at un+ = -e un-, also one that the impulse of another "
            "lifts (G_ij > 0): holding it down, approaching or not, takes a tensile impulse",
        ),
        Claim(
            "energy_gain",
            separating_contact | lifting_contacts,
            "Brogliato 2010, eq. (29); dT = sum Pn_j (1 - e_j) un-_j / 2 for un+ = -e un-",
            "each contact adds Pn_j (1 - e_j) un-_j / 2 to dT: positive where an approaching "
            "contact takes a tensile impulse (another's impulse lifts it) or a separating one "
            "is pushed, so below e = 1 the law can create energy",
        ),
    )
    guarantees = (
        keeps_energy(
            "Brogliato 2010, eq. (29); dT = sum Pn_j (un-_j + un+_j) / 2",
            "at e = 1 every closed contact leaves with un+ = -un-, so each term of dT vanishes",
        ),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        G = problem.delassus
        change = -(1.0 + problem.restitution("kinematic")) * problem.un
        if is_diagonal(G):
            Pn = change / np.diag(G)
            formulation = "closed form" if problem.m == 1 else "decoupled (diagonal Delassus)"
        else:
            Pn, formulation = _solve_independent(G, change), "linear system"
            if Pn is None:
                Pn, formulation = _solve_dependent(G, change), "least squares (dependent contacts)"
        diagnostics = {
            "formulation": formulation,
            "tensile_contacts": [int(j) for j in np.flatnonzero(Pn < 0)],
        }
        return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics)

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """``G Pn = -(1 + E) un-`` for every problem; dependent contacts go one by one."""
        change = -(1.0 + batch.restitution("kinematic")) * batch.un
        Pn = _solve_independent(batch.delassus, change)
        return None if Pn is None else (Pn, "linear system (batch)")


# Condition number past which the contacts count as dependent (redundant).
DEPENDENT = 1e12


def _solve_independent(G: np.ndarray, change: np.ndarray) -> np.ndarray | None:
    """Solve ``G P = change`` (stacked: ``G`` (..., m, m)) by LU; None if a ``G`` is singular."""
    if (np.linalg.cond(G) > DEPENDENT).any():
        return None
    return np.linalg.solve(G, change[..., None])[..., 0]


def _solve_dependent(G: np.ndarray, change: np.ndarray) -> np.ndarray:
    """Solve ``G P = change`` by least squares.

    Dependent (redundant) contacts get the least-norm impulses; their targets must agree, or
    the law has no solution.
    """
    Pn, *_ = np.linalg.lstsq(G, change, rcond=None)
    residual = np.abs(G @ Pn - change).max()
    if residual > 1e-9 * max(np.abs(change).max(), 1e-300):
        raise NotApplicable(
            "newton: the contacts are dependent and their restitution targets disagree "
            f"(residual {residual:.3g}): the law has no solution"
        )
    return Pn


LAWS.register(Newton())
