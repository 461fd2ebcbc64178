"""Rigid-body engines as impact laws: PyBullet, MuJoCo and Drake, held to the checks of any law.

Each engine is a law (`lawbench.laws.engines._base.EngineLaw`) that builds the scene's declared
geometry in the engine, steps through the impact and returns an ordinary outcome; a scene that
declares no geometry is refused. The engines install with the optional extra ``engines``; an
engine that is not installed is listed among the laws that did not load, with the command that
installs it.
"""

import importlib

from lawbench.core.law import LAWS

# The engine modules, each named after the engine it drives, and the package it imports.
ENGINES = {"drake": "pydrake", "mujoco": "mujoco", "pybullet": "pybullet"}

for _engine, _package in ENGINES.items():
    try:
        importlib.import_module(f"{__name__}.{_engine}")
    except ModuleNotFoundError as missing:
        if missing.name != _package:
            raise
        LAWS.missing(_engine, f"missing dependency: {missing}")
