"""Kharaz's oblique impacts against every law that treats one frictional planar contact.

The measured setup (`lawbench.measurements.sets.kharaz`): a 5 mm alumina sphere without spin
strikes a glass anvil at 3.9 m/s at incidences from the normal to grazing. Every registered law
whose tags treat one frictional planar contact solves it through the one way into a solve (the
engines too, at their default settings: the problem carries the setup's geometry), with
the coefficients DEM benchmarks use for this pair, ``e = 0.98`` and ``mu = 0.092``, every other
contact field at its default, and where a law reads stiffness Hertz's ``K = 4/3 E* R^(1/2)``
(exponent 1.5) for alumina (E = 380 GPa, nu = 0.23) on soda-lime glass (70 GPa, 0.25), the
moduli of MFiX's test DEM05: ``E* = 62.9 GPa``, ``K = 4.20e9 N/m^1.5``. The ratio of normal to
tangential stiffness stays at its default, Mindlin's 17/14 for nu = 0.3; Mindlin's ratio for
this pair, ``E* / (4 G*) = 1.16``, is DEM05's ``KN / KT = 1.72 / 1.48``.

Quantities, against the incidence ``a`` from the normal (degrees), in the set's coordinates
``(vx, vy, omega)`` with the contact point at ``(0, -R)``:

- ``tangential_restitution``: ``vx+ / vx-`` of the centre;
- ``rebound_spin``: ``-omega+`` (rad/s): friction spins the sphere clockwise, which the
  digitized points count positive;
- ``rebound_angle``: ``atan(vx+ / vy+)`` of the centre (degrees from the normal);
- ``contact_angle``: ``atan(vt+ / vy+)`` with ``vt+ = vx+ + R omega+`` the contact point's
  tangential velocity (degrees; negative where the contact point moves back against the
  approach, the source's convention).

Each quantity is compared with its digitized points in two ranges of the paper's nominal
incidences: sticking (up to 30 degrees) and sliding (from 40 degrees), each bound widened by
`READING` because the digitized incidences lie up to 1.2 degrees from the nominal angles
(31.09 for 30, 39.03 for 40). Between them lies the onset of gross slip, ``tan a = 7/2 mu
(1 + e)`` for a solid sphere (32.5 degrees).

Finding (Maw, Barber and Fawcett, Wear 38 (1976) 101-114; Kharaz, Gorham and Salman, Powder
Technology 120 (2001) 281-291): below about 30 degrees the measured contact point leaves the
anvil moving backwards, down to -8.5 degrees at 20 degrees, and the centre's tangential
restitution falls to 0.60, below the rolling value ``1 / (1 + m R^2 / I) = 5/7``. The tangential
compliance of the contact stores energy while the contact sticks and gives it back reversed.
A rigid law with Coulomb friction that ends a sticking impact at zero slip (Whittaker's,
Moreau's, Darboux-Keller's, the energetic multiple-impact law's, and Brach's at ``e_t = 0``)
leaves the contact point at rest: a contact angle of zero and a tangential restitution of
exactly 5/7 at every incidence below the onset of gross slip, whatever ``e``. Laws with tangential
springs (Jia's, the compliant contacts' with tangential springs and sliders) reverse; how far
depends on the ratio of tangential to normal stiffness and on ``mu``. Above the onset of gross
slip every law gives Coulomb's sliding impulse and the laws agree with each other and with the
measurements.

Near the normal the two laws with tangential springs part. The compliant contacts hold a
constant tangential stiffness, Mindlin's at the indentation scale, in front of a Hertz normal
force whose stiffness grows from zero: the tangential period is then close to the whole
contact's duration (``omega_t t_c`` about 6.8 rad at this speed), so below about 4 degrees,
where the contact sticks through most of the impact, the tangential impulse nearly cancels
and the centre keeps ``e_t`` of about 0.99 where Kharaz measured 0.79 (unchanged at a tighter
``tol`` and with Radau: the model, not its integration). Jia's linear springs (a tangential
to normal frequency ratio ``(7/2 / eta0^2)^(1/2)`` = 1.7 over half a normal period) give 0.83.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from lawbench.core.law import LAWS
from lawbench.core.problem import ImpactProblem
from lawbench.core.trial import make_trial
from lawbench.measurements.sets import kharaz

# The coefficients of DEM benchmarks of this pair (MFiX DEM05, Di Renzo and Di Maio 2004).
NORMAL_RESTITUTION = kharaz.NORMAL_RESTITUTION
FRICTION = kharaz.KHARAZ.facts["dem_friction"]
# Young's moduli (Pa) and Poisson's ratios of the sphere and the anvil (MFiX DEM05's mfix.dat).
SPHERE = (380.0e9, 0.23)
ANVIL = (70.0e9, 0.25)
# Hertz's exponent of a sphere on a plane.
HERTZ = 1.5
# The fine grid of incidences (degrees from the normal).
GRID = np.arange(1.0, 86.0)
# The nominal bounds of the sticking and the sliding ranges (degrees), and the reading tolerance
# that takes the digitized incidences to their nominal angles.
STICKING = 30.0
SLIDING = 40.0
READING = 1.5
# A contact angle below minus this (degrees) is a reversal: the digitizing's resolution (the
# points at 2.1 and 3.9 degrees read the same 0.77 degrees), far above a rigid law's rounding.
REVERSED = 0.1
# The quantities, in the order of the tables.
QUANTITIES = ("tangential_restitution", "rebound_spin", "rebound_angle", "contact_angle")
# A solve that runs longer than this (seconds) is recorded as failed at its incidence.
MAX_SECONDS = 60.0


def effective_modulus(sphere: tuple[float, float], anvil: tuple[float, float]) -> float:
    """Hertz's contact modulus ``E* = 1 / ((1 - nu1^2) / E1 + (1 - nu2^2) / E2)`` (Pa)."""
    return 1.0 / sum((1.0 - nu**2) / young for young, nu in (sphere, anvil))


def hertz_stiffness(radius: float = kharaz.SETUP.radius) -> float:
    """Hertz's stiffness ``K = 4/3 E* R^(1/2)`` of the sphere on the flat anvil (N/m^1.5)."""
    return 4.0 / 3.0 * effective_modulus(SPHERE, ANVIL) * math.sqrt(radius)


def impact_problem(incidence: float) -> ImpactProblem:
    """The measured impact at ``incidence`` degrees, with the benchmarks' coefficients.

    It carries the setup's geometry, for the engines.
    """
    setup = kharaz.SETUP
    problem = ImpactProblem.from_arrays(
        setup.mass_matrix(),
        [[0.0], [1.0], [0.0]],
        setup.velocity_before(incidence),
        [[1.0], [0.0], [setup.radius]],
        e=NORMAL_RESTITUTION,
        mu=FRICTION,
        stiffness=hertz_stiffness(setup.radius),
        exponent=HERTZ,
    )
    geometry = setup.geometry(NORMAL_RESTITUTION, FRICTION)
    return dataclasses.replace(problem, geometry=geometry)


def frictional_laws() -> list[str]:
    """The registered laws whose tags treat the setup's one frictional planar contact."""
    probe = impact_problem(45.0)
    return [name for name in LAWS.names() if LAWS.get(name).refusal(probe) is None]


def rebound(v_before: np.ndarray, v_after: np.ndarray) -> dict[str, float]:
    """The four quantities of one impact from the centre's velocities before and after."""
    vx, vy, omega = v_after
    contact = vx + kharaz.SETUP.radius * omega
    return {
        "tangential_restitution": float(vx / v_before[0]),
        "rebound_spin": float(-omega),
        "rebound_angle": math.degrees(math.atan2(vx, vy)),
        "contact_angle": math.degrees(math.atan2(contact, vy)),
    }


def law_curve(law: str, incidences: Sequence[float]) -> pd.DataFrame:
    """One law's quantities at ``incidences``: one row per solve.

    A solve that fails records its error class and message in ``error`` and NaN quantities;
    it never raises.
    """
    rows = []
    for incidence in incidences:
        problem = impact_problem(float(incidence))
        row = {"law": law, "incidence": float(incidence), "error": ""}
        try:
            outcome = make_trial(law, problem, max_seconds=MAX_SECONDS).outcome
        except Exception as exc:  # the point records its failure and the curve goes on
            row |= dict.fromkeys(QUANTITIES, math.nan)
            row["error"] = f"{type(exc).__name__}: {exc}"
        else:
            row |= rebound(problem.v, outcome.v_plus)
        rows.append(row)
    return pd.DataFrame(rows, columns=["law", "incidence", *QUANTITIES, "error"])


def measured() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The digitized points of the four quantities: ``(incidence, value)``."""
    return kharaz.curves() | {"contact_angle": kharaz.contact_curve()}


def digitized_incidences() -> np.ndarray:
    """Every incidence at which some quantity was digitized, sorted, each once."""
    return np.unique(np.concatenate([x for x, _ in measured().values()]))


def curves(
    laws: Sequence[str] | None = None, incidences: Sequence[float] | None = None
) -> pd.DataFrame:
    """Every law's quantities on the fine grid and at the digitized incidences.

    Parameters
    ----------
    laws : sequence of str, optional
        Registered law names; every law of `frictional_laws` when None.
    incidences : sequence of float, optional
        Incidences (degrees); `GRID` and `digitized_incidences` when None.

    Returns
    -------
    DataFrame
        One row per law and incidence: ``law, incidence``, the four `QUANTITIES` and
        ``error`` ('' for a solve that succeeded).
    """
    if incidences is None:
        incidences = np.union1d(GRID, digitized_incidences())
    names = frictional_laws() if laws is None else list(laws)
    return pd.concat([law_curve(name, incidences) for name in names], ignore_index=True)


def range_of(incidence: np.ndarray) -> np.ndarray:
    """'sticking', 'sliding' or '' (between the two) for each incidence, read as nominal."""
    return np.where(
        incidence <= STICKING + READING,
        "sticking",
        np.where(incidence >= SLIDING - READING, "sliding", ""),
    )


def errors(table: pd.DataFrame) -> pd.DataFrame:
    """Each law's error at each digitized point it was solved at.

    Returns
    -------
    DataFrame
        One row per law, quantity and digitized point: ``law, quantity, range, incidence,
        measured, predicted, error`` (predicted minus measured, NaN where the solve failed).
    """
    rows = []
    points = measured()
    for law, solved in table.groupby("law", sort=False):
        for quantity in QUANTITIES:
            at, values = points[quantity]
            predicted = solved.set_index("incidence")[quantity]
            found = np.isin(at, predicted.index)
            prediction = predicted.reindex(at[found]).to_numpy()
            rows.append(
                pd.DataFrame(
                    {
                        "law": law,
                        "quantity": quantity,
                        "range": range_of(at[found]),
                        "incidence": at[found],
                        "measured": values[found],
                        "predicted": prediction,
                        "error": prediction - values[found],
                    }
                )
            )
    return pd.concat(rows, ignore_index=True)


def rms(table: pd.DataFrame) -> pd.DataFrame:
    """The RMS error of each law against each quantity's points, per range.

    Returns
    -------
    DataFrame
        ``law, quantity, range, rms, points, failed``: the root mean square of predicted minus
        measured over the points where the law answered (in the quantity's unit: none, rad/s,
        degrees), their number, and the number of points where the solve failed.
    """
    points = errors(table)
    points = points[points["range"] != ""]
    grouped = points.groupby(["law", "quantity", "range"], sort=False)["error"]
    return grouped.agg(
        rms=lambda e: (
            float(np.sqrt(np.mean(np.square(e.dropna())))) if e.notna().any() else math.nan
        ),
        points=lambda e: int(e.notna().sum()),
        failed=lambda e: int(e.isna().sum()),
    ).reset_index()


def reversal(table: pd.DataFrame) -> pd.DataFrame:
    """Whether each law's contact point reverses at some incidence of the sticking range.

    Returns
    -------
    DataFrame
        ``law, reverses, lowest_angle, at_incidence``: whether the contact angle falls below
        ``-REVERSED`` at an incidence of the sticking range (`range_of`), its lowest value
        there (degrees) and the incidence of that value; None and NaN where the law answered
        at no incidence of that range.
    """
    rows = []
    for law, solved in table.groupby("law", sort=False):
        answered = solved[solved["contact_angle"].notna()]
        sticking = answered[range_of(answered["incidence"].to_numpy()) == "sticking"]
        if sticking.empty:
            rows.append({"law": law, "reverses": None, "lowest_angle": math.nan})
            continue
        lowest = sticking.loc[sticking["contact_angle"].idxmin()]
        rows.append(
            {
                "law": law,
                "reverses": bool(lowest["contact_angle"] < -REVERSED),
                "lowest_angle": float(lowest["contact_angle"]),
                "at_incidence": float(lowest["incidence"]),
            }
        )
    return pd.DataFrame(rows, columns=["law", "reverses", "lowest_angle", "at_incidence"])


def summary(table: pd.DataFrame | None = None) -> str:
    """The RMS table and the reversal finding as text, for a report or a terminal.

    ``table`` is `curves`' output; every frictional law on the whole grid when None.
    """
    table = curves() if table is None else table
    setup = kharaz.SETUP
    failures = table[table["error"] != ""]
    lines = [
        f"Kharaz, Gorham and Salman 2001: alumina sphere of radius {setup.radius:g} m on glass "
        f"at {setup.speed:g} m/s, e = {NORMAL_RESTITUTION:g}, mu = {FRICTION:g}, "
        f"K = {hertz_stiffness():.3g} N/m^1.5",
        "",
        "RMS error against the digitized points (sticking: incidence <= "
        f"{STICKING:g} deg, sliding: >= {SLIDING:g} deg, nominal):",
        rms(table).to_string(index=False, float_format=lambda x: f"{x:.4g}"),
        "",
        f"Contact point reversed (contact angle below -{REVERSED:g} deg at an incidence "
        f"<= {STICKING:g} deg):",
        reversal(table).to_string(index=False, float_format=lambda x: f"{x:.3g}"),
    ]
    if not failures.empty:
        lines += [
            "",
            "Failed solves:",
            failures[["law", "incidence", "error"]].to_string(index=False),
        ]
    return "\n".join(lines)
