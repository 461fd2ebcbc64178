"""The report as a document: sections of text, tables and figures, written as HTML and Markdown.

Every table is written as CSV, every figure as PNG, SVG and the CSV of its data, all beside
``index.html`` and ``report.md`` so the folder opens from disk without a network. Text uses
two inline marks, the same in both pages: ```code``` and ``[text](target)`` links (``#anchor``
or a file of the folder). A table can name a column whose values become the anchors of its
rows (the findings list).
"""

from __future__ import annotations

import html
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
from matplotlib import rc_context
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure as MplFigure

LINK = re.compile(r"\[([^\]]+)\]\(([^)\s]+)\)")
CODE = re.compile(r"`([^`]+)`")
STYLE = """
body { font-family: sans-serif; max-width: 1200px; margin: 2em auto; padding: 0 1em; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.85em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.5em; vertical-align: top; }
th { background: #eee; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; }
figcaption, .caption { font-size: 0.9em; color: #333; }
tr:target { background: #ffd; }
code { background: #f4f4f4; }
"""


@dataclass
class Table:
    """A table: ``frame`` is shown, ``data`` (default ``frame``) is written as CSV."""

    name: str
    caption: str
    frame: pd.DataFrame
    data: pd.DataFrame | None = None
    anchors: str | None = None


@dataclass
class Figure:
    """A figure with its caption and the data it plots."""

    name: str
    caption: str
    figure: MplFigure
    data: pd.DataFrame


@dataclass
class Section:
    """A numbered section: paragraphs (str), tables and figures, in order."""

    anchor: str
    title: str
    blocks: list[str | Table | Figure] = field(default_factory=list)

    def tables(self) -> list[Table]:
        """The section's tables."""
        return [b for b in self.blocks if isinstance(b, Table)]

    def figures(self) -> list[Figure]:
        """The section's figures."""
        return [b for b in self.blocks if isinstance(b, Figure)]


def _inline_html(text: str) -> str:
    escaped = html.escape(text, quote=False)
    escaped = LINK.sub(r'<a href="\2">\1</a>', escaped)
    return CODE.sub(r"<code>\1</code>", escaped).replace("\n", "<br>")


def _cell_markdown(value: object) -> str:
    return str(value).replace("|", "\\|").replace("\n", "<br>")


def _text(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.astype(object).where(frame.notna(), "").astype(str)


def _table_html(table: Table) -> str:
    frame = _text(table.frame)
    head = "".join(f"<th>{html.escape(c)}</th>" for c in frame.columns)
    rows = []
    for _, row in frame.iterrows():
        anchor = f' id="{html.escape(row[table.anchors])}"' if table.anchors else ""
        cells = "".join(f"<td>{_inline_html(v)}</td>" for v in row)
        rows.append(f"<tr{anchor}>{cells}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


def _table_markdown(table: Table) -> str:
    frame = _text(table.frame)
    lines = ["| " + " | ".join(frame.columns) + " |", "|" + "---|" * len(frame.columns)]
    for _, row in frame.iterrows():
        cells = [_cell_markdown(v) for v in row]
        if table.anchors:
            cells[0] = f'<a id="{row[table.anchors]}"></a>{cells[0]}'
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def save_figure(figure: MplFigure, name: str, data: pd.DataFrame, out: Path) -> None:
    """Write ``NAME.png``, ``NAME.svg`` (reproducible: fixed ids, no date) and ``NAME.csv``."""
    FigureCanvasAgg(figure)
    # A tight bounding box keeps the legends placed outside the axes.
    figure.savefig(out / f"{name}.png", dpi=100, bbox_inches="tight")
    with rc_context({"svg.hashsalt": "lawbench"}):
        figure.savefig(out / f"{name}.svg", metadata={"Date": None}, bbox_inches="tight")
    data.to_csv(out / f"{name}.csv", index=False)


def save_serially(figures: list[Figure], out: Path) -> None:
    """Save ``figures`` one after the other in this process."""
    for block in figures:
        save_figure(block.figure, block.name, block.data, out)


def _caption(block: Table | Figure, rerun: str) -> str:
    if isinstance(block, Table):
        return f"{block.caption} Table: [{block.name}.csv]({block.name}.csv)."
    files = ", ".join(f"[{block.name}.{ext}]({block.name}.{ext})" for ext in ("svg", "csv"))
    return f"{block.caption} Files: {files}. Rerun: `{rerun}`."


def write_page(
    out: Path,
    title: str,
    preamble: list[str],
    sections: list[Section],
    rerun: str,
    save: Callable[[list[Figure], Path], None] = save_serially,
) -> None:
    """Write every file of the report into ``out``: figures, tables, HTML and Markdown.

    ``save`` writes the figures (for example in worker processes).
    """
    out.mkdir(parents=True, exist_ok=True)
    body = [f"<h1>{html.escape(title)}</h1>"]
    markdown = [f"# {title}"]
    for text in preamble:
        body.append(f"<p>{_inline_html(text)}</p>")
        markdown.append(text)
    contents = [f'<li><a href="#{s.anchor}">{html.escape(s.title)}</a></li>' for s in sections]
    body.append(f"<ol>{''.join(contents)}</ol>")
    markdown += [f"{n}. [{s.title}](#{s.anchor})" for n, s in enumerate(sections, 1)]
    for section in sections:
        body.append(f'<h2 id="{section.anchor}">{html.escape(section.title)}</h2>')
        markdown.append(f'<a id="{section.anchor}"></a>\n\n## {section.title}')
        for block in section.blocks:
            if isinstance(block, str):
                body.append(f"<p>{_inline_html(block)}</p>")
                markdown.append(block)
                continue
            caption = _caption(block, rerun)
            if isinstance(block, Table):
                data = block.frame if block.data is None else block.data
                data.to_csv(out / f"{block.name}.csv", index=False)
                body.append(_table_html(block))
                body.append(f'<p class="caption">{_inline_html(caption)}</p>')
                markdown += [_table_markdown(block), caption]
            else:
                image = f"{block.name}.png"
                body.append(
                    f'<figure id="{block.name}"><a href="{block.name}.svg">'
                    f'<img src="{image}" alt="{html.escape(block.name)}"></a>'
                    f"<figcaption>{_inline_html(caption)}</figcaption></figure>"
                )
                markdown += [f"![{block.name}]({image})", caption]
    (out / "index.html").write_text(
        "<!doctype html>\n<html lang='en'><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>\n"
        + "\n".join(body)
        + "\n</body></html>\n"
    )
    (out / "report.md").write_text("\n\n".join(markdown) + "\n")
    save([b for s in sections for b in s.blocks if isinstance(b, Figure)], out)


def number(value: float | None, scale: float = 0.0) -> str:
    """Four significant digits; rounding noise (below 1e-12 of ``scale``) shown as 0."""
    if value is None or value != value:
        return ""
    return f"{0.0 if abs(value) <= 1e-12 * scale else value:.4g}"
