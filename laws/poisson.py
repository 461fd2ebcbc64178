"""Poisson's kinetic restitution law in the form of Pfeiffer and Glocker.

Source: Poisson's hypothesis, the expansion impulse is ``e`` times the compression impulse
(Brogliato, *An introduction to impact dynamics*, 2010, kinetic coefficient); for several
contacts the two complementarity problems of F. Pfeiffer and C. Glocker, *Multibody Dynamics
with Unilateral Contacts* (Wiley, 1996), ch. 7:

- compression: ``uc = un- + G Pc``, ``0 <= uc _|_ Pc >= 0``;
- expansion: ``un+ = uc + G (E Pc + L)``, ``0 <= un+ _|_ L >= 0``, and ``Pn = (1 + E) Pc + L``.

Both are solved exactly, as non-negative least squares (Lawson-Hanson active set); the
expansion problem is degenerate (every contact that ended compression closed has ``uc = 0``),
where an interior-point method loses accuracy.

Redundant contacts (normals dependent in the kinetic metric: ``G`` singular on the contacts
that end compression closed) share the compression impulse in a way the law leaves open. The
velocity after compression is unique, and so is the outcome when the coefficients of the
redundant contacts are equal (a contact given twice); when they differ, the outcome depends on
the split, and the law refuses the problem (`NotApplicable`) instead of picking one.

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart. The outcome is admissible
(``un+ >= 0``) with non-negative impulses by construction. A closed contact already separating
before the impact receives nothing in compression unless the others push it, and in expansion
only what keeps it from approaching (L). For one approaching contact the law equals Newton's.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.linalg

from lawbench.checks.regions import separating_contact
from lawbench.core.errors import NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.tags import Tags
from lawbench.core.verdicts import Claim
from lawbench.laws._claims import PAOLI_DISCONTINUITY, RIGID_DISPERSION, keeps_energy
from lawbench.numerics.solvers import ENUMERATION_MAX, enumerate_lcp, solve_lcp

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch


class Poisson(Law):
    """Poisson's law: compression LCP, then expansion LCP with ``E`` times its impulse."""

    name = "poisson"
    summary = "Poisson's kinetic restitution: compression then expansion complementarity problems"
    source = "Pfeiffer and Glocker 1996, ch. 7; Brogliato 2010, kinetic coefficient"
    tags = Tags(several_contacts=True)
    separating_rule = (
        "a separating contact takes a compression impulse only when the others make it "
        "approach, and in expansion only the impulse L that keeps it from approaching"
    )
    findings = (
        PAOLI_DISCONTINUITY,
        RIGID_DISPERSION,
        Claim(
            "energy_kept",
            separating_contact,
            "Pfeiffer and Glocker 1996, ch. 7: the expansion impulse L",
            "a contact that separates before the impact can be driven to approach by the "
            "restitution impulses of the others; the impulse L that stops it is plastic and "
            "takes energy even at e = 1",
            (("three_ball_chain", "separating contact"),),
        ),
    )
    guarantees = (
        keeps_energy(
            "Pfeiffer and Glocker 1996, ch. 7; dT = (1 - e^2) Pc.un- / 2 without L",
            "at e = 1 the compression impulse Pc restituted in full gives dT = 0 by the "
            "compression complementarity, and no approaching contact needs L",
        ),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        G, e = problem.delassus, problem.restitution("kinetic")
        compression = solve_lcp(G, problem.un, method="nnls")
        _refuse_open_split(G, e, compression.w)
        restitution = e * compression.z
        expansion = solve_lcp(G, compression.w + G @ restitution, method="nnls")
        Pn = compression.z + restitution + expansion.z
        diagnostics = {
            "formulation": f"compression {compression.method}, expansion {expansion.method}",
            "compression_impulse": compression.z.tolist(),
        }
        return Outcome.from_impulses(problem, Pn, diagnostics=diagnostics)

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """Both complementarity problems by active-set enumeration, for every problem at once."""
        if batch.m > ENUMERATION_MAX:
            return None
        G, e = batch.delassus, batch.restitution("kinetic")
        if (np.linalg.eigvalsh(G)[:, 0] <= SINGULAR * np.abs(G).max(axis=(1, 2))).any():
            return None  # redundant contacts: one by one, where the law decides or refuses
        compression, found = enumerate_lcp(G, batch.un)
        slack = np.einsum("kij,kj->ki", G, compression) + batch.un
        restitution = e * compression
        expansion, found_too = enumerate_lcp(G, slack + np.einsum("kij,kj->ki", G, restitution))
        if not (found.all() and found_too.all()):
            return None
        return compression + restitution + expansion, "compression and expansion LCPs (batch)"


# Relative size below which an eigenvalue of G, or a velocity change, is rounding.
SINGULAR = 1e-10


def _refuse_open_split(G: np.ndarray, e: np.ndarray, slack: np.ndarray) -> None:
    """Refuse when the split of the compression impulse among redundant contacts decides v+.

    ``slack`` is the gap rate after compression: the contacts with none share the impulse, in
    any split ``Pc + d`` with ``G d = 0`` on them. The split moves the bodies after expansion by
    ``G (e d)``; where that is not zero for some such ``d``, the answer depends on the split.
    """
    closed = np.flatnonzero(slack <= SINGULAR * max(float(np.abs(slack).max()), 1.0))
    if closed.size < 2:
        return
    block = G[np.ix_(closed, closed)]
    splits = scipy.linalg.null_space(block, rcond=SINGULAR)
    if (
        splits.size
        and np.abs(block @ (e[closed, None] * splits)).max() > SINGULAR * np.abs(block).max()
    ):
        raise NotApplicable(
            f"poisson: contacts {closed.tolist()} are redundant (their normals are dependent in "
            "the kinetic metric) and their coefficients differ: the split of the compression "
            "impulse among them, which Poisson's law leaves open, decides the outcome"
        )


LAWS.register(Poisson())
