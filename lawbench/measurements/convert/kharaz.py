"""Convert the digitized Kharaz points of MFiX's test DEM05 and Kratos' test 4 into ``kharaz.npz``.

Run as ``python -m lawbench.measurements.convert.kharaz write_usr0.f benchmark4_graph3.dat
OUT_DIR``, the first file being ``tests/dem/DEM05/write_usr0.f`` of MFiX, the second
``applications/DEMApplication/tests/DEM3D_chung_ooi_tests/test4_data/paper_data/
benchmark4_graph3.dat`` of Kratos. The Fortran file's three routines each declare the incidence
angles and the measured values of one quantity as array constants; they are read as written,
and the training split is drawn over the impacts the set rebuilds from them. The Kratos file
holds blocks of ``incidence, angle`` lines, each after a ``#`` title; its block ``#Experiment``
is the rebound angle of the contact point (the other two blocks are simulations), read as
written.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

from lawbench.measurements.impacts import Processing, processing_array, training_mask
from lawbench.measurements.sets.kharaz import NAME

# Each routine's (incidence array, value array) and the names the data file gives them.
ROUTINES = {
    "WRITE_EXP_COEFF": ("incidence_et", "et", "EXP_COEFF"),
    "WRITE_EXP_OMEGA": ("incidence_spin", "spin", "EXP_OMEGA"),
    "WRITE_EXP_ALPHA": ("incidence_angle", "rebound_angle", "EXP_ANGLE"),
}
# The title of the Kratos file's block of measured points.
CONTACT_BLOCK = "Experiment"


def _constant(body: str, name: str) -> np.ndarray:
    """The numbers of the array constant ``name(...) = (/ ... /)`` in a routine's body."""
    match = re.search(rf"{name}\([A-Z]+\)\s*=\s*&?\s*\(/(.*?)/\)", body, re.S)
    if match is None:
        raise ValueError(f"no array constant {name} in the routine")
    text = match.group(1).replace("&", " ")
    return np.array([float(x) for x in text.replace(",", " ").split()])


def read_raw(path: str | Path) -> dict[str, np.ndarray]:
    """The digitized points of each quantity, as the file declares them."""
    text = Path(path).read_text(encoding="utf-8")
    arrays = {}
    for routine, (incidence, value, constant) in ROUTINES.items():
        body = text.split(f"SUBROUTINE {routine}", 2)[1]
        arrays[incidence] = _constant(body, "IMPT_ANGLE")
        arrays[value] = _constant(body, constant)
    return arrays


def read_contact(path: str | Path) -> dict[str, np.ndarray]:
    """The contact point's rebound angles: the block ``#Experiment`` of the Kratos file."""
    blocks = Path(path).read_text(encoding="utf-8").split("#")
    rows = [block.splitlines()[1:] for block in blocks if block.startswith(CONTACT_BLOCK)]
    if len(rows) != 1:
        raise ValueError(f"expected one block #{CONTACT_BLOCK}, found {len(rows)}")
    points = np.array([[float(x) for x in line.split(",")] for line in rows[0] if line.strip()])
    return {"incidence_contact": points[:, 0], "contact_angle": points[:, 1]}


def convert(raw_path: str | Path, contact_path: str | Path, out_dir: str | Path) -> Path:
    """Write ``OUT_DIR/kharaz.npz`` from the two raw files and return its path."""
    arrays = read_raw(raw_path) | read_contact(contact_path)
    spin = arrays["incidence_spin"]
    inside = (arrays["incidence_et"] >= spin[0]) & (arrays["incidence_et"] <= spin[-1])
    processing = Processing(
        method=(
            "one impact at each incidence of the tangential restitution, the rebound spin "
            "interpolated linearly in incidence, the normal rebound with e_n = 0.98"
        ),
        kept=int(inside.sum()),
        dropped={"incidence outside the digitized spin points": int((~inside).sum())},
    )
    out = Path(out_dir) / f"{NAME}.npz"
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        out,
        **arrays,
        train=training_mask(int(inside.sum())),
        processing=processing_array(processing),
    )
    return out


if __name__ == "__main__":
    print(convert(sys.argv[1], sys.argv[2], sys.argv[3]))
