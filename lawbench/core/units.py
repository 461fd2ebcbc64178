"""Units of mass, velocity and time near an impact's own scales, and the problem rescaled to them.

A scale-free law (`lawbench.core.law.Law.scale_free`) solves a problem in units where its
heaviest mass and fastest speed are near 1, so that masses of 1e-308 kg or speeds of 1e-300 m/s
neither under- nor overflow in its linear algebra and integrators. The units are powers of two:
rescaling by them rounds nothing. `in_units` rescales a problem.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.core.errors import InvalidProblem

if TYPE_CHECKING:
    from lawbench.core.problem import ImpactProblem

# A problem whose heaviest mass entry and fastest velocity component lie within this factor of
# 1 (about 1e-9 to 1e9) is solved in its own units; beyond, in units near them.
UNIT_BAND = 2.0**30


def binary_scale(size: float) -> float:
    """The power of two nearest ``size`` (1 for zero or a non-finite size).

    Multiplying by it is exact (no digit is rounded) wherever no number under- or overflows.
    """
    if not math.isfinite(size) or size <= 0.0:
        return 1.0
    return math.ldexp(1.0, round(math.log2(size)))


def solving_units(
    M: Any, v: np.ndarray, springs: Iterable[tuple[float, float]]
) -> tuple[float, float, float]:
    """The units of mass, velocity and time a scale-free law solves an impact in.

    ``M`` and ``v`` are the impact's mass matrix and velocity, ``springs`` the stiffness and
    exponent of its contacts.

    Powers of two (`binary_scale`) near the heaviest diagonal entry of M and the fastest
    component of v, or 1 for a scale within `UNIT_BAND` of 1; when one of them is not 1, the
    time unit brings the stiffest contact's stiffness near 1 (the time of its compression),
    else it is 1 too.

    Raises
    ------
    InvalidProblem
        When the impulse or energy unit these give, ``mass velocity`` or ``mass velocity^2``,
        is not a positive double: an answer could not be scaled back.
    """
    # A positive definite M's diagonal entries are positive.
    mass = float(M.diagonal().max())
    speed = float(np.abs(v).max())
    mass_unit, velocity_unit = (
        1.0 if 1.0 / UNIT_BAND <= size <= UNIT_BAND else binary_scale(size)
        for size in (mass, speed)
    )
    energy = mass_unit * velocity_unit * velocity_unit
    if not (mass_unit * velocity_unit > 0.0 and 0.0 < energy < math.inf):
        raise InvalidProblem(
            f"M (largest diagonal entry {mass:.3g}) and v (largest |v| {speed:.3g}) give "
            f"impulses and energies beyond double precision (energy scale "
            f"{mass * speed**2:.3g})"
        )
    if mass_unit == velocity_unit == 1.0:
        return 1.0, 1.0, 1.0
    # Compression time of a spring K d^p loaded by the unit mass at the unit speed:
    # (m / (K v^(p - 1)))^(1 / (p + 1)), in base-2 logarithms to stay clear of overflow.
    mass_log, velocity_log = math.log2(mass_unit), math.log2(velocity_unit)
    time_log = min(
        (mass_log - math.log2(stiffness) - (exponent - 1.0) * velocity_log) / (exponent + 1.0)
        for stiffness, exponent in springs
    )
    return mass_unit, velocity_unit, math.ldexp(1.0, round(time_log))


def stiffness_in_units(
    stiffness: float, exponent: float, mass: float, length: float, time: float
) -> float:
    """A stiffness K d^exponent (N/m^exponent) in units of ``mass``, ``length`` and ``time``.

    N/m^exponent is kg m^(1 - exponent) s^-2: K is multiplied by
    ``length^(exponent - 1) time^2 / mass``, in base-2 logarithms to stay clear of overflow.
    """
    factor_log = (exponent - 1.0) * math.log2(length) + 2.0 * math.log2(time) - math.log2(mass)
    return 2.0 ** (math.log2(stiffness) + factor_log)


def in_units(problem: ImpactProblem, mass: float, velocity: float, time: float) -> ImpactProblem:
    """``problem`` with masses, velocities and times in units ``mass``, ``velocity``, ``time``.

    Lengths are then in units of ``velocity time``: M and v are divided by their units,
    gaps by the length unit, and a stiffness (N/m^exponent = kg m^(1 - exponent) s^-2) is
    multiplied by ``length^(exponent - 1) time^2 / mass``. A damping's unit depends on the
    compliant model that reads it, so it is kept as given: the laws that read it solve in
    the problem's own units (`lawbench.core.law.Law.scale_free`).

    Raises
    ------
    InvalidProblem
        When a number rescaled leaves double precision, naming it and the units.
    """
    length = velocity * time
    contacts, rescaled = [], {}
    for contact in problem.contacts:
        if contact not in rescaled:
            stiffness = stiffness_in_units(contact.stiffness, contact.exponent, mass, length, time)
            rescaled[contact] = dataclasses.replace(contact, stiffness=stiffness)
        contacts.append(rescaled[contact])
    gaps = problem.gaps / length if problem.gaps.any() else None
    try:
        return dataclasses.replace(
            problem, M=problem.M / mass, v=problem.v / velocity, contacts=contacts, gaps=gaps
        )
    except (InvalidProblem, OverflowError) as exc:
        raise InvalidProblem(
            f"in units of {mass:g} kg, {velocity:g} m/s and {time:g} s the problem cannot "
            f"be solved: {exc}"
        ) from None
