"""The comparison report: every law on every case it applies to, side by side.

`write_report` runs each applicable (law, case) pair on each of the case's named examples (the
first is the defaults) and writes ``report.md`` and ``index.html``: one table of post-impact
velocities, energy change and the verdict of every check, and the list of findings (the known
defects of the laws, marked in the table). A pair that fails keeps its row, with the error.
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pandas as pd

from lawbench.api import evaluate
from lawbench.case import CASES, Case
from lawbench.checks import CHECKS, run_checks
from lawbench.errors import LawbenchError
from lawbench.law import LAWS, Law

VERDICTS = {True: "pass", False: "FAIL", None: "-"}
FINDING = "FAIL (finding)"


def _number(value: float, scale: float) -> str:
    """Four significant digits; rounding noise (below 1e-12 of ``scale``) shown as 0."""
    return f"{0.0 if abs(value) <= 1e-12 * scale else value:.4g}"


def _row(law: Law, case: Case, example: str) -> dict[str, object]:
    row: dict[str, object] = {"case": case.name, "example": example, "law": law.name}
    try:
        trial = evaluate(law, case, **case.examples[example])
    except LawbenchError as exc:
        return {**row, "error": f"{type(exc).__name__}: {exc}"}
    outcome = trial.outcome
    scale = float(np.abs(trial.problem.v).max())
    row["v_plus"] = "[" + ", ".join(_number(x, scale) for x in outcome.v_plus) + "]"
    row["dT [J]"] = _number(outcome.dT, outcome.T_minus)
    for name, result in run_checks(trial).items():
        finding = result.passed is False and (case.name, example, name) in law.findings
        row[name] = FINDING if finding else VERDICTS[result.passed]
    return {**row, "error": ""}


def comparison_table() -> pd.DataFrame:
    """One row per applicable (case, example, law)."""
    rows = [
        _row(law, case, example)
        for case in CASES
        for example in case.examples
        for law in LAWS
        if case.requires.met_by(law.capabilities)
    ]
    columns = ["case", "example", "law", "v_plus", "dT [J]", *CHECKS, "error"]
    return pd.DataFrame(rows, columns=columns)


def findings_table() -> pd.DataFrame:
    """The known defects of every law: where a check fails because of the law, and why."""
    rows = [
        {"law": law.name, "case": case, "example": example, "check": check, "reason": reason}
        for law in LAWS
        for (case, example, check), reason in sorted(law.findings.items())
    ]
    return pd.DataFrame(rows, columns=["law", "case", "example", "check", "reason"])


def _markdown(table: pd.DataFrame) -> str:
    text = table.astype(object).where(table.notna(), "").astype(str)
    lines = ["| " + " | ".join(text.columns) + " |", "|" + "---|" * len(text.columns)]
    lines += ["| " + " | ".join(row) + " |" for row in text.itertuples(index=False)]
    return "\n".join(lines)


INTRO = (
    "Every registered law on every scene it applies to, on each of the scene's named examples "
    "(`lawbench describe CASE` lists their parameters): post-impact velocities, kinetic energy "
    "change, and the verdict of each check (pass, FAIL, or - when the check does not apply). "
    "A failure that is a known defect of the law is marked 'FAIL (finding)' and explained "
    "below. Rerun with `lawbench report`."
)
FINDINGS = (
    "Known defects: each is a property of the law, not of its implementation, and runs in the "
    "test suite as an expected failure."
)


def write_report(out: Path) -> Path:
    """Write ``report.md``, ``index.html`` and the tables as CSV into ``out``; return ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    sections = [
        ("Outcomes and checks", INTRO, comparison_table(), "comparison.csv"),
        ("Findings", FINDINGS, findings_table(), "findings.csv"),
    ]
    title = "lawbench: impact laws compared"
    markdown, page = [f"# {title}"], [f"<h1>{html.escape(title)}</h1>"]
    for heading, text, table, csv_name in sections:
        table.to_csv(out / csv_name, index=False)
        markdown += [f"## {heading}", text, _markdown(table), f"Table: `{csv_name}`."]
        page += [
            f"<h2>{html.escape(heading)}</h2>",
            f"<p>{html.escape(text)}</p>",
            table.to_html(index=False, na_rep=""),
            f"<p>Table: <a href='{csv_name}'>{csv_name}</a>.</p>",
        ]
    (out / "report.md").write_text("\n\n".join(markdown) + "\n")
    (out / "index.html").write_text(
        "<!doctype html>\n<html lang='en'><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title></head><body>\n"
        + "\n".join(page)
        + "\n</body></html>\n"
    )
    return out
