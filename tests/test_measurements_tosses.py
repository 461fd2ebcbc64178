"""Impacts extracted from tracked tosses: a synthetic toss with a known impulse at one vertex.

The toss is free flight, one impulse at the lowest vertex of a cube of side 0.1048 m and
0.37 kg, then free flight, sampled at 148 Hz with noise of 0.2 mm on the centre and 2 mrad on
the orientation, as the ContactNets tracker's residuals suggest. The extraction recovers the
velocities on either side within a few standard errors of the fits.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lawbench.measurements import MeasuredImpact, consistency
from lawbench.measurements.sets.cube import INERTIA, MASS, VERTICES
from lawbench.measurements.tosses import GRAVITY, Extraction, first_impact, vertex_problem

RATE = 148.0


def flight(position, velocity, omega, rotation, tau):
    """Free flight from a state, ``tau`` seconds on (negative: back)."""
    fall = np.array([0.0, 0.0, GRAVITY])
    return (
        position + velocity * tau - fall * tau**2 / 2,
        Rotation.from_rotvec(omega * tau) * rotation,
    )


@pytest.fixture
def toss():
    """A toss sampled around an impact at t = 15.4 frames, with its true velocities."""
    rotation = Rotation.from_euler("xyz", [0.3, 0.5, 0.2])
    offsets = rotation.apply(VERTICES)
    lowest = int(np.argmin(offsets[:, 2]))
    position = np.array([0.1, -0.05, -offsets[lowest, 2]])
    v_before = np.array([0.4, -0.2, -1.5, 2.0, -3.0, 1.0])
    problem = vertex_problem(MASS, INERTIA, offsets[[lowest]], v_before)
    impulse = np.array([0.5, 0.04, -0.03])
    v_after = v_before + problem.solve_mass(problem.W @ impulse)
    assert problem.un[0] < 0 < (problem.Wn.T @ v_after)[0]
    impact_time = 15.4 / RATE
    times = np.arange(40) / RATE
    rng = np.random.default_rng(7)
    positions, rotations = [], []
    for time in times:
        v = v_before if time < impact_time else v_after
        p, r = flight(position, v[:3], v[3:], rotation, time - impact_time)
        positions.append(p + rng.normal(0.0, 2e-4, 3))
        rotations.append(Rotation.from_rotvec(rng.normal(0.0, 2e-3, 3)) * r)
    return times, np.array(positions), Rotation.concatenate(rotations), v_before, v_after, lowest


def test_a_synthetic_toss_gives_back_its_velocities_within_the_noise(toss):
    times, positions, rotations, v_before, v_after, lowest = toss
    found = first_impact(times, positions, rotations, VERTICES, 0.0, Extraction(rate=RATE))
    assert not isinstance(found, str), found
    assert found.time == pytest.approx(15.4 / RATE, abs=0.3 / RATE)
    assert np.flatnonzero(found.touching).tolist() == [lowest]
    for measured, true in ((found.v_before, v_before), (found.v_after, v_after)):
        assert np.abs(measured[:3] - true[:3]).max() < 0.03
        assert np.abs(measured[3:] - true[3:]).max() < 0.2
    offsets = found.rotation.apply(VERTICES[found.touching])
    impact = MeasuredImpact(vertex_problem(MASS, INERTIA, offsets, found.v_before), found.v_after)
    assert consistency([impact]).median < 0.03
    assert max(found.facts["fit_residuals_m"]) < 1e-3


def test_a_toss_without_an_impact_or_with_a_quick_second_one_is_dropped_with_its_reason(toss):
    times, positions, rotations, *_ = toss
    assert first_impact(times[:14], positions[:14], rotations[:14], VERTICES) == "no impact found"
    bounced = positions.copy()
    bounced[20:, 2] += np.arange(20) ** 2 * 0.01
    found = first_impact(times, bounced, rotations, VERTICES)
    assert found == "too few samples between the impact and the next"
