"""The comparison report: every law on every case it applies to, side by side.

`write_report` runs each applicable (law, case) pair at the case's default parameters and
writes ``report.md`` and ``index.html`` with one table: post-impact velocities, energy change
and the verdict of every check. A pair that fails keeps its row, with the error.
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pandas as pd

from lawbench.api import evaluate
from lawbench.case import CASES
from lawbench.checks import CHECKS, run_checks
from lawbench.errors import LawbenchError
from lawbench.law import LAWS

VERDICTS = {True: "pass", False: "FAIL", None: "-"}


def comparison_table() -> pd.DataFrame:
    """One row per applicable (case, law) pair at default parameters."""
    rows = []
    for case in CASES:
        for law in LAWS:
            if not case.requires.met_by(law.capabilities):
                continue
            row = {"case": case.name, "law": law.name}
            try:
                trial = evaluate(law, case)
            except LawbenchError as exc:
                rows.append({**row, "error": f"{type(exc).__name__}: {exc}"})
                continue
            outcome = trial.outcome
            row["v_plus"] = np.array2string(outcome.v_plus, precision=4, separator=", ")
            row["dT [J]"] = outcome.dT
            checks = run_checks(trial)
            row.update({name: VERDICTS[result.passed] for name, result in checks.items()})
            row["error"] = ""
            rows.append(row)
    columns = ["case", "law", "v_plus", "dT [J]", *CHECKS, "error"]
    return pd.DataFrame(rows, columns=columns)


def _markdown(table: pd.DataFrame) -> str:
    text = table.astype(object).where(table.notna(), "").astype(str)
    lines = ["| " + " | ".join(text.columns) + " |", "|" + "---|" * len(text.columns)]
    lines += ["| " + " | ".join(row) + " |" for row in text.itertuples(index=False)]
    return "\n".join(lines)


INTRO = (
    "Every registered law on every scene it applies to, at the scene's default parameters: "
    "post-impact velocities, kinetic energy change, and the verdict of each check "
    "(pass, FAIL, or - when the check does not apply). Rerun with `lawbench report`."
)


def write_report(out: Path) -> Path:
    """Write ``report.md``, ``index.html`` and ``comparison.csv`` into ``out``; return ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    table = comparison_table()
    table.to_csv(out / "comparison.csv", index=False)
    title = "lawbench: impact laws compared"
    (out / "report.md").write_text(
        f"# {title}\n\n## Outcomes and checks\n\n{INTRO}\n\n{_markdown(table)}\n"
    )
    (out / "index.html").write_text(
        "<!doctype html>\n<html lang='en'><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title></head><body>\n<h1>{html.escape(title)}</h1>\n"
        f"<h2>Outcomes and checks</h2>\n<p>{html.escape(INTRO)}</p>\n"
        f"{table.to_html(index=False, na_rep='', float_format='{:.6g}'.format)}\n</body></html>\n"
    )
    return out
