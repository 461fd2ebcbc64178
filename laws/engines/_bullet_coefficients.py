"""The coefficients Bullet gives each body, from the scene's coefficients of each pair.

Bullet gives a contact the products of its two bodies' restitutions and frictions, the friction
clamped to `MAX_FRICTION` (btManifoldResult.cpp: calculateCombinedRestitution and
calculateCombinedFriction, https://github.com/bulletphysics/bullet3): a user sets a body's
coefficients (PyBullet's changeDynamics), not a pair's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from lawbench.core.errors import NotApplicable
from lawbench.core.geometry import Geometry

# Bullet clamps the product of two frictions to this.
MAX_FRICTION = 10.0


def body_coefficients(geometry: Geometry, tuned: bool) -> list[tuple[float, float]]:
    """Each body's restitution and lateral friction (changeDynamics).

    Default: the mean of the scene's coefficients over the body's pairs, as a user gives a body
    its coefficients. Tuned: factors whose products over each pair's bodies are the pair's
    coefficients (`factors`).

    Raises
    ------
    NotApplicable
        When no such factors exist (tuned).
    """
    count = len(geometry.bodies)
    columns = []
    for kind in ("e", "mu"):
        values = [getattr(pair, kind) for pair in geometry.pairs]
        if not tuned:
            columns.append(means(geometry, values))
            continue
        found = factors(geometry, values)
        if found is None or (kind == "mu" and max(values) > MAX_FRICTION):
            raise NotApplicable(
                f"pybullet: Bullet gives a contact the product of its two bodies' {kind}; no "
                f"per-body values have the scene's {kind} = {values} as their products"
            )
        columns.append(found)
    return [(columns[0][k], columns[1][k]) for k in range(count)]


def means(geometry: Geometry, values: Sequence[float]) -> list[float]:
    """Each body's mean of ``values`` over the pairs it takes part in (0 for none)."""
    sums, counts = np.zeros(len(geometry.bodies)), np.zeros(len(geometry.bodies))
    for pair, value in zip(geometry.pairs, values, strict=True):
        for body in (pair.a, pair.b):
            sums[geometry.index[body]] += value
            counts[geometry.index[body]] += 1
    return (sums / np.maximum(counts, 1)).tolist()


def factors(geometry: Geometry, values: Sequence[float]) -> list[float] | None:
    """Per-body factors whose products over each pair's two bodies are the pairs' ``values``.

    A body whose pairs all have value 0 takes 0; the others are found along the pairs from a
    fixed body (which keeps 1) or from the first body of each connected group; None when the
    pairs ask for two different factors of one body or put a zero next to a positive value.
    """
    index = geometry.index
    edges = [(index[p.a], index[p.b], v) for p, v in zip(geometry.pairs, values, strict=True)]
    zero = {
        k for k in range(len(geometry.bodies)) if all(v == 0 for a, b, v in edges if k in (a, b))
    }
    factors: dict[int, float] = {k: 0.0 for k in zero}
    live = [(a, b, v) for a, b, v in edges if a not in zero and b not in zero]
    if any(v == 0 for *_, v in live):
        return None
    roots = sorted(
        set(range(len(geometry.bodies))) - zero,
        key=lambda k: geometry.moving(geometry.bodies[k].name),
    )
    for root in roots:
        if root in factors:
            continue
        factors[root], frontier = 1.0, [root]
        while frontier:
            k = frontier.pop()
            for a, b, v in live:
                if k not in (a, b):
                    continue
                other = b if k == a else a
                wanted = v / factors[k]
                if other not in factors:
                    factors[other] = wanted
                    frontier.append(other)
                elif not math.isclose(factors[other], wanted, rel_tol=1e-12):
                    return None
    return [factors.get(k, 1.0) for k in range(len(geometry.bodies))]
