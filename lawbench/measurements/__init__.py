"""Measured impacts: sets of impacts observed in experiments, with their sources and data.

Owns `MeasuredImpact` (an impact problem at a measured configuration with the velocity
measured after it), `MeasurementSet` (a set's source, processing, impacts and its fixed
train/test split), the `MEASUREMENTS` registry (one module per built-in set in
``lawbench.measurements.sets``, plugins through the entry-point group
``lawbench.measurements``), the self-consistency check of measured impulses, the extraction
of impacts from tracked free-flight trajectories, a reader for a user's own CSV file of
measured impacts, and the scripts that convert the published raw files into the small files
shipped under ``data/``. It sits in the layer of the laws and scenes: it may import
`lawbench.core`, `lawbench.numerics`, `lawbench.files` and `lawbench.checks`, never a law, a
scene, the study engine or a view.
"""

from lawbench.measurements.consistency import Consistency, consistency, residuals
from lawbench.measurements.csvfile import read_csv
from lawbench.measurements.impacts import (
    MEASUREMENTS,
    MeasuredImpact,
    MeasurementSet,
    Processing,
    Source,
)

__all__ = [
    "MEASUREMENTS",
    "Consistency",
    "MeasuredImpact",
    "MeasurementSet",
    "Processing",
    "Source",
    "consistency",
    "read_csv",
    "residuals",
]
