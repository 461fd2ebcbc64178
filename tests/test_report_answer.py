"""The report's first screen and its layout: the answer, the scenes, the laws, the run's health.

The answer recommends only cells that hold and chooses the same laws from two timings; the page
reads in that order in Chromium at 1280 x 900, with the answer on the first screen.
"""

import dataclasses
import re
import subprocess
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pandas as pd
import pytest

import lawbench
from lawbench.core.verdicts import Verdict
from lawbench.views.report import QUICK, answer, write_report
from lawbench.views.report.answer import LEVELS

CHROMIUM = Path("/usr/bin/chromium")
SET_ASIDE = ("numerical failure", "budget", "unexplained")
# The energetic law's sweep on the chain of three balls: its loosest tolerances are numerical
# failures there, its tightest holds within every level. On the rocking block at e = 0 the
# ground truth is Housner's closed form, which the impulse-level laws with friction reach.
SWEPT = ("three_ball_chain", "rocking_block")
TRADE = dataclasses.replace(
    QUICK,
    measurements=(),
    budget_s=60.0,
    laws=("newton", "sequential", "whittaker", "moreau", "lzb"),
    cases=SWEPT,
    studies=tuple(f"{scene}_speed_accuracy" for scene in SWEPT),
)


@pytest.fixture(scope="module")
def trade(tmp_path_factory):
    """A report of the speed/accuracy studies alone, on two chains."""
    return write_report(tmp_path_factory.mktemp("report") / "trade", config=TRADE)


def figures_of(page: str) -> list[str]:
    return re.findall(r'<img src="([^"]+)\.svg"', page)


def test_the_page_reads_answer_scenes_laws_health_and_every_link_lands(report):
    """The answer before the contents, then one section per scene, the laws, the run's
    health; every link inside the page has its target."""
    page = (report / "index.html").read_text()
    order = ['<table id="answer"', '<nav id="contents">', 'id="scenes"', 'id="laws"']
    order += ['id="health"']
    places = [page.index(marker) for marker in order]
    assert places == sorted(places), places
    for scene in ("three_ball_chain", "lamina"):
        assert page.index(f'<h3 id="scene-{scene}">') < page.index('id="laws"'), scene
    targets = set(re.findall(r'id="([^"]+)"', page))
    links = set(re.findall(r'href="#([^"]+)"', page))
    assert links - targets == set()
    contents = page.split('<nav id="contents">', 1)[1].split("</nav>", 1)[0]
    assert {"scenes", "laws", "health", "scene-lamina", "summary"} <= set(
        re.findall(r'href="#([^"]+)"', contents)
    )


def _answer(report: Path) -> pd.DataFrame:
    """The answer table by scene name (measured sets left out)."""
    table = pd.read_csv(report / "answer.csv", keep_default_na=False)
    table = table[table["scene"].str.startswith("[")]
    return table.set_index(table["scene"].str.extract(r"\[(\w+)\]")[0])


def _points(report: Path, scene: str) -> pd.DataFrame:
    """The speed/accuracy points of ``scene`` as the report computed them."""
    data = pd.read_csv(report / f"tradeoff_{scene}.csv", dtype={"knob": str, "failure": str})
    return data.fillna({"knob": "", "failure": ""}).astype({"candidate": bool})


def _same(value, shown: str) -> bool:
    """Whether a knob value read from the CSV is the one a cell shows."""
    try:
        return bool(np.isclose(float(value), float(shown)))
    except ValueError:
        return str(value) == shown


def _recommended(cell: str, points: pd.DataFrame) -> pd.Series:
    """The point a cell of the answer names (``law (knob=value), ...``)."""
    law, knob, value = re.match(r"(\w+)(?: \((\w+)=([^)]+)\))?", cell).groups()
    rows = points[points["law"] == law]
    if knob:
        rows = rows[[_same(v, value) for v in rows["value"]]]
    assert len(rows) == 1, (cell, rows)
    return rows.iloc[0]


def test_on_the_lamina_the_cheapest_law_is_as_close_to_the_ground_truth_as_each_level(report):
    """Brach's omega+ = 0.5 (Brogliato 2010, eq. 11 on the lamina) is measured against the
    compliant ground truth's own answer, and the truth's model is never the cheapest law."""
    case = lawbench.CASES.get("lamina")
    truth = case.ground_truth
    omega = lawbench.LAWS.get(truth.law).resolve(case.build(), **truth.options).v_plus[0]
    points = _points(report, "lamina")
    brach = points[points["law"] == "brach"]
    assert brach["model_error"].iloc[0] == pytest.approx(abs(0.5 - omega), rel=1e-6)
    lamina = _answer(report).loc["lamina"]
    assert lamina["ground truth"] == truth.describe()
    assert lamina["closest law, model error"] != "none"
    for level in LEVELS:
        chosen = lamina[f"cheapest with model error ≤ {level:g}"]
        if chosen != "none":
            point = _recommended(chosen, points)
            assert point["law"] not in ("brach", truth.law)
            assert point["model_error"] <= level, (level, chosen)


@pytest.mark.parametrize("name", ["report", "trade"])
def test_no_recommended_cell_is_a_failure_a_budget_or_unexplained(name, request):
    """Across every scene: the closest and the cheapest laws are cells that hold, and every
    cell set aside is counted and linked to its line in the health of the run."""
    report = request.getfixturevalue(name)
    answer = _answer(report)
    page = (report / "index.html").read_text()
    recommended = [c for c in answer.columns if c.startswith(("closest", "cheapest"))]
    checked = 0
    for scene, row in answer.iterrows():
        points = _points(report, scene)
        for column in recommended:
            if row[column] != "none":
                point = _recommended(row[column], points)
                assert point["verdict"] in ("holds", "law property"), (scene, column)
                checked += 1
        aside = points[points["candidate"] & points["verdict"].isin(SET_ASIDE)]
        for anchor in re.findall(r"\(#(cell-\w+)\)", row["set aside"]):
            assert f'<tr id="{anchor}">' in page, (scene, anchor)
        assert row["set aside"].count("](#cell-") == len(aside), scene
    assert checked > 0
    total = sum(row["set aside"].count("](#cell-") for _, row in answer.iterrows())
    assert f"{total} cells were set aside" in page


@pytest.mark.parametrize("scene", SWEPT)
def test_the_same_points_retimed_give_the_same_answer(trade, scene):
    """Two timings of the same cells (each the shortest after a warm-up) choose the same laws."""
    case = lawbench.CASES.get(scene)
    points = _points(trade, scene)
    first, second = (answer.retime(case, points) for _ in range(2))
    assert first.notna().sum() >= 1
    chosen = answer.choices(points, first)
    assert chosen == answer.choices(points, second)
    assert chosen["within 0.01"] != "none"


def test_a_tie_goes_to_the_loosest_tolerance_and_a_failing_cell_is_never_chosen():
    points = pd.DataFrame(
        {
            "law": ["lzb", "lzb", "jia", "newton"],
            "knob": ["tol", "tol", "tol", ""],
            "value": [1e-2, 1e-6, 1e-3, np.nan],
            "model_error": [1e-3, 1e-7, 1e-3, 1e-3],
            "verdict": ["numerical failure", "holds", "holds", "law property"],
            "candidate": True,
            "failure": "",
        }
    )
    costs = pd.Series([1e-4, 1e-3, 1.3e-3, 1.4e-3])
    assert answer.choose(points, costs, 1e-2)["law"] == "newton"  # no knob: the loosest
    assert answer.choose(points, costs.mul([1, 1, 1, 2]), 1e-2)["law"] == "jia"
    assert answer.choose(points, costs, 1e-6)["law"] == "lzb"
    assert answer.choose(points, costs, 1e-8) is None
    assert answer.closest(points)["value"] == 1e-6
    holding = points.assign(verdict="holds")
    assert answer.choose(holding, costs.mul([30, 1, 9, 9]), 1e-2)["value"] == 1e-2
    assert answer.choose(holding, costs.mul([30, 1, 9, 9]), 1e-6)["value"] == 1e-6


def test_an_engine_at_its_defaults_is_shown_with_the_tightest_level_it_reaches():
    """Only an engine's point at all its default options is shown; a law is never shown."""
    points = pd.DataFrame(
        {
            "law": ["pybullet", "pybullet", "mujoco", "moreau"],
            "model_error": [0.34, 1e-5, 3e-3, 1e-8],
            "options": ['{"dt": 0.0}', '{"dt": 0.0001}', "{}", '{"tol": 1e-10}'],
        }
    )
    shown = answer.at_defaults(points)
    assert shown == "pybullet 0.34 (none within 0.01), mujoco 0.003 (within 0.01)"
    assert answer.at_defaults(points.iloc[3:]) == "no engine answered"


# In the browser: measured with the page's folds closed, then everything measured with them open.
PROBE = """<script>window.addEventListener('load', async () => {
const body = document.body, set = (k, v) => body.setAttribute('data-' + k, v);
set('answer-top', Math.round(document.getElementById('answer').getBoundingClientRect().top
  + window.scrollY));
set('height', document.documentElement.scrollHeight);
document.querySelectorAll('details').forEach(d => { d.open = true; });
const images = Array.from(document.images);
await Promise.all(images.map(i => i.complete ? null
  : new Promise(r => { i.onload = r; i.onerror = r; })));
const broken = images.filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src);
const legend = document.querySelector('#summary ~ .legend');
const marks = legend ? Array.from(legend.querySelectorAll('.mark')) : [];
const commands = Array.from(document.querySelectorAll('code.reproducer'));
const strays = commands.filter(c => !c.textContent.startsWith('lawbench '));
set('images', images.length);
set('broken', broken.join(' '));
set('legend', marks.map(m => m.textContent).join('|'));
set('colours', new Set(marks.map(m => getComputedStyle(m).backgroundColor)).size);
set('commands', commands.length);
set('strays', strays.map(c => c.textContent).join('|'));
const page = document.documentElement.clientWidth;
const wide = Array.from(document.querySelectorAll('.scroll, figure, p, nav, details'))
  .filter(e => e.getBoundingClientRect().right > page + 1)
  .map(e => (e.id || e.tagName) + ':' + Math.round(e.getBoundingClientRect().width));
set('width', document.documentElement.scrollWidth);
set('wide', wide.join(' '));
const split = [];
for (const th of document.querySelectorAll('th')) {
  const walker = document.createTreeWalker(th, NodeFilter.SHOW_TEXT);
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    for (const word of node.data.matchAll(/\\S+/g)) {
      const range = document.createRange();
      range.setStart(node, word.index);
      range.setEnd(node, word.index + word[0].length);
      const rects = Array.from(range.getClientRects()).filter(r => r.width > 0);
      if (new Set(rects.map(r => Math.round(r.top))).size > 1) split.push(word[0]);
    }
  }
}
set('split', split.join('|'));
set('shown', images.map(i => i.alt + ':' + i.getBoundingClientRect().width).join(' '));
});</script>"""
# Tick labels are text drawn as glyph paths, scaled from matplotlib's 100-point glyphs.
TICK = re.compile(r"[xy]tick_\d+")
SVG = "{http://www.w3.org/2000/svg}"


def tick_points(svg: Path) -> tuple[float | None, float]:
    """The smallest tick label's size in points and the figure's width in points."""
    root = ElementTree.parse(svg).getroot()
    sizes = [
        100 * float(m[1])
        for g in root.iter(f"{SVG}g")
        if TICK.fullmatch(g.get("id") or "")
        for text in g.iter(f"{SVG}g")
        if (m := re.search(r"scale\(([\d.e+-]+)", text.get("transform") or ""))
    ]
    return (min(sizes) if sizes else None), float(root.get("viewBox").split()[2])


def _attribute(dom: str, name: str) -> str:
    return re.search(rf'data-{name}="([^"]*)"', dom)[1]


@pytest.mark.skipif(
    not CHROMIUM.exists(), reason="needs /usr/bin/chromium (Debian package chromium)"
)
def test_the_page_renders_in_chromium_with_its_answer_first_and_readable_headers(report, tmp_path):
    """At 1280 x 900: the answer on the first screen, no header cell broken inside a word,
    nothing wider than the window, every figure drawn, every tick label at least 9 px tall."""
    probe = report / "probe.html"
    probe.write_text((report / "index.html").read_text().replace("</body>", PROBE + "</body>"))
    command = [
        str(CHROMIUM),
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--allow-file-access-from-files",
        "--virtual-time-budget=20000",
        "--window-size=1280,900",
    ]
    dom = subprocess.run(
        [*command, "--dump-dom", probe.as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    assert int(_attribute(dom, "answer-top")) <= 1350
    print(f"page height {_attribute(dom, 'height')} px at 1280 px wide")
    images = int(_attribute(dom, "images"))
    assert images == len(figures_of((report / "index.html").read_text())) > 0
    assert _attribute(dom, "broken") == ""
    legend = _attribute(dom, "legend").split("|")
    assert [text.rstrip("✓✗!·»?") for text in legend] == [str(v) for v in Verdict]
    assert _attribute(dom, "colours") == str(len(Verdict))
    assert int(_attribute(dom, "commands")) > 0
    assert _attribute(dom, "strays") == ""
    assert _attribute(dom, "split") == "", "header cells broken inside a word"
    assert int(_attribute(dom, "width")) <= 1280
    assert _attribute(dom, "wide") == ""
    rendered = {}
    for shown in _attribute(dom, "shown").split():
        name, width = shown.rsplit(":", 1)
        points, whole = tick_points(report / f"{name}.svg")
        if points is not None:
            rendered[name] = points * float(width) / whole
    assert rendered, "no tick label found in the page's figures"
    small = {name: f"{px:.1f} px" for name, px in rendered.items() if px < 9}
    assert not small, f"tick labels under 9 px tall: {small}"
    shot = tmp_path / "page.png"
    subprocess.run(
        [*command, f"--screenshot={shot}", probe.as_uri()],
        capture_output=True,
        timeout=120,
        check=True,
    )
    assert shot.stat().st_size > 10_000
    probe.unlink()
