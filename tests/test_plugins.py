"""Laws and scenes from other distributions, found through entry points, held to the checks.

A throwaway distribution is written to a temporary folder (a package and a ``.dist-info``
with ``entry_points.txt``), put on ``PYTHONPATH``, and the command line must see its law and
its scene with no edit to lawbench.
"""

import os
import subprocess
import sys
import textwrap

import pytest

TOY = '''
"""A toy law and scene for the plugin test.

Source: Newton's law of restitution at one contact. Conventions: un < 0 approaches.
The scene: one ball on a wall; coordinates: the ball's velocity (m/s).
"""

import numpy as np

import lawbench


class Mirror(lawbench.Law):
    name = "mirror"
    summary = "Newton's restitution at one contact"
    source = "Newton's law of restitution"
    tags = lawbench.Tags()

    def _resolve(self, problem, options):
        Pn = -(1 + problem.restitution("kinematic")) * problem.un / np.diag(problem.delassus)
        return lawbench.Outcome.from_impulses(problem, np.maximum(Pn, 0.0),
                                              diagnostics={"formulation": "closed form"})


class Gainer(Mirror):
    name = "gainer"
    summary = "restitution that creates energy (broken on purpose)"

    def _resolve(self, problem, options):
        Pn = -3.0 * problem.un / np.diag(problem.delassus)
        return lawbench.Outcome.from_impulses(problem, Pn,
                                              diagnostics={"formulation": "closed form"})


class BallOnWall(lawbench.Case):
    name = "ball_on_wall"
    summary = "one ball on a wall"
    params = (lawbench.Spec("e", 0.5, "restitution", low=0.0, high=1.0),)
    examples = {"default": {}}

    def _build(self, params):
        return lawbench.ImpactProblem.from_arrays(
            np.eye(1), [[1.0]], [-1.0], e=params["e"], bodies={"ball": [0]}
        )

    def coordinates(self, params):
        return ["ball (m/s)"]
'''

ENTRY_POINTS = """
[lawbench.laws]
mirror = toy_plugin:Mirror
gainer = toy_plugin:Gainer
broken = toy_plugin_missing:Nothing

[lawbench.cases]
ball_on_wall = toy_plugin:BallOnWall
"""


def distribution(root, name, modules, entry_points):
    """Write a distribution of ``modules`` (name -> source) with ``entry_points`` into ``root``.

    Returns the environment that puts it on ``PYTHONPATH``.
    """
    for module, source in modules.items():
        (root / f"{module}.py").write_text(source)
    info = root / f"{name.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(entry_points)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(root), env.get("PYTHONPATH", "")])
    return env


@pytest.fixture(scope="module")
def plugin_env(tmp_path_factory):
    root = tmp_path_factory.mktemp("plugin")
    modules = {"toy_plugin": textwrap.dedent(TOY)}
    return root, distribution(root, "toy-plugin", modules, ENTRY_POINTS)


def lawbench_cli(env, *argv, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "lawbench", *argv], capture_output=True, text=True, env=env, cwd=cwd
    )


def test_the_plugin_law_and_scene_are_listed_and_a_broken_one_is_reported(plugin_env):
    _, env = plugin_env
    listed = lawbench_cli(env, "list")
    assert listed.returncode == 0, listed.stderr
    assert "mirror" in listed.stdout and "ball_on_wall" in listed.stdout
    assert "not loaded" in listed.stdout and "broken" in listed.stdout
    assert "newton" in listed.stdout  # the built-in laws still load


def test_the_plugin_law_solves_and_passes_the_common_checks(plugin_env):
    _, env = plugin_env
    solved = lawbench_cli(env, "solve", "mirror", "ball_on_wall", "--json")
    assert solved.returncode == 0, solved.stderr
    checked = lawbench_cli(env, "check", "mirror")
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert "holds" in checked.stdout


def test_a_law_that_creates_energy_fails_the_check_by_name(plugin_env):
    _, env = plugin_env
    checked = lawbench_cli(env, "check", "gainer", "--random", "0")
    assert checked.returncode == 6
    assert "energy_gain" in checked.stderr.splitlines()[-1]


def test_a_grid_run_takes_the_plugin(plugin_env, tmp_path):
    _, env = plugin_env
    done = lawbench_cli(
        env,
        "run",
        "--laws",
        "mirror,newton",
        "--cases",
        "ball_on_wall",
        "--out",
        "run.csv",
        "--format",
        "csv",
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    text = (tmp_path / "run.csv").read_text()
    assert "mirror" in text and "newton" in text


def test_a_new_law_and_scene_need_no_baseline_edit(plugin_env):
    """Adding a law or scene touches no committed baseline: regress says there is none yet."""
    _, env = plugin_env
    done = lawbench_cli(env, "regress", "--laws", "mirror,newton", "--cases", "ball_on_wall")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "no baseline yet for mirror on ball_on_wall" in done.stdout


REPORT = """
import dataclasses, pathlib, sys
from lawbench.views.report import write_report
from lawbench.views.report.config import QUICK

config = dataclasses.replace(
    QUICK, laws=("mirror", "newton"), cases=("ball_on_wall",), measurements=(), workers=1
)
write_report(pathlib.Path(sys.argv[1]), config=config)
"""


def test_the_report_shows_the_plugin_law_on_the_plugin_scene(plugin_env, tmp_path):
    """The summary matrix of a report restricted to the plugin's law and scene shows both."""
    _, env = plugin_env
    done = subprocess.run(
        [sys.executable, "-c", REPORT, str(tmp_path / "report")],
        capture_output=True,
        text=True,
        env=env,
    )
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "report" / "report.md").read_text()
    assert "Scenes: `ball_on_wall`" in page
    rows = [line for line in page.splitlines() if line.startswith("| mirror | ")]
    # The summary matrix: the cell's one mark is its worst verdict, and every check holds.
    assert any(row.split("|")[2].strip() == "✓" for row in rows), rows
