"""The built-in measurement sets, one module each; importing this package registers them.

A set's module registers a `MeasurementSet` that reads its data file only on first use.
"""

from lawbench.measurements.sets import cube, ellipse, kharaz

__all__ = ["cube", "ellipse", "kharaz"]
