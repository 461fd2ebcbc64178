"""Studies declared as data by the scenes and laws, built by the registry only when asked for."""

import subprocess
import sys

import pytest

from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.studies.declared import SHAPES, STUDIES, _Studies, build
from lawbench.studies.study import Study, costly, evenly
from lawbench.views.report.config import VIEWS, view

LOAD_EVERY_SCENE_AND_LAW = """
import sys
import lawbench.cases
from lawbench.core.case import CASES
from lawbench.core.law import LAWS
cases, laws = list(CASES.values()), list(LAWS.values())
assert cases and laws
declared = sum(len(entry.studies) for entry in (*cases, *laws))
assert declared > 30, declared
engine = sorted(m for m in sys.modules if m.startswith("lawbench.studies"))
print(",".join(engine))
"""


def test_loading_every_scene_and_law_builds_no_study_and_imports_no_study_engine():
    done = subprocess.run(
        [sys.executable, "-c", LOAD_EVERY_SCENE_AND_LAW],
        capture_output=True,
        text=True,
        check=True,
    )
    assert done.stdout.strip() == ""


def test_every_declaration_becomes_one_study_named_after_its_scene_or_law():
    declared = sum(len(case.studies) for case in CASES.values())
    assert len(STUDIES) >= declared + 1  # the engine's own summary, and the laws' studies
    grazing = STUDIES.get("lamina_grazing")
    assert isinstance(grazing, Study) and grazing.cases == ("lamina",)
    assert grazing.shape == "extremes"
    assert STUDIES.get("jia_path").laws == ("jia",)


def test_the_report_draws_every_study_by_its_shape():
    assert {study.shape for study in STUDIES.values()} <= set(VIEWS)
    assert all(view(study) is not None for study in STUDIES.values())
    assert view(STUDIES.get("lamina_speed_accuracy")) == "tradeoff"
    assert view(STUDIES.get("lamina_friction")) == "stability"


@pytest.mark.parametrize(
    ("declaration", "words"),
    [
        ({"shape": "spline", "name": "wiggle"}, ("scene lamina", "'wiggle'", "spline")),
        ({"shape": "speed_accuracy", "knobs": [1e-3]}, ("scene lamina", "speed_accuracy", "knobs")),
        ({"shape": "extremes", "name": "tall"}, ("scene lamina", "'tall'", "axis")),
        ({"title": "no shape"}, ("scene lamina", "None")),
    ],
)
def test_a_bad_declaration_is_an_invalid_problem_naming_its_scene_and_study(declaration, words):
    with pytest.raises(InvalidProblem) as raised:
        build(declaration, "case", "lamina")
    assert all(word in str(raised.value) for word in words), str(raised.value)


def test_a_law_declaration_names_the_law():
    with pytest.raises(InvalidProblem, match="law jia, study 'impact_path'"):
        build({"shape": "impact_path"}, "law", "jia")


def test_a_bad_declaration_stops_the_registry_when_it_is_first_asked(monkeypatch):
    lamina = type(CASES.get("lamina"))
    monkeypatch.setattr(lamina, "studies", (*lamina.studies, {"shape": "continuity", "e": 1}))
    fresh = _Studies("study", "lawbench.cases", Study)
    with pytest.raises(InvalidProblem, match="scene lamina, study 'continuity'"):
        fresh.names()
    monkeypatch.setattr(lamina, "studies", (*lamina.studies[:-1], {"shape": "speed_accuracy"}))
    fresh = _Studies("study", "lawbench.cases", Study)
    with pytest.raises(InvalidProblem, match="lamina_speed_accuracy' is declared twice"):
        fresh.names()


def test_every_shape_builds_a_study_the_report_draws():
    drawn = {"grazing", "duplicated_contact", "large_friction"}  # axes of the stability grid
    assert set(SHAPES) - drawn <= set(VIEWS)


def _values(jobs, law):
    """The parameter grid, options and transforms ``law``'s cells of ``jobs`` take."""
    cells = [job for job in jobs if job.law == law]
    return (
        {(tuple(map(str, job.params.values()))) for job in cells},
        {tuple(job.options.items()) for job in cells},
        {job.transform for job in cells},
    )


@pytest.mark.parametrize("name", ["three_ball_chain_grazing", "three_ball_chain_speed_accuracy"])
def test_the_quick_report_gives_the_laws_that_follow_time_a_subsample(name):
    """Engines and compliant laws get each axis's first value and their accuracy knob at its
    default; the others, and the full report, every value; the study as declared (``lawbench
    study``) is left whole."""
    declared = STUDIES.get(name)
    quick, full = declared.preset("quick"), declared.preset("full")
    assert full.costly_points is None and declared.costly_points is None
    assert quick.costly_points == 1
    whole, thinned = list(declared.jobs()), list(quick.jobs())
    laws = {job.law for job in whole}
    costly_laws = {law for law in laws if costly(LAWS.get(law))}
    assert {"mujoco", "compliant", "lzb"} <= costly_laws and "newton" in laws - costly_laws
    for law in laws:
        kept, every = _values(thinned, law), _values(whole, law)
        if law not in costly_laws:
            assert kept == every, law
            continue
        assert all(len(k) == 1 for k in kept), (law, kept)
        first = next(job for job in whole if job.law == law)
        (job,) = (job for job in thinned if job.law == law)
        knob = LAWS.get(law).tags.accuracy_knob
        default = LAWS.get(law).option_values()[knob]
        assert (job.params, job.transform) == (first.params, first.transform), law
        assert job.options == {
            **first.options,
            **({knob: default} if knob in first.options else {}),
        }
    assert len(list(full.jobs())) > len(whole) > len(thinned)


def test_evenly_spaced_values_keep_the_ends_and_one_is_the_first():
    assert evenly([1, 2, 3, 4, 5], 3) == [1, 3, 5]
    assert evenly([1, 2, 3], 1) == [1]
    assert evenly([1, 2], 5) == [1, 2] and evenly([1, 2], None) == [1, 2]


def test_the_quick_speed_accuracy_study_measures_a_thinned_law_for_model_error_but_its_truth():
    """In the quick report a law that follows the impact through time gets one point and no
    numerical error (its tightest setting is the costliest solve of its sweep), except the ground
    truth's own model, whose convergence the figure shows; the full report measures every
    law."""
    study = STUDIES["rocking_block_speed_accuracy"]
    laws = ["moreau", "lzb", "compliant", "mujoco"]
    quick = study.preset("quick").plan(laws, ["rocking_block"])
    kept = {job.law: set(quick.measures_of(job)) for job in quick.jobs}
    every = {"model_error", "numerical_error"}
    assert kept == {
        "moreau": every,
        "lzb": {"model_error"},
        "compliant": every,
        "mujoco": {"model_error"},
    }
    full = study.preset("full").plan(laws, ["rocking_block"])
    assert all(set(full.measures_of(job)) == every for job in full.jobs)


def test_the_quick_report_leaves_the_engines_to_the_full_one_where_a_scene_asks():
    """The rod, the lamina and the billiard shot leave their engine cells to the full report;
    the rocking block keeps them in the quick one."""
    engines = {law.name for law in LAWS.values() if law.engine}
    if not engines:
        pytest.skip("no engine installed")
    for case, kept in (("falling_rod", False), ("lamina", False), ("billiard", False)):
        assert CASES.get(case).quick_engines is kept
    for name, kept in (("falling_rod_speed_accuracy", False), ("rocking_block_friction", True)):
        study = STUDIES.get(name)
        quick = {job.law for job in study.preset("quick").jobs()}
        full = {job.law for job in study.preset("full").jobs()}
        assert engines <= full
        assert (engines <= quick) is kept and (not engines & quick) is not kept
