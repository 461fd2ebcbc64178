"""How verdicts look, the same in every section: one colour and one glyph per class.

A `Mark` is one verdict shown in a table cell: a short text (a check's symbol), its class (the
colour), the reason (a tooltip) and, for a *law property*, a link to the finding that predicts
it. Every *refused* mark looks the same, whether the law refused the scene or the check does
not apply.
"""

from __future__ import annotations

from dataclasses import dataclass

from lawbench.core.verdicts import Verdict

COLOURS = {
    Verdict.HOLDS: "#a5d6a7",
    Verdict.LAW_PROPERTY: "#90caf9",
    Verdict.NUMERICAL_FAILURE: "#ffb74d",
    Verdict.REFUSED: "#e0e0e0",
    Verdict.BUDGET: "#ce93d8",
    Verdict.UNEXPLAINED: "#e57373",
}
GLYPHS = {
    Verdict.HOLDS: "✓",
    Verdict.LAW_PROPERTY: "✗",
    Verdict.NUMERICAL_FAILURE: "!",
    Verdict.REFUSED: "·",
    Verdict.BUDGET: "»",
    Verdict.UNEXPLAINED: "?",
}
MEANINGS = {
    Verdict.HOLDS: "the check passes",
    Verdict.LAW_PROPERTY: "fails where a finding of the law predicts it (linked)",
    Verdict.NUMERICAL_FAILURE: "fails where the law's theory says it holds",
    Verdict.REFUSED: "the law or the check does not apply (the reason in the tooltip)",
    Verdict.BUDGET: "a named budget ran out (steps, events, iterations, seconds)",
    Verdict.UNEXPLAINED: "anything else: a bug to fix or a finding to write",
}


@dataclass(frozen=True)
class Mark:
    """One verdict in a table cell."""

    text: str
    verdict: Verdict
    reason: str = ""
    link: str = ""

    def markdown(self) -> str:
        """The mark as text: its symbol, glyph, and the link of a finding."""
        text = f"{self.text}{GLYPHS[self.verdict]}" if self.text else GLYPHS[self.verdict]
        return f"[{text}]({self.link})" if self.link else text


def legend() -> list[Mark]:
    """One mark per class, its name as text and its meaning as reason."""
    return [Mark(str(v), v, MEANINGS[v]) for v in Verdict]
