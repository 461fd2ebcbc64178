"""Rigid-body engines as impact laws: PyBullet and MuJoCo, held to the same checks as any law.

Each engine is a law (`lawbench.laws.engines._base.EngineLaw`) that builds the scene's declared
geometry in the engine, steps through the impact and returns an ordinary outcome; a scene that
declares no geometry is refused. The engines install with the optional extra ``engines``; an
engine that is not installed is listed among the laws that did not load, with the command that
installs it.
"""

import importlib

from lawbench.core.law import LAWS

# The engine modules, each named after the package it drives.
ENGINES = ("mujoco", "pybullet")

for _engine in ENGINES:
    try:
        importlib.import_module(f"{__name__}.{_engine}")
    except ModuleNotFoundError as missing:
        if missing.name != _engine:
            raise
        LAWS.missing(_engine, f"missing dependency: {missing}")
