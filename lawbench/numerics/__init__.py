"""Numerics: the methods laws share, with no law or scene in them.

Owns the LCP and QP solvers and their enumerations, second-order cones (clarabel), Lemke's
method, the event integrator and its root finder, rigid-body kinematics and chain builders.
May import `lawbench.core` only.
"""
