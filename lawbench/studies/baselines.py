"""Regression baselines: committed outcomes of every law, compared after each change.

``reports/baselines/baseline.toml`` holds a run specification (the grid: every law on every
scene it applies to, on each scene's named examples and at extremes) and a ``[tolerances]``
table: per law, per quantity, the largest accepted difference, relative to
``max(1, |baseline|)``; tight for closed-form laws, looser for integrated ones. The committed
results are one CSV per law, ``reports/baselines/<law>.csv``. `regress` recomputes the grid
and reports every quantity that moved past its tolerance; it writes what it obtained beside
the baseline (``<law>.obtained.csv``) for inspection. ``update`` rewrites the baselines.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.studies.grid import RunSpec
from lawbench.studies.runner import Executor, Task

# The repository's committed baselines (lawbench/studies/ is two folders below its top).
BASELINES = Path(__file__).resolve().parents[2] / "reports" / "baselines"
QUANTITIES = ("v_plus", "Pn", "Pt", "T_plus")
IDENTITY = ["law", "case", "params", "options"]
DEFAULT_TOLERANCE = 1e-9


def load(folder: Path = BASELINES) -> tuple[RunSpec, dict[str, dict[str, float]]]:
    """The baseline grid and its tolerances."""
    path = folder / "baseline.toml"
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise InvalidProblem(f"baseline spec {path}: {exc}") from None
    tolerances = data.pop("tolerances", {})
    return RunSpec.from_dict(data), tolerances


COLUMNS = [*IDENTITY, "error_class", *QUANTITIES]


def compute_table(
    spec: RunSpec, laws: Sequence[str] | None, cases: Sequence[str] | None, workers: int = 1
) -> pd.DataFrame:
    """Records of the baseline grid (restricted to ``laws`` and ``cases`` when given), as text.

    Vectors are JSON and numbers their shortest exact repr, so the CSV keeps every digit. With
    ``workers`` above one the rows are computed by that many worker processes; the table is the
    same.
    """
    jobs = [
        job
        for job in spec.rows()
        if (not laws or job.law in laws) and (not cases or job.case in cases)
    ]
    tasks = [Task(index, job) for index, job in enumerate(jobs)]
    with Executor("processes" if workers > 1 else "serial", workers) as executor:
        rows = dict(executor.run(tasks))
    records = [rows[position] for position in range(len(tasks))]
    table = pd.DataFrame(records).reindex(columns=COLUMNS)
    table["T_plus"] = table["T_plus"].map(lambda x: "" if pd.isna(x) else repr(float(x)))
    return table.fillna("").astype(str)


def _vector(text: str) -> np.ndarray | None:
    return np.atleast_1d(np.array(json.loads(text), dtype=float)) if text else None


def _difference(base: np.ndarray | None, new: np.ndarray | None) -> float:
    if base is None or new is None or base.shape != new.shape:
        return 0.0 if base is None and new is None else np.inf
    if base.size == 0:
        return 0.0
    return float(np.abs(new - base).max() / max(1.0, np.abs(base).max()))


# What a row computed now but absent from the baselines says in the drift table.
NEW_ROW = "new row"


def compare(
    obtained: pd.DataFrame, expected: pd.DataFrame, tolerances: dict[str, dict[str, float]]
) -> pd.DataFrame:
    """Every drift: a quantity past its tolerance, a changed error class, a row lost or new."""
    merged = expected.merge(
        obtained, on=IDENTITY, how="outer", suffixes=("_base", "_new"), indicator=True
    ).fillna("")
    drift = []
    for record in merged.to_dict("records"):
        where = {k: record[k] for k in IDENTITY}
        if record["_merge"] != "both":
            side = "only in the baseline" if record["_merge"] == "left_only" else NEW_ROW
            drift.append({**where, "quantity": "row", "baseline": side, "obtained": ""})
            continue
        quantities = ["error_class", *QUANTITIES]
        for quantity in quantities:
            base, new = record[f"{quantity}_base"], record[f"{quantity}_new"]
            if quantity == "error_class":
                difference, tolerance = (0.0 if base == new else np.inf), 0.0
            else:
                tolerance = float(
                    tolerances.get(record["law"], {}).get(quantity, DEFAULT_TOLERANCE)
                )
                difference = _difference(_vector(base), _vector(new))
            if difference > tolerance:
                drift.append(
                    {
                        **where,
                        "quantity": quantity,
                        "baseline": base,
                        "obtained": new,
                        "difference": difference,
                        "tolerance": tolerance,
                    }
                )
    columns = [*IDENTITY, "quantity", "baseline", "obtained", "difference", "tolerance"]
    return pd.DataFrame(drift, columns=columns)


def regress(
    laws: Sequence[str] | None = None,
    cases: Sequence[str] | None = None,
    update: bool = False,
    folder: Path = BASELINES,
    workers: int = 1,
) -> pd.DataFrame:
    """Recompute the baseline grid; return the drift (empty when every law holds).

    With ``update`` the baselines are rewritten and the returned table lists what changed;
    ``workers`` worker processes compute the grid.
    """
    for name in laws or ():
        LAWS.get(name)  # an unknown name is an error, never an empty selection that holds
    for name in cases or ():
        CASES.get(name)
    spec, tolerances = load(folder)
    obtained = compute_table(spec, laws, cases, workers)
    drift = []
    for law, table in obtained.groupby("law", sort=True):
        path = folder / f"{law}.csv"
        expected = (
            pd.read_csv(path, dtype=str, keep_default_na=False)
            if path.exists()
            else pd.DataFrame(columns=COLUMNS)
        )
        in_scope = expected["case"].isin(cases) if cases else np.ones(len(expected), bool)
        drift.append(compare(table, expected[in_scope], tolerances))
        if update:
            merged = pd.concat([expected[~in_scope], table])
            merged.sort_values(["case", "params", "options"]).to_csv(path, index=False)
        elif len(drift[-1]):
            table.to_csv(folder / f"{law}.obtained.csv", index=False)
    return pd.concat(drift, ignore_index=True) if drift else pd.DataFrame()
