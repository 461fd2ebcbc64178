"""The billiard shot: geometry of the two contacts, the straight shot, the masse shot."""

import json
import math

import numpy as np
import pytest

import lawbench
from lawbench.cases.billiard import cue_geometry
from lawbench.views.cli import main

CASE = lawbench.CASES.get("billiard")
STRAIGHT = CASE.examples["straight"]


@pytest.mark.parametrize(
    "shot",
    [
        {},
        {"elevation": 30.0, "offset_side": 0.01},
        {"elevation": 70.0, "offset_side": -0.012, "offset_height": 0.005},
    ],
)
def test_contact_rates_are_the_velocities_of_the_touching_points(shot):
    """For any motion (cue speed u, ball v and w), Wn^T and Wt^T give the relative velocity of
    the touching points along the normals and tangents, computed here point by point."""
    params = CASE.parameters(**shot)
    problem = CASE.build(**params)
    d, r, n, tangents = cue_geometry(params)
    radius = params["radius"]
    rng = np.random.default_rng(3)
    for _ in range(5):
        qdot = rng.normal(size=7)
        u, v, w = qdot[0], qdot[1:4], qdot[4:]
        at_cue = v + np.cross(w, r) - u * d
        at_table = v + np.cross(w, [0.0, 0.0, -radius])
        expected_n = [at_cue @ n, at_table[2]]
        expected_t = [at_cue @ t for t in tangents] + [at_table[0], at_table[1]]
        np.testing.assert_allclose(problem.Wn.T @ qdot, expected_n, atol=1e-14)
        np.testing.assert_allclose(problem.Wt.T @ qdot, expected_t, atol=1e-14)
    assert abs(np.linalg.norm(r) - radius) < 1e-15
    assert problem.un[0] < 0 and problem.un[1] == 0.0


def test_the_straight_shot_is_the_frictionless_binary_impact():
    """Horizontal, through the centre: no contact point slips and the two normals are
    orthogonal in the kinetic metric, so friction cannot act; the cue's impulse is
    P = (1 + e) u m mc / (m + mc) (Newton's binary impact), no spin, whatever mu."""
    params = CASE.parameters(**STRAIGHT)
    m, mc, u, e = params["mass"], params["cue_mass"], params["speed"], params["e"][0]
    impulse = (1 + e) * u * m * mc / (m + mc)
    expected = [u - impulse / mc, impulse / m, 0, 0, 0, 0, 0]
    for mu in ([0.6, 0.2], [0.0, 0.0]):
        outcome = lawbench.solve("moreau", "billiard", mu=mu, **STRAIGHT)
        np.testing.assert_allclose(outcome.v_plus, expected, atol=1e-9)


def test_a_masse_shot_spins_the_ball_about_a_tilted_axis():
    """The default shot, a steep cue struck off the centre, presses the ball into the table:
    both contacts take friction and the spin axis is neither vertical nor horizontal (Jia
    2012, the masse shot)."""
    outcome = lawbench.solve("moreau", "billiard")
    w = outcome.v_plus[4:]
    tilt = math.degrees(math.asin(abs(w[2]) / np.linalg.norm(w)))
    assert 10.0 < tilt < 80.0
    assert outcome.Pn[1] > 0 and np.linalg.norm(outcome.Pt[2:]) > 0
    assert outcome.dT < 0


def test_jia_solves_the_default_shot_with_friction_at_both_contacts(capsys):
    """`lawbench solve jia billiard`: the masse shot's cue grips the ball and the ball slides
    on the cloth, so both contacts take a tangential impulse, each inside its cone."""
    assert main(["solve", "jia", "billiard", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    Pn, Pt = np.array(record["Pn"]), np.reshape(record["Pt"], (2, 2))
    mu = CASE.parameters()["mu"]
    for j in range(2):
        assert 1e-3 * Pn[j] < np.linalg.norm(Pt[j]) <= mu[j] * Pn[j] * (1 + 1e-9), j


def test_a_cue_that_misses_the_ball_is_refused():
    with pytest.raises(lawbench.InvalidProblem, match="misses the ball"):
        CASE.build(offset_side=0.03)


def test_mirrored_offsets_give_mirrored_shots():
    """Reflecting the shot in the vertical plane of the cue (y -> -y) reflects the outcome: the
    ball's vy and the spin components wx, wz (a pseudovector) change sign, the rest stays."""
    mirror = np.array([1, 1, -1, 1, -1, 1, -1])
    for elevation in (0.0, 60.0):
        left = lawbench.solve("moreau", "billiard", elevation=elevation, offset_side=-0.01)
        right = lawbench.solve("moreau", "billiard", elevation=elevation, offset_side=0.01)
        np.testing.assert_allclose(left.v_plus, mirror * right.v_plus, atol=1e-7)


def test_english_alone_runs_straight_and_a_masse_shot_curves():
    """Spin about the vertical leaves the slip at the cloth along the velocity, so the table's
    friction only slows the ball: the path's curvature is zero for a horizontal shot with side
    offset; a masse shot's tilted spin axis bends the path, the mirrored shot the other way."""
    from lawbench.cases.billiard import path_curvature
    from lawbench.core.trial import Trial

    def curvature(**params):
        params = CASE.parameters(**params)
        problem = CASE.build(**params)
        outcome = lawbench.LAWS.get("moreau").resolve(problem)
        law = lawbench.LAWS.get("moreau")
        return path_curvature(Trial(law, CASE, params, {}, problem, outcome, {}))

    assert curvature(**CASE.examples["side spin"]) == pytest.approx(0.0, abs=1e-9)
    bent = curvature()
    assert abs(bent) > 0.1
    assert curvature(offset_side=-CASE.parameters()["offset_side"]) == pytest.approx(-bent)


@pytest.mark.parametrize("law", ["moreau", "jia", "compliant"])
def test_the_path_on_the_cloth_hops_slides_on_a_parabola_and_rolls(law):
    """After the masse shot the ball hops for 2 vz / g, then slides: its acceleration is
    -mu2 g along the initial slip, and it rolls from t_roll on at v0 - (2/7) s0 (a solid
    sphere: the classical 5/7 of a spinless ball's speed), its path a straight line after the
    parabola."""
    from lawbench.cases.billiard import table_path
    from lawbench.core.trial import Trial

    params = CASE.parameters()
    problem = CASE.build(**params)
    outcome = lawbench.LAWS.get(law).resolve(problem)
    trial = Trial(lawbench.LAWS.get(law), CASE, params, {}, problem, outcome, {})
    path = table_path(trial)
    v, w = outcome.v_plus[1:4], outcome.v_plus[4:]
    radius, mu, g = params["radius"], params["mu"][1], 9.81
    slip = np.array([v[0] - radius * w[1], v[1] + radius * w[0]])
    assert path["t_land"] == pytest.approx(2 * max(v[2], 0.0) / g)
    assert path["t_roll"] - path["t_land"] == pytest.approx(2 * np.linalg.norm(slip) / (7 * mu * g))
    t, xy = np.array(path["t"]), np.column_stack([path["x"], path["y"]])
    rolling = t > path["t_roll"] + 1e-9
    speed = np.diff(xy[rolling], axis=0) / np.diff(t[rolling])[:, None]
    np.testing.assert_allclose(speed, np.tile(v[:2] - 2 / 7 * slip, (len(speed), 1)), atol=1e-9)
    sliding = (t > path["t_land"] + 1e-9) & (t < path["t_roll"] - 1e-9)
    assert sliding.sum() >= 3
    on_parabola = xy[sliding]
    accel = (on_parabola[2:] - 2 * on_parabola[1:-1] + on_parabola[:-2]) / (t[1] - t[0]) ** 2
    expected = -mu * g * slip / np.linalg.norm(slip)
    np.testing.assert_allclose(accel, np.tile(expected, (len(accel), 1)), atol=1e-6)
