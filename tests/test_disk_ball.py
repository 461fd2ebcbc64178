"""The disk-ball scene: its Jacobians against rigid motions, and the energetic law along b."""

import numpy as np
import pytest

import lawbench
from lawbench.cases.disk_ball import disk_inertia, jacobians

R, H, B = 0.05, 0.005, 0.02


def _rotation(theta: float) -> np.ndarray:
    return np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])


def _gaps(q: np.ndarray) -> np.ndarray:
    """Exact gaps of A, B, C (height above the floor) and D (ball off the face), at q.

    q = (yb, zb, yd, zd, theta); at q = (yd - h, zd + b, yd, zd, 0) every gap is zero when the
    disk stands on the floor (zd = r).
    """
    ball, centre, rot = q[:2], q[2:4], _rotation(q[4])
    floor = [(centre + rot @ rho)[1] for rho in ([-H, -R], [0.0, -R], [H, -R])]
    normal = rot @ np.array([-1.0, 0.0])
    face = centre + rot @ np.array([-H, 0.0])
    return np.array([*floor, normal @ (ball - face)])


def _slips(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Relative tangential velocities of A, B, C (+y) and D (ball over the face, +z), by hand."""
    centre_v, omega = v[2:4], v[4]

    def point_velocity(rho):
        return centre_v + omega * np.array([-rho[1], rho[0]])

    floor = [point_velocity(rho)[0] for rho in ([-H, -R], [0.0, -R], [H, -R])]
    ball_over_face = v[1] - point_velocity([-H, B])[1]
    return np.array([*floor, ball_over_face])


RIGID_MOTIONS = {
    "ball alone": [1.0, 0.0, 0.0, 0.0, 0.0],
    "disk lifted": [0.0, 0.0, 0.0, 1.0, 0.0],
    "disk slides": [0.0, 0.0, 1.0, 0.0, 0.0],
    "rolls about B": [0.0, 0.0, -R * 2.0, 0.0, 2.0],
    "spins about O": [0.0, 0.0, 0.0, 0.0, 1.0],
    "everything": [0.3, -0.7, 1.1, 0.4, -2.5],
}


@pytest.mark.parametrize("motion", RIGID_MOTIONS, ids=list(RIGID_MOTIONS))
def test_normal_jacobian_is_the_rate_of_the_exact_gaps(motion):
    """Wn^T v equals d(gap)/dt of the exact geometry (central difference) for rigid motions."""
    v = np.array(RIGID_MOTIONS[motion])
    q0 = np.array([-H, R + B, 0.0, R, 0.0])
    np.testing.assert_allclose(_gaps(q0), 0.0, atol=1e-15)
    dt = 1e-6
    rate = (_gaps(q0 + dt * v) - _gaps(q0 - dt * v)) / (2 * dt)
    Wn, _ = jacobians(R, H, B)
    np.testing.assert_allclose(Wn.T @ v, rate, atol=1e-8)


@pytest.mark.parametrize("motion", RIGID_MOTIONS, ids=list(RIGID_MOTIONS))
def test_tangential_jacobian_is_the_slip_rate(motion):
    """Wt^T v equals each contact's relative tangential velocity computed point by point."""
    v = np.array(RIGID_MOTIONS[motion])
    _, Wt = jacobians(R, H, B)
    np.testing.assert_allclose(Wt.T @ v, _slips(None, v), atol=1e-15)


def test_hand_values_of_two_motions():
    """Rolling about B: A, C rise and sink by h omega, no slip; D meets the ball at (r+b) omega."""
    Wn, Wt = jacobians(R, H, B)
    omega = 2.0
    rolling = np.array([0.0, 0.0, -R * omega, 0.0, omega])
    np.testing.assert_allclose(Wn.T @ rolling, [-H * omega, 0.0, H * omega, -(R + B) * omega])
    np.testing.assert_allclose(Wt.T @ rolling, [0.0, 0.0, 0.0, H * omega], atol=1e-15)
    ball = np.array([1.0, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(Wn.T @ ball, [0.0, 0.0, 0.0, -1.0])


def test_scene_builds_the_derived_problem():
    problem = lawbench.CASES.get("disk_ball").build(b=B)
    Wn, Wt = jacobians(R, H, B)
    np.testing.assert_array_equal(problem.Wn, Wn)
    np.testing.assert_array_equal(problem.Wt, Wt)
    assert problem.M[4, 4] == pytest.approx(0.5 * (R**2 / 4 + (2 * H) ** 2 / 12))
    assert disk_inertia(1.0, 1.0, 0.0) == 0.25
    np.testing.assert_allclose(problem.un, [0.0, 0.0, 0.0, -1.0])


def test_impact_height_off_the_disk_is_refused():
    with pytest.raises(lawbench.InvalidProblem, match=r"b = 0\.06"):
        lawbench.CASES.get("disk_ball").build(b=0.06)


def test_disk_state_changes_sharply_with_b_and_lzb_never_gains_energy():
    """Zhang, Liu, Zhao, Brogliato (2013): the disk's post-impact state varies strongly with b.

    The rotation reverses across the centre and grows to about 3 rad/s at the rim, while the
    translation barely moves; the energetic law with friction never creates energy, and at the
    rim a floor point takes over as primary contact from the ball contact D.
    """
    omegas, primaries = [], []
    for b in (-0.05, -0.02, 0.0, 0.02, 0.05):
        outcome = lawbench.solve("lzb", "disk_ball", b=b)
        assert outcome.T_plus <= outcome.T_minus
        omegas.append(outcome.v_plus[4])
        primaries.append(outcome.diagnostics["primaries"])
    assert omegas[0] > 2.5 and omegas[-1] < -2.5 and abs(omegas[2]) < 1e-9
    assert np.sign(omegas[1]) != np.sign(omegas[3])
    assert primaries[2] == [3] and primaries[0][-1] == 0 and primaries[-1][-1] == 2
