"""The report as a document: sections of text, tables and figures, written as HTML and Markdown.

Every table is written as CSV, every figure as PNG, SVG and the CSV of its data, all beside
``index.html`` and ``report.md`` so the folder opens from disk without a network. The HTML page
is a Jinja template (it escapes every value). Text uses two inline marks, the same in both
pages: ```code``` and ``[text](target)`` links (``#anchor`` or a file of the folder). A table
cell may hold verdict marks (`lawbench.views.report.marks.Mark`), drawn in their class's colour; a
table can name a column whose values become the anchors of its rows (the findings list) and
columns of commands (reproducers), shown as code.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import jinja2
import pandas as pd
from markupsafe import Markup, escape
from matplotlib import rc_context
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure as MplFigure

from lawbench.files.paths import replaced
from lawbench.views.report.marks import COLOURS, GLYPHS, Mark, legend
from lawbench.views.report.plots import lay_out_once

LINK = re.compile(r"\[([^\]]+)\]\(([^)\s]+)\)")
CODE = re.compile(r"`([^`]+)`")
STYLE = """
body { font-family: sans-serif; max-width: 1200px; margin: 2em auto; padding: 0 1em; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.85em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.5em; vertical-align: top; }
th { background: #eee; overflow-wrap: normal; word-break: normal; hyphens: none; }
.scroll { max-width: 100%; overflow-x: auto; }
figure { margin: 1.5em 0; }
details { margin: 0.5em 0; }
summary { cursor: pointer; color: #225; }
nav ol ol { columns: 3; font-size: 0.9em; }
figure img { max-width: 100%; }
figcaption, .caption { font-size: 0.9em; color: #333; }
tr:target { background: #ffd; }
code { background: #f4f4f4; }
.mark { display: inline-block; padding: 0 0.3em; margin: 0.05em; border-radius: 0.2em;
        color: #000; text-decoration: none; white-space: nowrap; }
.legend .mark { margin-right: 0.6em; }
"""
TEMPLATE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{{ title }}</title>
<style>{{ style }}{% for verdict, colour in colours.items() %}
.{{ verdict | css }} { background: {{ colour }}; }{% endfor %}</style></head>
<body>
<h1>{{ title }}</h1>
{% for block in preamble %}{{ render(block) }}
{% endfor %}<nav id="contents"><ol>{% for s, children in contents %}
<li><a href="#{{ s.anchor }}">{{ s.title }}</a>{% if children %}<ol>{% for c in children %}
<li><a href="#{{ c.anchor }}">{{ c.title }}</a></li>{% endfor %}</ol>{% endif %}</li>{% endfor %}
</ol></nav>
{% for s in sections %}<h{{ s.level }} id="{{ s.anchor }}">{{ s.title }}</h{{ s.level }}>
{% for block in s.blocks %}{{ render(block) }}
{% endfor %}{% endfor %}</body></html>
"""
PARTS = {
    "text": "<p>{{ block | inline }}</p>",
    "legend": '<p class="legend">{% for m in block.marks %}{{ mark(m) }}'
    "<span> {{ m.reason }}</span><br>{% endfor %}</p>",
    "details": "<details><summary>{{ block.summary | inline }}</summary>"
    "{% for b in block.blocks %}{{ render(b) }}{% endfor %}</details>",
    "table": '<div class="scroll"><table id="{{ block.name }}"'
    '{% if block.css %} class="{{ block.css }}"{% endif %}><thead><tr>'
    "{% for c in block.frame.columns %}<th>{{ c | unbroken }}</th>{% endfor %}</tr></thead><tbody>"
    '{% for row in rows %}<tr{% if row.anchor %} id="{{ row.anchor }}"{% endif %}>'
    "{% for c in row.cells %}<td>{{ c }}</td>{% endfor %}</tr>{% endfor %}</tbody></table></div>"
    '<p class="caption">{{ caption | inline }}</p>',
    "figure": '<figure id="{{ block.name }}"><a href="{{ block.name }}.svg">'
    '<img src="{{ block.name }}.svg" alt="{{ block.name }}"></a>'
    "<figcaption>{{ caption | inline }}</figcaption></figure>",
    "mark": '{% if m.link %}<a class="mark {{ m.verdict | css }}" href="{{ m.link }}" '
    'title="{{ m.reason }}">{% else %}<span class="mark {{ m.verdict | css }}" '
    'title="{{ m.reason }}">{% endif %}{{ m.text }}{{ glyph }}'
    "{% if m.link %}</a>{% else %}</span>{% endif %}",
}


@dataclass
class Table:
    """A table: ``frame`` is shown, ``data`` (default ``frame``) is written as CSV.

    ``anchors`` names a column whose values become the rows' anchors; ``commands`` the columns
    of commands (shown as code, with the class ``reproducer``); ``hidden`` the columns written
    to the CSV but not shown.
    """

    name: str
    caption: str
    frame: pd.DataFrame
    data: pd.DataFrame | None = None
    anchors: str | None = None
    commands: tuple[str, ...] = ()
    css: str = ""
    hidden: tuple[str, ...] = ()

    def shown(self) -> pd.DataFrame:
        """The columns the page shows."""
        return self.frame.drop(columns=list(self.hidden))


@dataclass
class Figure:
    """A figure with its caption and the data it plots."""

    name: str
    caption: str
    figure: MplFigure
    data: pd.DataFrame


@dataclass(frozen=True)
class Legend:
    """The colours of the verdict classes, with their meanings."""

    marks: tuple[Mark, ...] = field(default_factory=lambda: tuple(legend()))


@dataclass
class Details:
    """Blocks folded under a one-line summary, open on a click."""

    summary: str
    blocks: list[Block] = field(default_factory=list)


Block = str | Table | Figure | Legend | Details


def flat(blocks: Sequence[Block]) -> list[Block]:
    """The blocks with every `Details` replaced by its blocks, recursively."""
    found: list[Block] = []
    for block in blocks:
        found += flat(block.blocks) if isinstance(block, Details) else [block]
    return found


@dataclass
class Section:
    """A section: paragraphs (str), tables, figures, legends and folds, in order.

    ``level`` is its heading's (2: a part of the page, 3: a section in it, 4: a topic of it).
    """

    anchor: str
    title: str
    blocks: list[Block] = field(default_factory=list)
    level: int = 2

    def figures(self) -> list[Figure]:
        """The section's figures, folded ones included."""
        return [b for b in flat(self.blocks) if isinstance(b, Figure)]


def contents(sections: Sequence[Section]) -> list[tuple[Section, list[Section]]]:
    """The parts of the page (level 2), each with its sections (level 3)."""
    parts: list[tuple[Section, list[Section]]] = []
    for section in sections:
        if section.level == 2 or not parts:
            parts.append((section, []))
        elif section.level == 3:
            parts[-1][1].append(section)
    return parts


def _inline(text: Any) -> Markup:
    escaped = str(escape(str(text)))
    escaped = LINK.sub(r'<a href="\2">\1</a>', escaped)
    return Markup(CODE.sub(r"<code>\1</code>", escaped).replace("\n", "<br>"))


def _css(verdict: Any) -> str:
    return "v-" + str(verdict).replace(" ", "-")


# The minus sign of a number's exponent (1e-06): a browser may break a line after a hyphen.
_EXPONENT_SIGN = re.compile(r"(?<=\de)-(?=\d)")


def _unbroken(text: Any) -> str:
    """A header's text with its numbers' exponent signs as non-breaking hyphens."""
    return _EXPONENT_SIGN.sub("\u2011", str(text))


def _blank(value: Any) -> bool:
    return value is None or (isinstance(value, float) and value != value)


class _Html:
    """Renders blocks with the page's Jinja environment."""

    def __init__(self, rerun: str) -> None:
        self.rerun = rerun
        env = jinja2.Environment(autoescape=True, undefined=jinja2.StrictUndefined)
        env.filters.update(inline=_inline, css=_css, unbroken=_unbroken)
        self.env = env
        self.parts = {name: env.from_string(text) for name, text in PARTS.items()}

    def mark(self, m: Mark) -> Markup:
        return Markup(self.parts["mark"].render(m=m, glyph=GLYPHS[m.verdict]))

    def cell(self, value: Any, command: bool) -> Markup:
        if isinstance(value, Mark):
            value = [value]
        if isinstance(value, list | tuple) and value and all(isinstance(v, Mark) for v in value):
            return Markup(" ").join(self.mark(m) for m in value)
        if _blank(value):
            return Markup("")
        if command:
            return Markup('<code class="reproducer">{}</code>').format(value)
        return _inline(value)

    def render(self, block: Block) -> Markup:
        if isinstance(block, str):
            return Markup(self.parts["text"].render(block=block))
        if isinstance(block, Legend):
            return Markup(self.parts["legend"].render(block=block, mark=self.mark))
        if isinstance(block, Details):
            return Markup(self.parts["details"].render(block=block, render=self.render))
        caption = _caption(block, self.rerun)
        if isinstance(block, Figure):
            return Markup(self.parts["figure"].render(block=block, caption=caption))
        rows = []
        for (_, row), (_, whole) in zip(
            block.shown().iterrows(), block.frame.iterrows(), strict=True
        ):
            cells = [self.cell(v, c in block.commands) for c, v in row.items()]
            anchor = str(whole[block.anchors]) if block.anchors else ""
            rows.append({"anchor": anchor, "cells": cells})
        return Markup(self.parts["table"].render(block=block, rows=rows, caption=caption))

    def page(self, title: str, preamble: Sequence[Block], sections: list[Section]) -> str:
        template = self.env.from_string(TEMPLATE)
        colours = {str(v): c for v, c in COLOURS.items()}
        return template.render(
            title=title,
            style=Markup(STYLE),
            colours=colours,
            preamble=preamble,
            contents=contents(sections),
            sections=sections,
            render=self.render,
        )


def _markdown_cell(value: Any, command: bool) -> str:
    if isinstance(value, Mark):
        value = [value]
    if isinstance(value, list | tuple) and value and all(isinstance(v, Mark) for v in value):
        return " ".join(m.markdown() for m in value)
    if _blank(value):
        return ""
    text = str(value).replace("|", "\\|").replace("\n", "<br>")
    return f"`{text}`" if command else text


def _markdown(block: Block, rerun: str) -> str:
    if isinstance(block, str):
        return block
    if isinstance(block, Legend):
        return "Verdicts: " + "; ".join(m.markdown() + f" {m.reason}" for m in block.marks)
    if isinstance(block, Details):
        return "\n\n".join([f"**{block.summary}**", *(_markdown(b, rerun) for b in block.blocks)])
    caption = _caption(block, rerun)
    if isinstance(block, Figure):
        return f"![{block.name}]({block.name}.svg)\n\n{caption}"
    frame = block.shown()
    lines = [
        f'<a id="{block.name}"></a>\n',
        "| " + " | ".join(map(str, frame.columns)) + " |",
        "|" + "---|" * len(frame.columns),
    ]
    for (_, row), (_, whole) in zip(frame.iterrows(), block.frame.iterrows(), strict=True):
        cells = [_markdown_cell(v, c in block.commands) for c, v in row.items()]
        if block.anchors:
            cells[0] = f'<a id="{whole[block.anchors]}"></a>{cells[0]}'
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + f"\n\n{caption}"


def save_figure(figure: MplFigure, name: str, data: pd.DataFrame, out: Path) -> None:
    """Write ``NAME.svg`` (reproducible: fixed ids, no date) and ``NAME.csv``.

    The page shows the vector image itself: a raster copy as well doubled the drawing time.
    """
    FigureCanvasAgg(figure)
    lay_out_once(figure)
    with rc_context({"svg.hashsalt": "lawbench"}):
        with replaced(out / f"{name}.svg", "report figure") as temporary:
            figure.savefig(temporary, format="svg", metadata={"Date": None})
    with replaced(out / f"{name}.csv", "report table") as temporary:
        data.to_csv(temporary, index=False)


def save_serially(figures: list[Figure], out: Path) -> None:
    """Save ``figures`` one after the other in this process."""
    for block in figures:
        save_figure(block.figure, block.name, block.data, out)


def _caption(block: Table | Figure, rerun: str) -> str:
    if isinstance(block, Table):
        return f"{block.caption} Table: [{block.name}.csv]({block.name}.csv)."
    files = ", ".join(f"[{block.name}.{ext}]({block.name}.{ext})" for ext in ("svg", "csv"))
    return f"{block.caption} Files: {files}. Rerun: `{rerun}`."


def _plain(frame: pd.DataFrame) -> pd.DataFrame:
    """The frame with marks written as their text, for CSV."""

    def text(value: Any) -> Any:
        if isinstance(value, Mark):
            return str(value.verdict)
        if isinstance(value, list | tuple) and value and all(isinstance(v, Mark) for v in value):
            return " ".join(m.markdown() for m in value)
        return value

    return frame.apply(lambda column: column.map(text))


def write_page(
    out: Path,
    title: str,
    preamble: Sequence[Block],
    sections: list[Section],
    rerun: str,
    save: Callable[[list[Figure], Path], None] = save_serially,
) -> None:
    """Write every file of the report into ``out``: figures, tables, HTML and Markdown.

    ``save`` writes the figures (for example in worker processes).
    """
    out.mkdir(parents=True, exist_ok=True)
    blocks = flat([*preamble, *(b for s in sections for b in s.blocks)])
    for block in blocks:
        if isinstance(block, Table):
            data = _plain(block.frame) if block.data is None else block.data
            with replaced(out / f"{block.name}.csv", "report table") as temporary:
                data.to_csv(temporary, index=False)
    _write_text(out / "index.html", _Html(rerun).page(title, preamble, sections))
    markdown = [f"# {title}", *(_markdown(b, rerun) for b in preamble)]
    for n, (part, children) in enumerate(contents(sections), 1):
        markdown.append(f"{n}. [{part.title}](#{part.anchor})")
        markdown += [f"    - [{c.title}](#{c.anchor})" for c in children]
    for section in sections:
        heading = "#" * section.level
        markdown.append(f'<a id="{section.anchor}"></a>\n\n{heading} {section.title}')
        markdown += [_markdown(b, rerun) for b in section.blocks]
    _write_text(out / "report.md", "\n\n".join(markdown) + "\n")
    save([b for b in blocks if isinstance(b, Figure)], out)


def _write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` whole or not at all (UTF-8, as the page declares)."""
    with replaced(path, "report page") as temporary:
        temporary.write_text(text, encoding="utf-8")


def number(value: float | None, scale: float = 0.0) -> str:
    """Four significant digits; rounding noise (below 1e-12 of ``scale``) shown as 0."""
    if value is None or value != value:
        return ""
    return f"{0.0 if abs(value) <= 1e-12 * scale else value:.4g}"
