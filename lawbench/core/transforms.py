"""Named transforms of a built problem: a cell stays law + scene + params + options + transform.

So every cell stays reproducible. A transform is spelled ``NAME=VALUE`` (or ``NAME`` alone for
its default value), the same in a study's table and on the command line
(``lawbench solve LAW SCENE --transform grazing=1e-08``):

- ``grazing=SPEED``: the pre-impact velocity changed along ``M^-1 Wn`` only, so that every gap
  rate is scaled by one factor and the fastest approach becomes SPEED (m/s); the motion the
  contacts do not see (orthogonal to them in the kinetic metric: the momentum of a free chain,
  the slip of a sphere) stays;
- ``duplicated=J``: contact J (default 0) given a second time, with its normal and tangential
  columns and its parameters: a redundant constraint.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.problem import ImpactProblem


@dataclass(frozen=True)
class Transform:
    """A named change of a built problem, with one number as its argument.

    Attributes
    ----------
    name : str
        The name users type.
    doc : str
        What it does, with the unit of its value.
    apply : callable
        ``(problem, value) -> problem``.
    default : float or None
        The value of ``NAME`` spelled alone; None when a value is required.
    domain : str
        The values it takes, as `parse` names them when refusing another.
    accepts : callable
        ``value -> bool``: whether ``value`` lies in ``domain``, whatever the problem.
    """

    name: str
    doc: str
    apply: Callable[[ImpactProblem, float], ImpactProblem]
    default: float | None = None
    domain: str = "a finite number"
    accepts: Callable[[float], bool] = math.isfinite


def grazing(problem: ImpactProblem, speed: float) -> ImpactProblem:
    """``problem`` with its gap rates scaled so that the fastest approach is ``speed``."""
    if not 0 < speed < math.inf:
        raise InvalidProblem(f"grazing speed {speed:g}: must be positive and finite")
    un = problem.un
    fastest = float(-un.min())
    if fastest <= 0:
        raise InvalidProblem("grazing: no contact approaches, nothing to make grazing")
    change, *_ = np.linalg.lstsq(problem.delassus, (speed / fastest - 1.0) * un, rcond=None)
    try:
        return dataclasses.replace(problem, v=problem.v + problem.solve_mass(problem.Wn @ change))
    except InvalidProblem as exc:
        raise InvalidProblem(
            f"grazing={speed:g}: the velocity leaves double precision ({exc})"
        ) from None


def duplicated(problem: ImpactProblem, contact: float = 0) -> ImpactProblem:
    """``problem`` with contact ``contact`` given a second time (a redundant constraint)."""
    j = int(contact)
    if j != contact or not 0 <= j < problem.m:
        raise InvalidProblem(
            f"duplicated={contact:g}: no contact {contact:g} (0 to {problem.m - 1})"
        )
    Wt = problem.Wt
    if Wt is not None:
        blocks = Wt.reshape(problem.n, problem.m, problem.d)
        Wt = np.concatenate([blocks, blocks[:, j : j + 1]], axis=1).reshape(problem.n, -1)
    return dataclasses.replace(
        problem,
        Wn=np.column_stack([problem.Wn, problem.Wn[:, j]]),
        Wt=Wt,
        contacts=[*problem.contacts, problem.contacts[j]],
        gaps=np.append(problem.gaps, problem.gaps[j]),
    )


TRANSFORMS = {
    t.name: t
    for t in (
        Transform(
            "grazing",
            "fastest approach made SPEED (m/s), unseen motion kept",
            grazing,
            domain="a positive, finite speed",
            accepts=lambda speed: 0 < speed < math.inf,
        ),
        Transform(
            "duplicated",
            "contact J (default 0) given twice",
            duplicated,
            0.0,
            domain="a contact's number (0, 1, ...)",
            accepts=lambda j: 0 <= j < math.inf and j == int(j),
        ),
    )
}


def parse(spelling: str) -> tuple[Transform, float]:
    """The transform and value of ``NAME=VALUE`` (or ``NAME``).

    Raises
    ------
    InvalidProblem
        For an unknown name, or a value that is not a number or lies outside the transform's
        domain (a grazing speed of nan, a contact numbered 1.5), so that a run refuses it
        before any work.
    """
    name, sep, text = spelling.partition("=")
    transform = TRANSFORMS.get(name.strip())
    if transform is None:
        known = ", ".join(f"{t.name} ({t.doc})" for t in TRANSFORMS.values())
        raise InvalidProblem(f"unknown transform {name.strip()!r}; known: {known}")
    if not sep:
        if transform.default is None:
            raise InvalidProblem(f"transform {transform.name}: give a value ({transform.doc})")
        return transform, transform.default
    try:
        value = float(text)
    except ValueError:
        raise InvalidProblem(f"transform {spelling!r}: {text!r} is not a number") from None
    if not transform.accepts(value):
        raise InvalidProblem(f"transform {spelling!r}: {text!r} is not {transform.domain}")
    return transform, value


def spell(name: str, value: float | None = None) -> str:
    """The spelling of a transform and its value, exact when read back (``grazing=1e-08``)."""
    return name if value is None else f"{name}={float(value)!r}"


def apply(spelling: str, problem: ImpactProblem) -> ImpactProblem:
    """``problem`` changed by the transform spelled ``spelling`` ('' leaves it as it is)."""
    if not spelling:
        return problem
    transform, value = parse(spelling)
    return transform.apply(problem, value)
