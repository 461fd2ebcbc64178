"""Section 1, the summary matrix: laws x scenes, the verdict of every check at the defaults.

A view of the ``summary`` study: every law on every scene at its default parameters, with every
check (continuity and dispersion included; the quick report leaves continuity to the continuity
studies of the two chains). Each cell holds one mark, the worst verdict of its
checks, with the symbols of the checks that have it and every check's reason on hover, so the
matrix fits a page; a *law property* links to the finding that predicts it. A law that refuses
the scene gets one *refused* mark, like a check that does not apply.
"""

from __future__ import annotations

from typing import Any

import pandas as pd

from lawbench.core.verdicts import Verdict
from lawbench.studies.record import budget_text
from lawbench.studies.study import Study
from lawbench.views.report.marks import Mark
from lawbench.views.report.page import Legend, Section, Table
from lawbench.views.report.runs import Context

ANCHOR, TITLE, VIEWS = "summary", "Summary matrix", ("summary",)


def abbreviations(names: list[str]) -> dict[str, str]:
    """One short symbol per check name.

    The initials of its words (``energy_kept``: ``ek``), or, where two names share them, the
    shortest distinct prefix.
    """
    initials = {name: "".join(word[0] for word in name.split("_")) for name in names}
    short = {}
    for name in names:
        if list(initials.values()).count(initials[name]) == 1:
            short[name] = initials[name]
            continue
        length = 1
        while any(o != name and o.startswith(name[:length]) for o in names) and length < len(name):
            length += 1
        short[name] = name[:length]
    return short


def findings(ctx: Context) -> list[dict[str, Any]]:
    """Every finding of the selected laws, numbered, with its anchor."""
    rows = []
    for law in ctx.laws:
        for index, claim in enumerate(law.findings):
            number = len(rows) + 1
            rows.append(
                {
                    "finding": number,
                    "anchor": f"finding-{number}",
                    "law": law.name,
                    "index": index,
                    "check": claim.check,
                    "where": claim.region.text,
                    "source": claim.source,
                    "reason": claim.reason,
                }
            )
    return rows


def failure(row: dict[str, Any]) -> str:
    """``Class: message`` of a cell without an answer, with the budget that ran out."""
    budget = budget_text(row)
    return f"{row['error_class']}: {row['error_message']}" + (f" ({budget})" if budget else "")


# The verdict a cell shows: the worst of its checks, in this order.
WORST_FIRST = (
    Verdict.UNEXPLAINED,
    Verdict.NUMERICAL_FAILURE,
    Verdict.BUDGET,
    Verdict.LAW_PROPERTY,
    Verdict.HOLDS,
    Verdict.REFUSED,
)


def _mark(row: dict[str, Any], checks: list[str], short: dict, by_key: dict) -> Mark:
    """The cell's one mark: its worst verdict, the checks that have it, every reason on hover.

    A law property links to the finding that predicts it.
    """
    if row["error_class"]:
        return Mark("", Verdict(row["verdict"]), failure(row))
    verdicts = {check: Verdict(row[f"{check}_verdict"]) for check in checks}
    worst = next(v for v in WORST_FIRST if v in verdicts.values())
    named = [c for c in checks if verdicts[c] == worst]
    text = "" if worst in (Verdict.HOLDS, Verdict.REFUSED) else " ".join(short[c] for c in named)
    reason = "; ".join(f"{c}: {verdicts[c]}: {row[f'{c}_detail']}" for c in checks)
    found = by_key.get((row["law"], row[f"{named[0]}_finding"]))
    link = f"#{found['anchor']}" if worst == Verdict.LAW_PROPERTY and found else ""
    return Mark(text, worst, reason, link)


def _caption(study: Study, short: dict[str, str]) -> str:
    """The matrix's caption: how to read a mark, the checks' key, where continuity is probed."""
    key = ", ".join(f"{s} = {c}" for c, s in short.items())
    sizes = ", ".join(f"{s:g}" for s in study.settings.get("continuity_sizes", ()))
    continuity = (
        f"continuity perturbed at sizes {sizes}"
        if "continuity" in short
        else "continuity in the continuity studies (here in the full report)"
    )
    return (
        "Every law on every scene at the scene's default parameters, one mark per cell: the "
        "worst verdict of its checks (unexplained, numerical failure, budget, law property, "
        f"holds, refused, in that order), with the checks that have it; the key: {key}; "
        f"{continuity}. A mark's colour is its verdict (legend "
        "above); hover for every check's verdict and reason; a law property links to its "
        "finding. A law that gave no answer has its reason: refused (NotApplicable), a "
        "budget, or an error. The CSV holds every check's verdict and value."
    )


def build(ctx: Context) -> Section:
    """The section, from the ``summary`` study's table."""
    tables = ctx.tables("summary")
    if not tables:
        return Section(ANCHOR, TITLE, ["No summary study ran."])
    study, table = tables[0]
    checks = list(study.check_names())
    short = abbreviations(checks)
    listed = findings(ctx)
    by_key = {(f["law"], f["index"]): f for f in listed}
    rows = {(r["law"], r["case"]): r for r in table.fillna({"error_class": ""}).to_dict("records")}
    matrix: dict[str, dict[str, Any]] = {}
    tidy, observed = [], {}
    for law in ctx.laws:
        matrix[law.name] = {"law": law.name}
        for case in ctx.cases:
            row = rows.get((law.name, case.name))
            if row is None:
                continue
            matrix[law.name][case.name] = _mark(row, checks, short, by_key)
            entry = {"law": law.name, "case": case.name, "verdict": row["verdict"]}
            if row["error_class"]:
                tidy.append({**entry, "status": "error", "error": failure(row)})
                continue
            verdicts = {c: row[f"{c}_verdict"] for c in checks}
            values = {f"{c}_value": row[f"{c}_value"] for c in checks}
            tidy.append({**entry, "status": "ran", **verdicts, **values, "error": ""})
            for check in checks:
                found = by_key.get((law.name, row[f"{check}_finding"]))
                if verdicts[check] == Verdict.LAW_PROPERTY and found:
                    observed.setdefault(found["finding"], []).append(case.name)
    frame = pd.DataFrame(list(matrix.values()))
    columns = ["law", "case", "status", "verdict", *checks, *(f"{c}_value" for c in checks)]
    data = pd.DataFrame(tidy).reindex(columns=[*columns, "error"])
    ran = data[data["status"] == "ran"]
    counts = {v: int((ran[checks] == str(v)).sum().sum()) for v in Verdict}
    refused = int((data["verdict"] == str(Verdict.REFUSED)).sum())
    summary = (
        f"{len(data)} law-scene cells: {len(ran)} solved, {refused} refused by the law. "
        "Check verdicts of the solved cells: "
        + ", ".join(f"{n} {v}" for v, n in counts.items())
        + "."
    )
    columns = ["finding", "law", "check", "where", "in this run", "reason", "source"]
    list_rows = [
        {**f, "finding": f["anchor"], "in this run": _observed(f, observed)} for f in listed
    ]
    return Section(
        ANCHOR,
        TITLE,
        [
            summary,
            Legend(),
            Table("comparison", _caption(study, short), frame, data),
            "Findings: what each law's theory predicts to fail, with the region where it "
            "applies and its source (the test suite holds every finding at its witnesses).",
            Table(
                "findings",
                "The findings of every law, with the reason; 'in this run' says where the "
                "matrix met it.",
                pd.DataFrame(list_rows, columns=columns),
                anchors="finding",
            ),
        ],
    )


def _observed(finding: dict[str, Any], observed: dict[int, list[str]]) -> str:
    scenes = observed.get(finding["finding"])
    if not scenes:
        return "not met in the matrix (its witnesses are other examples)"
    return "met on " + ", ".join(scenes)
