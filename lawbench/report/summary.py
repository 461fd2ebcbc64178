"""Section 1, the summary matrix: laws x scenes, the verdict of every check at the defaults.

Every law runs on every scene it can treat, at the scene's first named example (its default
parameters), with every check of `lawbench.checks.CHECKS` (the continuity check at the sizes of
the configuration). A failure listed in the law's ``findings`` is an expected failure and links
to its explanation in the findings list; any other failure is marked unexpected.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pandas as pd

from lawbench.case import Case
from lawbench.checks import CHECKS, SINGLE_SOLVE
from lawbench.law import Law
from lawbench.report.page import Section, Table
from lawbench.report.runs import Batch, Context, Job, error_text
from lawbench.verdicts import Verdict

ANCHOR, TITLE = "summary", "Summary matrix"

SYMBOLS = {
    Verdict.HOLDS: "✓",
    Verdict.LAW_PROPERTY: "✗",
    Verdict.NUMERICAL_FAILURE: "✗!",
    Verdict.REFUSED: "·",
    Verdict.BUDGET: "⧗",
    Verdict.UNEXPLAINED: "?!",
}
LEGEND = (
    "✓ holds; ✗ (#n) law property, predicted by the law's finding n; ✗! numerical failure (the "
    "law's theory says it holds); · refused (the check does not apply, with its reason); "
    "⧗ budget; ?! unexplained"
)


def default_example(case: Case) -> tuple[str, dict[str, Any]]:
    """The name and parameters of a scene's first example, its defaults."""
    name = next(iter(case.examples))
    return name, dict(case.examples[name])


def unmet(case: Case, law: Law) -> str:
    """Why a scene is not for a law (its required tags against the law's)."""
    return "the scene needs " + " and ".join(law.tags.missing(case.requires))


def default_batch(ctx: Context) -> Batch:
    """Every law on every scene it can treat, at the defaults, with every check."""
    jobs = [
        Job(law.name, case.name, default_example(case)[1])
        for case in ctx.cases
        for law in ctx.laws
        if law.tags.covers(case.requires)
    ]
    settings = {"continuity_sizes": list(ctx.config.summary_continuity_sizes)}
    return ctx.batch("defaults", jobs, checks=ordered_checks(), settings=settings)


def ordered_checks() -> list[str]:
    """Every check: those reading one outcome first, then those that solve again."""
    return [*SINGLE_SOLVE, *(name for name in CHECKS if name not in SINGLE_SOLVE)]


def default_records(ctx: Context) -> dict[tuple[str, str], dict[str, Any]]:
    """The records of `default_batch`, by (law, case)."""
    return {(r["law"], r["case"]): r for r in default_batch(ctx).records()}


def abbreviations(names: list[str]) -> dict[str, str]:
    """The shortest distinct prefix of each check name."""
    short = {}
    for name in names:
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


def _verdict(record: dict[str, Any], check: str) -> Verdict:
    return Verdict(record.get(f"{check}_verdict", Verdict.REFUSED))


def _cell(verdicts: dict[str, Verdict], short: dict[str, str], numbers: dict[str, int]) -> str:
    parts = []
    for check, verdict in verdicts.items():
        if check in numbers:
            n = numbers[check]
            parts.append(f"{short[check]}✗ ([#{n}](#finding-{n}))")
        else:
            parts.append(short[check] + SYMBOLS[verdict])
    return " ".join(parts)


def start(ctx: Context) -> Callable[[], Section]:
    """Start the section's runs; the returned function builds it."""
    default_batch(ctx)
    return lambda: _build(ctx)


def _matrix(ctx: Context, listed: list[dict], checks: list[str]) -> tuple[dict, list, dict]:
    """Cell texts by law and case, the tidy rows, and the verdict met by each finding."""
    records = default_records(ctx)
    by_key = {(f["law"], f["index"]): f for f in listed}
    short = abbreviations(checks)
    matrix: dict[str, dict[str, str]] = {}
    tidy, observed = [], {}
    for law in ctx.laws:
        matrix[law.name] = {}
        for case in ctx.cases:
            example = default_example(case)[0]
            row = {"law": law.name, "case": case.name, "example": example}
            record = records.get((law.name, case.name))
            if record is None:
                matrix[law.name][case.name] = "—"
                tidy.append({**row, "status": "not run", "error": unmet(case, law)})
                continue
            if record.get("error_class"):
                text = error_text(record)
                matrix[law.name][case.name] = text if len(text) < 90 else text[:87] + "..."
                tidy.append({**row, "status": "error", "error": text})
                continue
            verdicts, numbers = {}, {}
            for check in checks:
                verdicts[check] = _verdict(record, check)
                finding = by_key.get((law.name, record.get(f"{check}_finding", -1)))
                if verdicts[check] == Verdict.LAW_PROPERTY and finding:
                    numbers[check] = finding["finding"]
                    observed.setdefault(finding["finding"], []).append(case.name)
            matrix[law.name][case.name] = _cell(verdicts, short, numbers)
            values = {f"{c}_value": record.get(f"{c}_value") for c in checks}
            tidy.append({**row, "status": "ran", **verdicts, **values, "error": ""})
    return matrix, tidy, observed


def _build(ctx: Context) -> Section:
    listed = findings(ctx)
    checks = ordered_checks()
    short = abbreviations(checks)
    matrix, tidy, observed = _matrix(ctx, listed, checks)
    frame = pd.DataFrame(matrix).T.rename_axis("law").reset_index()
    columns = ["law", "case", "example", "status", *checks, *(f"{c}_value" for c in checks)]
    data = pd.DataFrame(tidy).reindex(columns=[*columns, "error"])
    counts = {v: int((data[checks] == v).sum().sum()) for v in Verdict}
    legend = ", ".join(f"{s} = {c}" for c, s in short.items())
    sizes = ", ".join(f"{s:g}" for s in ctx.config.summary_continuity_sizes)
    caption = (
        f"Every law on every scene it can treat, at the scene's default parameters (its first "
        f"example), with every check ({legend}); continuity perturbed at sizes {sizes}. "
        f"{LEGEND}; — the scene's requirements exceed the law's tags; otherwise the "
        f"error the solve raised."
    )
    columns = ["finding", "law", "check", "where", "in this run", "reason", "source"]
    list_rows = [
        {**f, "finding": f["anchor"], "in this run": _observed(f, observed)} for f in listed
    ]
    findings_frame = pd.DataFrame(list_rows, columns=columns)
    return Section(
        ANCHOR,
        TITLE,
        [
            f"{counts[Verdict.UNEXPLAINED]} unexplained cells (?!). "
            f"{len(data) - int((data['status'] == 'not run').sum())} law-scene pairs ran: "
            + ", ".join(f"{n} {v}" for v, n in counts.items())
            + f"; {int((data['status'] == 'error').sum())} pairs raised an error.",
            Table("comparison", caption, frame, data),
            "Findings: what each law's theory predicts to fail, with the region where it "
            "applies and its source (the test suite holds every finding at its witnesses).",
            Table(
                "findings",
                "The findings of every law, with the reason; 'in this run' says what the "
                "matrix observed.",
                findings_frame,
                anchors="finding",
            ),
        ],
    )


def _observed(finding: dict[str, Any], observed: dict[int, list[str]]) -> str:
    scenes = observed.get(finding["finding"])
    if not scenes:
        return "not met in the matrix (its witnesses are other examples)"
    return "met on " + ", ".join(scenes)
