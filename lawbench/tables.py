"""Studies tabulated over one parameter: every law that can treat them, side by side.

A table is a tidy frame (one row per law and parameter value) and notes: the laws left out and
why (not registered, or refusing the scene), and the rows a law failed, with the error class and
message. A law's failure on one row never stops the table.

- ``rocking_block``: the ratio of angular velocities ``omega+ / omega-`` of the rocking block
  against Housner's ``1 - 3/2 sin^2(alpha)``, over aspect ratios width / height from 0.1 to 10
  (9 log-spaced values), with ``e = 0`` (Housner's plastic impact), height 1 m, and two
  frictions: ``mu = 0`` and ``mu = 1`` (the landing corner sticks in Housner's impact for
  every aspect ratio: it needs ``mu >= 3 w h / (w^2 + 4 h^2) <= 3/4``). Every registered law
  is tried.
- ``sphere_wall``: the tangential behaviour of ``brach``, ``whittaker`` and ``darboux_keller``
  for a sphere without pre-impact spin striking the wall at incidences 5 to 85 degrees (the
  case's other defaults): the post-impact slip of the contact point along the pre-impact slip
  direction ``s`` (negative: reversed), the spin about ``n x s`` (positive: rolling along ``s``;
  rolling without slip is ``radius spin = vt``), and the impulse ratio ``-Pt.s / Pn``.
- ``dispersion``: the share of the post-impact kinetic energy carried by each of three equal
  balls struck by the first, and the dispersion index, for every law, as the stiffness ratio of
  the two contacts goes from 1e-3 to 1e3 (rigid laws do not read it: their rows repeat).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from lawbench.api import evaluate
from lawbench.case import CASES
from lawbench.checks import Trial
from lawbench.errors import InvalidProblem, NotApplicable
from lawbench.law import LAWS

ASPECT_RATIOS = np.logspace(-1.0, 1.0, 9)
ROCKING_FRICTIONS = (0.0, 1.0)
INCIDENCES = np.linspace(5.0, 85.0, 9)
SPHERE_LAWS = ("brach", "whittaker", "darboux_keller")
DISPERSION_RATIOS = np.logspace(-3.0, 3.0, 7)

# A row of a study: its label columns and the case parameters it sets.
Row = tuple[dict[str, Any], dict[str, Any]]


@dataclass
class Table:
    """A tabulated study: the frame and the notes (laws left out, rows that failed)."""

    name: str
    title: str
    frame: pd.DataFrame
    notes: list[str] = field(default_factory=list)

    def text(self) -> str:
        """The table as aligned text, its title first and its notes last."""
        body = self.frame.to_string(index=False, float_format=lambda x: f"{x:.6g}")
        notes = [f"note: {note}" for note in self.notes]
        return "\n".join([self.title, "", body if len(self.frame) else "(no rows)", *notes])

    def write_csv(self, path: Path) -> Path:
        """Write the frame to ``path`` as CSV (parent folders created); return the path."""
        path.parent.mkdir(parents=True, exist_ok=True)
        self.frame.to_csv(path, index=False)
        return path


def _study(
    case_name: str,
    laws: Iterable[str],
    rows: list[Row],
    measure: Callable[[Trial], dict[str, float]],
) -> tuple[list[dict[str, Any]], list[str]]:
    """Solve every row with every law; return the table rows and the notes."""
    case, records, notes = CASES.get(case_name), [], []
    for name in laws:
        if name not in LAWS:
            notes.append(f"{name}: left out, not registered")
            continue
        refusals: dict[str, list[str]] = {}
        failures: list[str] = []
        for labels, params in rows:
            try:
                values = measure(evaluate(name, case, **params))
            except NotApplicable as exc:
                refusals.setdefault(str(exc), []).append(_labels(labels))
                continue
            except Exception as exc:  # a row records its error, the table goes on
                failures.append(f"{_labels(labels)}: {type(exc).__name__}: {exc}")
                continue
            if not np.isfinite(list(values.values())).all():
                failures.append(f"{_labels(labels)}: non-finite value {values}")
                continue
            records.append({"law": name, **labels, **values})
        if not any(record["law"] == name for record in records):
            reason = next(iter(refusals), None) or failures[0]
            notes.append(f"{name}: left out, no row solved ({reason})")
            continue
        notes += [
            f"{name}: refused on {len(where)} of {len(rows)} rows (from {where[0]}): {reason}"
            for reason, where in refusals.items()
        ]
        notes += [f"{name}: failed at {failure}" for failure in failures]
    return records, notes


def _labels(labels: dict[str, Any]) -> str:
    return ", ".join(f"{key} = {value:.4g}" for key, value in labels.items())


def rocking_block_table() -> Table:
    """Every registered law's ``omega+ / omega-`` on the rocking block against Housner's."""
    from lawbench.cases.rocking_block import housner_ratio

    rows = [
        (
            {"mu": mu, "width_over_height": float(aspect)},
            {"width": float(aspect), "height": 1.0, "e": 0.0, "mu": mu},
        )
        for mu in ROCKING_FRICTIONS
        for aspect in ASPECT_RATIOS
    ]

    def measure(trial: Trial) -> dict[str, float]:
        ratio = trial.outcome.v_plus[2] / trial.problem.v[2]
        housner = housner_ratio(trial.params["width"], trial.params["height"])
        return {"omega_ratio": ratio, "housner": housner, "difference": ratio - housner}

    records, notes = _study("rocking_block", LAWS.names(), rows, measure)
    columns = ["law", "mu", "width_over_height", "omega_ratio", "housner", "difference"]
    title = (
        "rocking block: omega+/omega- against Housner's 1 - 3/2 sin^2(alpha), e = 0, "
        "height 1 m, width = height x width_over_height; Housner's formula holds for "
        "width_over_height <= sqrt(2) (wider, the pivot cannot lift off)"
    )
    return Table("rocking_block", title, pd.DataFrame(records, columns=columns), notes)


def sphere_wall_table() -> Table:
    """Tangential behaviour of the one-contact frictional laws on the sphere over incidence."""
    from lawbench.cases.sphere_wall import NORMAL, TANGENTS

    rows = [
        ({"angle_deg": float(angle)}, {"angle": float(angle), "spin": [0.0, 0.0, 0.0]})
        for angle in INCIDENCES
    ]

    def measure(trial: Trial) -> dict[str, float]:
        problem, outcome = trial.problem, trial.outcome
        slip = problem.ut / np.linalg.norm(problem.ut)
        axis = np.cross(NORMAL, slip[0] * TANGENTS[0] + slip[1] * TANGENTS[1])
        return {
            "ut_minus": float(np.linalg.norm(problem.ut)),
            "ut_plus": float(problem.Wt.T @ outcome.v_plus @ slip),
            "spin_plus": float(outcome.v_plus[3:] @ axis),
            "impulse_ratio": float(-outcome.Pt @ slip / outcome.Pn[0]),
        }

    records, notes = _study("sphere_wall", SPHERE_LAWS, rows, measure)
    columns = ["law", "angle_deg", "ut_minus", "ut_plus", "spin_plus", "impulse_ratio"]
    case = CASES.get("sphere_wall").parameters()
    title = (
        "sphere on a wall, no pre-impact spin: post-impact slip ut_plus along the pre-impact "
        "slip, spin about n x s, impulse ratio -Pt.s/Pn; "
        f"e = {case['e']:g}, e_t = {case['e_t']:g}, mu = {case['mu']:g}, "
        f"speed = {case['speed']:g} m/s, radius = {case['radius']:g} m"
    )
    return Table("sphere_wall", title, pd.DataFrame(records, columns=columns), notes)


def dispersion_table() -> Table:
    """Energy shares per ball on three equal balls struck by the first, as stiffness varies."""
    from lawbench.checks.dispersion import dispersion_index
    from lawbench.mechanics import energy_shares

    rows = [
        ({"stiffness_ratio": float(ratio)}, {"stiffness_ratio": float(ratio)})
        for ratio in DISPERSION_RATIOS
    ]

    def measure(trial: Trial) -> dict[str, float]:
        shares = energy_shares(trial.problem, trial.outcome.v_plus)
        return {
            **{f"share_{b}".replace(" ", "_"): s for b, s in shares.items()},
            "dispersion_index": dispersion_index(shares),
        }

    records, notes = _study("three_ball_chain", LAWS.names(), rows, measure)
    columns = [
        "law",
        "stiffness_ratio",
        "share_ball_1",
        "share_ball_2",
        "share_ball_3",
        "dispersion_index",
    ]
    title = (
        "three equal balls, velocities (1, 0, 0), e = 1, Hertz contacts: share of the "
        "post-impact kinetic energy per ball and the dispersion index (0: all in one ball) as "
        "the stiffness of contact 1 over contact 0 goes from 1e-3 to 1e3"
    )
    return Table("dispersion", title, pd.DataFrame(records, columns=columns), notes)


TABLES: dict[str, Callable[[], Table]] = {
    "rocking_block": rocking_block_table,
    "sphere_wall": sphere_wall_table,
    "dispersion": dispersion_table,
}


def build_table(name: str) -> Table:
    """Build the table called ``name``.

    Raises
    ------
    InvalidProblem
        For an unknown name; the message lists the known ones.
    """
    if name not in TABLES:
        raise InvalidProblem(f"unknown table {name!r}; known: {', '.join(TABLES)}")
    return TABLES[name]()
