"""Convert the ellipse bounces of DAIRLab/ImpactModeling into ``ellipse.npz``.

Run as ``python -m lawbench.measurements.convert.ellipse ellipse_uniform.mat OUT_DIR``. The
MATLAB file holds a struct array ``bounce_array`` of 2000 bounces: ``states`` (x, y, theta,
vx, vy, omega before, then after), the Jacobian rows ``n`` and ``d``, and six quality flags.
Only the velocities, the rows and the flags are written. The tangent row's angular entry is
reversed (see `lawbench.measurements.sets.ellipse` for why); the relative residual of the
impulse fit before and after that correction is measured here and stored in the processing
record.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from lawbench.measurements.consistency import consistency
from lawbench.measurements.impacts import (
    MeasuredImpact,
    Processing,
    planar_problem,
    processing_array,
    training_mask,
)
from lawbench.measurements.sets.ellipse import FLAGS, NAME, mass_matrix


def read_raw(path: str | Path) -> dict[str, np.ndarray]:
    """The bounces of the raw MATLAB file as arrays, one row per bounce, as recorded."""
    import scipy.io

    bounces = scipy.io.loadmat(str(path))["bounce_array"].ravel()
    states = np.array([b["states"].ravel() for b in bounces], dtype=float)
    return {
        "v_before": states[:, 3:6],
        "v_after": states[:, 9:12],
        "normal": np.array([b["n"].ravel() for b in bounces], dtype=float),
        "tangent": np.array([b["d"].ravel() for b in bounces], dtype=float),
        "flags": np.array([b["flags"].ravel() for b in bounces], dtype=bool),
    }


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


def convert(raw_path: str | Path, out_dir: str | Path) -> Path:
    """Write ``OUT_DIR/ellipse.npz`` from the raw file and return its path."""
    raw = read_raw(raw_path)
    corrected = raw["tangent"] * np.array([1.0, 1.0, -1.0])
    kept = ~raw["flags"].any(axis=1)
    rows = np.flatnonzero(kept)
    before = _median_residual(raw, raw["tangent"], rows)
    after = _median_residual(raw, corrected, rows)
    train = np.zeros(kept.size, dtype=bool)
    train[rows] = training_mask(rows.size)
    flagged = ", ".join(f"{name} {int(raw['flags'][:, j].sum())}" for j, name in enumerate(FLAGS))
    processing = Processing(
        method=(
            "bounces of the raw file without any quality flag, velocities as recorded "
            f"(bounces with each flag set, a bounce may have several: {flagged})"
        ),
        kept=int(rows.size),
        dropped={"flagged by the source": int((~kept).sum())},
        corrected=(
            "angular entry of the tangent row reversed: median relative residual of the "
            f"impulse fit {before:.4f} with the raw sign, {after:.4f} reversed"
        ),
    )
    out = Path(out_dir) / f"{NAME}.npz"
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        out,
        v_before=raw["v_before"],
        v_after=raw["v_after"],
        normal=raw["normal"],
        tangent=corrected,
        flags=raw["flags"],
        train=train,
        processing=processing_array(processing),
    )
    return out


if __name__ == "__main__":
    print(convert(sys.argv[1], sys.argv[2]))
