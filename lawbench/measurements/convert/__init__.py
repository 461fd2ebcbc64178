"""Conversions of the published raw files into the small files the built-in sets ship.

Each module runs as ``python -m lawbench.measurements.convert.<set> RAW OUT_DIR`` and writes
``OUT_DIR/<set>.npz``; the set's README.md under ``lawbench/measurements/data`` gives the exact
command, the source and what was dropped or corrected.
"""
