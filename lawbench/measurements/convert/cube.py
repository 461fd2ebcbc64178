"""Convert the ContactNets cube tosses of DAIRLab/dair_pll into ``cube.npz``.

Run as ``python -m lawbench.measurements.convert.cube assets/contactnets_cube OUT_DIR``, the
folder holding ``0.pt`` to ``549.pt``. Each file is a PyTorch tensor (k, 13) of float64 saved
with ``torch.save``: a zip archive holding a pickle whose tensors point at raw storages. It is
read here without PyTorch: the unpickler rebuilds each tensor as a numpy array from its
storage, offset, shape and strides, and refuses any other object. Columns: quaternion
(w, x, y, z, body to world), centre position, body-axes angular velocity, world-axes linear
velocity. The table's height is the median over the tosses of the mean height of the four
lowest vertices at the last sample, when the cube rests.
"""

from __future__ import annotations

import collections
import io
import pickle
import sys
import zipfile
from collections import Counter
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from lawbench.measurements.consistency import residual, residuals
from lawbench.measurements.impacts import (
    MeasuredImpact,
    Processing,
    processing_array,
    training_mask,
)
from lawbench.measurements.sets.cube import INERTIA, MASS, NAME, VERTICES
from lawbench.measurements.tosses import Extraction, TossImpact, first_impact, vertex_problem

RULES = Extraction()
STORAGES = {"DoubleStorage": np.float64, "FloatStorage": np.float32}


class _TensorUnpickler(pickle.Unpickler):
    """Rebuilds the tensors of a ``torch.save`` archive as numpy arrays, and nothing else."""

    def __init__(self, archive: zipfile.ZipFile, prefix: str) -> None:
        super().__init__(io.BytesIO(archive.read(f"{prefix}/data.pkl")))
        self.archive = archive
        self.prefix = prefix

    def find_class(self, module: str, name: str) -> object:
        """Only a tensor's rebuilding function, its storage types and its metadata dict."""
        if (module, name) == ("torch._utils", "_rebuild_tensor_v2"):
            return _rebuild
        if module == "torch" and name in STORAGES:
            return STORAGES[name]
        if (module, name) == ("collections", "OrderedDict"):
            return collections.OrderedDict
        raise pickle.UnpicklingError(f"{module}.{name} is not a tensor's part")

    def persistent_load(self, pid: tuple) -> np.ndarray:
        """The raw storage ``pid`` names, read from the archive as a flat array."""
        _, dtype, key, _, _ = pid
        return np.frombuffer(self.archive.read(f"{self.prefix}/data/{key}"), dtype=dtype)


def _rebuild(storage: np.ndarray, offset: int, shape: tuple, strides: tuple, *_: object):
    """A tensor's values from its storage, as ``torch._utils._rebuild_tensor_v2`` reads them."""
    steps = [s * storage.itemsize for s in strides]
    return np.lib.stride_tricks.as_strided(storage[offset:], shape=shape, strides=steps).copy()


def read_tensor(path: str | Path) -> np.ndarray:
    """The tensor a ``torch.save`` file holds, as a numpy array."""
    with zipfile.ZipFile(path) as archive:
        pickled = next(n for n in archive.namelist() if n.endswith("/data.pkl"))
        return np.asarray(_TensorUnpickler(archive, pickled.rpartition("/")[0]).load())


def table_height(tosses: list[np.ndarray]) -> float:
    """The table's height: where the four lowest vertices rest at the tosses' ends."""
    rests = []
    for samples in tosses:
        rotation = Rotation.from_quat(samples[-1, [1, 2, 3, 0]])
        heights = np.sort(rotation.apply(VERTICES)[:, 2] + samples[-1, 6])
        rests.append(heights[:4].mean())
    return float(np.median(rests))


def _stored_spin_residual(samples: np.ndarray, found: TossImpact, world: bool) -> float:
    """The impact's residual with the angular velocities the raw file stores.

    Averaged over the fits' windows, read as they are (body axes, taken for world axes when
    ``world`` is False) or turned into the world frame sample by sample.
    """
    first, stop, start, end = found.facts["windows"]
    rotations = Rotation.from_quat(samples[:, [1, 2, 3, 0]])
    spins = rotations.apply(samples[:, 7:10]) if world else samples[:, 7:10]
    v_before = np.concatenate([found.v_before[:3], spins[first:stop].mean(axis=0)])
    v_after = np.concatenate([found.v_after[:3], spins[start:end].mean(axis=0)])
    offsets = found.rotation.apply(VERTICES[found.touching])
    problem = vertex_problem(MASS, INERTIA, offsets, v_before)
    return residual(MeasuredImpact(problem, v_after))


def _impacts(rows: dict[str, list]) -> list[MeasuredImpact]:
    """The measured impacts of the converted rows, as the set builds them."""
    impacts = []
    for quaternion, touching, v_before, v_after in zip(
        rows["quaternion"], rows["touching"], rows["v_before"], rows["v_after"], strict=True
    ):
        offsets = Rotation.from_quat(quaternion).apply(VERTICES[touching])
        impacts.append(MeasuredImpact(vertex_problem(MASS, INERTIA, offsets, v_before), v_after))
    return impacts


def convert(raw_dir: str | Path, out_dir: str | Path) -> Path:
    """Write ``OUT_DIR/cube.npz`` from the folder of tosses and return its path."""
    files = sorted(Path(raw_dir).glob("*.pt"), key=lambda p: int(p.stem))
    tosses = [read_tensor(path) for path in files]
    table = table_height(tosses)
    rows: dict[str, list] = collections.defaultdict(list)
    dropped: Counter[str] = Counter()
    # Residuals with the raw columns read as world axes (False) or turned into them (True).
    stored: dict[bool, list[float]] = {False: [], True: []}
    for path, samples in zip(files, tosses, strict=True):
        times = np.arange(len(samples)) / RULES.rate
        rotations = Rotation.from_quat(samples[:, [1, 2, 3, 0]])
        found = first_impact(times, samples[:, 4:7], rotations, VERTICES, table, RULES)
        if isinstance(found, str):
            dropped[found] += 1
            continue
        rows["toss"].append(int(path.stem))
        rows["quaternion"].append(found.rotation.as_quat())
        rows["position"].append(found.position)
        rows["v_before"].append(found.v_before)
        rows["v_after"].append(found.v_after)
        rows["touching"].append(found.touching)
        rows["fit_residuals"].append(
            found.facts["fit_residuals_m"] + found.facts["fit_residuals_rad"]
        )
        rows["compound"].append(found.facts["compound"])
        for world in stored:
            stored[world].append(_stored_spin_residual(samples, found, world))
    kept = len(rows["toss"])
    fitted = float(np.median(residuals(_impacts(rows))))
    processing = Processing(
        method=(
            f"first impact of each of {len(files)} tosses, free flight fitted on each side "
            f"({RULES}); table at z = {table:.4f} m"
        ),
        kept=kept,
        dropped=dict(sorted(dropped.items())),
        corrected=(
            "angular velocities fitted to the orientations in the world frame, not read from "
            "the raw columns, which hold them in body axes: median relative residual of the "
            f"impulse fit {np.median(stored[False]):.4f} with the raw columns read as world "
            f"axes, {np.median(stored[True]):.4f} turned into the world frame, "
            f"{fitted:.4f} with the fitted ones"
        ),
    )
    out = Path(out_dir) / f"{NAME}.npz"
    out.parent.mkdir(parents=True, exist_ok=True)
    arrays = {key: np.array(values) for key, values in rows.items()}
    np.savez_compressed(
        out, **arrays, train=training_mask(kept), processing=processing_array(processing)
    )
    return out


if __name__ == "__main__":
    print(convert(sys.argv[1], sys.argv[2]))
