"""Regions of problems where a law's claim applies, decided from the trial itself.

A region is physics, not a list of scenes: "a closed contact separates before the impact",
"a frictional contact whose normal and tangential directions are coupled", "two contacts at a
kinetic angle other than 90 degrees". So a claim declared on the shared scenes holds just the
same on a problem of the user's own. `example` names one scene's named example, for claims
that only a given configuration shows.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.core.mechanics import kinetic_angles, separating_contacts
from lawbench.core.metric import is_sparse
from lawbench.core.verdicts import EVERYWHERE, Region

# Relative size of a normal-tangential Delassus entry that counts as coupling.
COUPLING = 1e-9
# A contact's gap rate below this fraction of the largest one counts as rest.
REST = 1e-12
# Kinetic angles within this many degrees of 90 count as orthogonal.
ORTHOGONAL_DEG = 1e-6

__all__ = [
    "EVERYWHERE",
    "coupled_friction",
    "damped_contacts",
    "dissipative_contacts",
    "example",
    "frictional",
    "frictionless",
    "lifting_contacts",
    "nonlinear_springs",
    "oblique_contacts",
    "option",
    "recompressed_contact",
    "resting_contact",
    "separating_contact",
]


def _separating(trial: Any) -> bool:
    return bool(separating_contacts(trial.problem))


separating_contact = Region("a closed contact separates before the impact", _separating)


def _resting(trial: Any) -> bool:
    problem = trial.problem
    un, closed = np.asarray(problem.un), np.asarray(problem.closed)
    scale = max(float(np.abs(un).max()), 1e-300)
    resting = np.flatnonzero(closed & (np.abs(un) <= REST * scale))
    approaching = np.flatnonzero(closed & (un < -REST * scale))
    if resting.size == 0 or approaching.size == 0:
        return False
    G = problem.delassus
    G = G.toarray() if is_sparse(G) else np.asarray(G)
    return bool(np.abs(G[np.ix_(resting, approaching)]).max() > COUPLING * np.abs(G).max())


resting_contact = Region(
    "a closed contact at rest before the impact (un- = 0), coupled to one that approaches",
    _resting,
)


def _lifting(trial: Any) -> bool:
    problem = trial.problem
    closed = np.asarray(problem.closed)
    if closed.sum() < 2:
        return False
    G = problem.delassus
    if is_sparse(G):
        G = G.tocoo()
        rows, columns, values = G.row, G.col, G.data
    else:
        rows, columns = np.nonzero(np.asarray(G))
        values = np.asarray(G)[rows, columns]
    between = closed[rows] & closed[columns] & (rows != columns)
    return bool((values[between] > COUPLING * np.abs(values).max()).any())


lifting_contacts = Region(
    "two closed contacts where an impulse at one lifts the other (Delassus entry G_ij > 0)",
    _lifting,
)

frictional = Region("some contact has friction", lambda trial: trial.problem.frictional)
frictionless = ~frictional


def _coupled(trial: Any) -> bool:
    problem = trial.problem
    if not problem.frictional:
        return False
    G, m, d = problem.contact_delassus, problem.m, problem.d
    for j in np.flatnonzero(problem.mu > 0):
        normal = G[j, j]
        tangential = G[j, m + j * d : m + (j + 1) * d]
        if np.abs(tangential).max() > COUPLING * normal:
            return True
    return False


coupled_friction = Region(
    "a frictional contact whose normal and tangential directions are coupled through the "
    "mass matrix (G_nt != 0)",
    _coupled,
)


def _oblique(trial: Any) -> bool:
    problem = trial.problem
    closed = np.flatnonzero(problem.closed)
    if closed.size < 2:
        return False
    angles = kinetic_angles(problem)[np.ix_(closed, closed)]
    off = ~np.eye(closed.size, dtype=bool)
    return bool((np.abs(angles[off] - 90.0) > ORTHOGONAL_DEG).any())


oblique_contacts = Region("two closed contacts at a kinetic angle other than 90 degrees", _oblique)


def option(name: str, value: Any) -> Region:
    """The law runs with option ``name`` set to ``value``."""
    return Region(f"option {name} = {value}", lambda trial: trial.options.get(name) == value)


def example(case: str, name: str) -> Region:
    """The scene ``case`` at its named example ``name``."""

    def contains(trial: Any) -> bool:
        if trial.case is None or trial.case.name != case:
            return False
        return trial.params == trial.case.parameters(**trial.case.examples[name])

    return Region(f"{case}, example '{name}'", contains)


def _nonlinear(trial: Any) -> bool:
    problem = trial.problem
    return int(problem.closed.sum()) > 1 and any(c.exponent != 1 for c in problem.contacts)


nonlinear_springs = Region(
    "several contacts, some with a force law other than linear (exponent != 1)", _nonlinear
)


recompressed_contact = Region(
    "a contact whose spring gave back all its energy is compressed again within the impact",
    lambda trial: bool(trial.outcome.diagnostics.get("recompressed")),
)


def _dissipative(trial: Any) -> bool:
    problem = trial.problem
    closed = problem.closed
    return int(closed.sum()) > 1 and bool((problem.restitution("energetic")[closed] < 1.0).any())


dissipative_contacts = Region(
    "several closed contacts, some dissipative (energetic e < 1)", _dissipative
)


def _damped(trial: Any) -> bool:
    problem = trial.problem
    e = problem.restitution("kinematic")[problem.closed]
    return bool(((e > 0.0) & (e < 1.0)).any())


damped_contacts = Region(
    "a closed contact with 0 < e < 1 (a dashpot: neither elastic nor plastic)", _damped
)
