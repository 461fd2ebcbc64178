"""The page arranged by the reader's question: each scene, then the laws, then the run's health.

The sections are built by topic (outcomes, speed/accuracy, energy maps, ...); a reader choosing
a law reads by scene. `arrange` moves every block that belongs to one scene (a figure or table
named after it, a paragraph naming it alone) into that scene's section, topic by topic, and
leaves each topic's own text and its tables across scenes in the part on the laws, where the
scene sections link to it. Long tables and the figures of one law each fold in a `Details`.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from lawbench.views.report.page import Block, Details, Figure, Section, Table

# The topics of a scene's section, in the order a reader asks: outcome, sweeps, speed/accuracy
# trade, findings. Keys are the anchors of the topics' sections.
SCENE_TOPICS = {
    "outcomes": "Outcome",
    "sweeps": "Sweeps",
    "tradeoff": "Speed and accuracy",
    "paradoxes": "Findings: energy-increase map",
    "dispersion": "Findings: dispersion and continuity",
    "inside": "Findings: inside the impact",
}
# The laws' part, in this order; a topic of a scene's section is there too, with how to read it.
LAW_TOPICS = ("summary", "measured", "stability", *SCENE_TOPICS)
# Tables longer than this fold; the answer and the summary matrix never do.
FOLD_ROWS = 8
UNFOLDED = ("answer", "comparison")
CODE = re.compile(r"`([^`]+)`")


def scene_of(block: Block, names: Sequence[str]) -> str | None:
    """The one scene a block belongs to, or None.

    A figure or table whose name holds a scene's name between underscores (the longest such
    name); a paragraph that names, in code marks, exactly one scene.
    """
    if isinstance(block, Figure | Table):
        found = [n for n in names if f"_{n}_" in f"_{block.name}_"]
        return max(found, key=len) if found else None
    if isinstance(block, str):
        found = {n for n in CODE.findall(block) if n in names}
        return found.pop() if len(found) == 1 else None
    return None


def split(section: Section, names: Sequence[str]) -> tuple[list[Block], dict[str, list[Block]]]:
    """The blocks of ``section`` that belong to no scene, and those of each scene.

    A paragraph that names no scene and follows a scene's block stays with that block (a
    note under its figure).
    """
    general: list[Block] = []
    scenes: dict[str, list[Block]] = {}
    last: str | None = None
    for block in section.blocks:
        scene = scene_of(block, names)
        if scene is None and isinstance(block, str) and last is not None:
            scene = last
        if scene is None:
            general.append(block)
        else:
            scenes.setdefault(scene, []).append(block)
        last = scene
    return general, scenes


def fold(blocks: Sequence[Block]) -> list[Block]:
    """The blocks with each table longer than `FOLD_ROWS` folded under a line naming it."""
    folded: list[Block] = []
    for block in blocks:
        if isinstance(block, Table) and block.name not in UNFOLDED:
            if len(block.frame) > FOLD_ROWS:
                rows = len(block.frame)
                block = Details(f"Table `{block.name}` ({rows} rows): show", [block])
        folded.append(block)
    return folded


def _fold_figures(blocks: list[Block], what: str) -> list[Block]:
    """The blocks with their figures, after the first, folded together at the first's place."""
    figures = [b for b in blocks if isinstance(b, Figure)]
    if len(figures) < 2:
        return blocks
    rest = [b for b in blocks if not isinstance(b, Figure) or b is figures[0]]
    return [*rest, Details(f"{len(figures) - 1} more figures, {what}: show", figures[1:])]


def arrange(topics: dict[str, Section], names: Sequence[str], health: list[Block]) -> list[Section]:
    """The page's sections: the scenes, the laws, the health of the run.

    ``topics`` are the sections built by topic, by anchor; ``names`` the scenes in order.
    """
    per_scene: dict[str, dict[str, list[Block]]] = {name: {} for name in names}
    general: dict[str, list[Block]] = {}
    for anchor, section in topics.items():
        if anchor not in SCENE_TOPICS:
            general[anchor] = section.blocks
            continue
        general[anchor], scenes = split(section, names)
        for name, blocks in scenes.items():
            per_scene[name][anchor] = blocks
    sections = [
        Section(
            "scenes",
            "Scene by scene",
            [
                "Each scene's outcome, sweeps, speed/accuracy trade and findings; how to read "
                "each kind of figure is in [The laws](#laws)."
            ],
        )
    ]
    for name, found in per_scene.items():
        if not found:
            continue
        sections.append(Section(f"scene-{name}", name, [], level=3))
        for anchor, title in SCENE_TOPICS.items():
            if anchor in found:
                read = f"How to read it: [{topics[anchor].title}](#{anchor})."
                blocks = fold([read, *found[anchor]])
                sections.append(Section(f"scene-{name}-{anchor}", title, blocks, level=4))
    sections.append(
        Section(
            "laws",
            "The laws",
            [
                "Every law's checks and findings, against measurements and at the extremes, and "
                "how to read each kind of figure of the scenes."
            ],
        )
    )
    for anchor in [*LAW_TOPICS, *(a for a in topics if a not in LAW_TOPICS)]:
        if anchor in topics:
            blocks = fold(general[anchor])
            if anchor == "stability":
                blocks = _fold_figures(blocks, "one per law")
            sections.append(Section(anchor, topics[anchor].title, blocks, level=3))
    sections.append(Section("health", "Health of the run", fold(health)))
    return sections
