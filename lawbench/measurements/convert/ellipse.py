"""Convert the ellipse bounces of DAIRLab/ImpactModeling into ``ellipse.npz``.

Run as ``python -m lawbench.measurements.convert.ellipse ellipse_uniform.mat OUT_DIR``. The
MATLAB file holds a struct array ``bounce_array`` of 2000 bounces: ``states`` (x, y, theta,
vx, vy, omega before, then after), the Jacobian rows ``n`` and ``d``, and six quality flags.
Written: the velocities, the flags, and the angle of each impact, the one at which the
ellipse's lowest point is the rows' contact point (`contact_angle`); the rows themselves are
that point's (`lawbench.measurements.sets.ellipse.geometry`). The relative residual of the
impulse fit with the rows read counterclockwise and clockwise, and the distances behind the
choice of the angle, are measured here and stored in the processing record.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import scipy.optimize

from lawbench.measurements.consistency import consistency
from lawbench.measurements.impacts import (
    MeasuredImpact,
    Processing,
    planar_problem,
    processing_array,
    training_mask,
)
from lawbench.measurements.sets.ellipse import FLAGS, NAME, lowest_point, mass_matrix

# The angles searched for each contact point: a grid over half a turn (the ellipse's symmetry),
# then the best one refined.
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 20001)


def read_raw(path: str | Path) -> dict[str, np.ndarray]:
    """The bounces of the raw MATLAB file as arrays, one row per bounce, as recorded."""
    import scipy.io

    bounces = scipy.io.loadmat(str(path))["bounce_array"].ravel()
    states = np.array([b["states"].ravel() for b in bounces], dtype=float)
    return {
        "angle_before": states[:, 2],
        "v_before": states[:, 3:6],
        "v_after": states[:, 9:12],
        "normal": np.array([b["n"].ravel() for b in bounces], dtype=float),
        "tangent": np.array([b["d"].ravel() for b in bounces], dtype=float),
        "flags": np.array([b["flags"].ravel() for b in bounces], dtype=bool),
    }


def _lowest(angles: np.ndarray) -> np.ndarray:
    """`lowest_point` at each of ``angles`` (k, 2)."""
    return np.array([lowest_point(float(t)) for t in np.ravel(angles)])


def contact_angle(point: np.ndarray) -> tuple[float, float]:
    """The angle (rad, clockwise, in [-pi/2, pi/2)) whose lowest point is nearest ``point``.

    ``point`` is the contact point from the centre, ``(x, -h)``: the nearest point of `ANGLES`,
    refined by least squares on the two coordinates. Returns the angle and the distance of its
    lowest point from ``point`` (m).
    """
    start = float(ANGLES[np.argmin(np.hypot(*(_GRID - point).T))])
    found = scipy.optimize.least_squares(
        lambda t: np.array(lowest_point(float(t[0]))) - point,
        [start],
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    # Half a turn gives the same ellipse: the angle back within [-pi/2, pi/2).
    angle = (float(found.x[0]) + np.pi / 2) % np.pi - np.pi / 2
    return angle, float(np.hypot(*found.fun))


_GRID = _lowest(ANGLES)


def _median_residual(raw: dict[str, np.ndarray], tangent: np.ndarray, rows: np.ndarray) -> float:
    """The median relative residual of the kept bounces with tangent rows ``tangent``."""
    M = mass_matrix()
    impacts = [
        MeasuredImpact(
            planar_problem(M, raw["normal"][i], tangent[i], raw["v_before"][i]), raw["v_after"][i]
        )
        for i in rows
    ]
    return consistency(impacts).median


def _angles(raw: dict[str, np.ndarray], rows: np.ndarray) -> tuple[np.ndarray, str]:
    """The contact angle of every bounce, and what it is, measured over the kept ``rows``.

    The rows' contact point read clockwise is ``(-n_3, -d_3)`` (`lawbench.measurements.sets
    .ellipse`).
    """
    points = np.column_stack([-raw["normal"][:, 2], -raw["tangent"][:, 2]])
    found = np.array([contact_angle(p) for p in points])
    angles, off = found[:, 0], found[:, 1]
    recorded = np.hypot(*(_lowest(raw["angle_before"]) - points).T)
    turn = (angles - raw["angle_before"] + np.pi / 2) % np.pi - np.pi / 2
    spin = raw["v_before"][:, 2]
    um, mm, deg = 1e6, 1e3, 180 / np.pi
    text = (
        "the contact is the ellipse's lowest point at the angle whose lowest point is the "
        f"source's contact point (that point lies {um * np.median(off[rows]):.4f} um median, "
        f"{um * off[rows].max():.3f} um at most from it, over the kept bounces); the recorded "
        f"angle before the impact puts the lowest point {mm * np.median(recorded[rows]):.3f} mm "
        f"median, {mm * recorded[rows].max():.3f} mm at most from it, the angles differing by "
        f"{deg * np.median(np.abs(turn[rows])):.2f} degrees median, "
        f"{deg * np.abs(turn[rows]).max():.2f} at most (correlation with the spin before "
        f"{np.corrcoef(turn[rows], spin[rows])[0, 1]:.3f}; the source's angle the recorded "
        f"one minus {-mm * np.median(turn[rows] / spin[rows]):.2f} ms times the spin, median)"
    )
    return angles, text


def convert(raw_path: str | Path, out_dir: str | Path) -> Path:
    """Write ``OUT_DIR/ellipse.npz`` from the raw file and return its path."""
    raw = read_raw(raw_path)
    clockwise = raw["tangent"] * np.array([1.0, 1.0, -1.0])
    kept = ~raw["flags"].any(axis=1)
    rows = np.flatnonzero(kept)
    before = _median_residual(raw, raw["tangent"], rows)
    after = _median_residual(raw, clockwise, rows)
    angles, placed = _angles(raw, rows)
    train = np.zeros(kept.size, dtype=bool)
    train[rows] = training_mask(rows.size)
    flagged = ", ".join(f"{name} {int(raw['flags'][:, j].sum())}" for j, name in enumerate(FLAGS))
    processing = Processing(
        method=(
            "bounces of the raw file without any quality flag, velocities as recorded "
            f"(bounces with each flag set, a bounce may have several: {flagged}); {placed}"
        ),
        kept=int(rows.size),
        dropped={"flagged by the source": int((~kept).sum())},
        corrected=(
            "angle and spin read clockwise, which reverses the angular entry of the tangent "
            f"row: median relative residual of the impulse fit {before:.4f} with the raw sign, "
            f"{after:.4f} reversed"
        ),
    )
    out = Path(out_dir) / f"{NAME}.npz"
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        out,
        v_before=raw["v_before"],
        v_after=raw["v_after"],
        angle=angles,
        flags=raw["flags"],
        train=train,
        processing=processing_array(processing),
    )
    return out


if __name__ == "__main__":
    print(convert(sys.argv[1], sys.argv[2]))
