"""The regions where the engines' findings hold, and the findings the engines share.

Each region reads a trial of an engine law (`lawbench.laws.engines._base.EngineLaw`): its
problem, its geometry, and the diagnostics the stepping rule records (the impact's time, the
step, the engine's own velocity after the impact).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.checks.regions import option
from lawbench.core.outcome import gap_rates
from lawbench.core.verdicts import Claim, Region
from lawbench.laws.engines._base import APPROACH, OVERLAP

# A body that moves by more than this fraction of its largest size during the impact leaves the
# configuration the problem is frozen at.
MOVED = 0.5


def _moved(trial: Any) -> bool:
    """Whether a body's centre moves by more than `MOVED` of its largest size in the impact.

    At the faster of its speeds before and after, over the engine's impact time.
    """
    geometry = getattr(trial.problem, "geometry", None)
    seconds = trial.outcome.diagnostics.get("impact_time")
    if geometry is None or seconds is None:
        return False
    speeds = [
        np.linalg.norm(geometry.body_velocities(v)[:, :3], axis=1)
        for v in (trial.problem.v, trial.outcome.v_plus)
    ]
    fastest = np.maximum(*speeds)
    return any(
        fastest[k] * seconds > MOVED * max(body.size)
        for k, body in enumerate(geometry.bodies)
        if body.size
    )


moving_impact = Region(
    f"a body moves by more than {MOVED:g} of its size during the engine's impact", _moved
)


def _turned(trial: Any) -> bool:
    """Whether the bodies' turning in the engine's impact accounts for every approach after it.

    A contact's gap rate after the impact is read along its lever arm r at the configuration the
    problem is frozen at, while the engine ends the impact at the configuration its bodies have
    reached: a body that turns by ``theta = |omega| T`` in the impact's time T has carried its
    contact point's arm through theta, which moves the point's velocity ``omega x r`` by up to
    ``|omega| r theta``. The region holds where some closed contact approaches after the impact,
    and each such contact's approach is within that sum over its two bodies (``|omega|`` the
    faster of before and after), plus the approach the stepping rule counts as rest
    (`APPROACH`).
    """
    problem, outcome = trial.problem, trial.outcome
    geometry = getattr(problem, "geometry", None)
    seconds = outcome.diagnostics.get("impact_time")
    if geometry is None or seconds is None:
        return False
    spins = [geometry.body_velocities(v)[:, 3:] for v in (problem.v, outcome.v_plus)]
    spin = np.maximum(*(np.linalg.norm(w, axis=1) for w in spins))
    closed = np.flatnonzero(problem.closed)
    after = gap_rates(problem, outcome.v_plus)
    rest = APPROACH * float(-np.min(problem.un, initial=0.0))
    approaching = [j for j in closed if after[j] < 0.0]
    if not approaching:
        return False
    for j in approaching:
        pair = geometry.pairs[j]
        swing = 0.0
        for name in (pair.a, pair.b):
            k = geometry.index[name]
            arm = float(np.linalg.norm(np.subtract(pair.point, geometry.bodies[k].position)))
            swing += spin[k] ** 2 * seconds * arm
        if -after[j] > swing + rest:
            return False
    return True


turning_impact = Region(
    "a closed contact left approaching by no more than its bodies' turning in the engine's "
    "impact moves its point's velocity (|omega|^2 r T)",
    _turned,
)


def _misreported(trial: Any) -> bool:
    """Whether a closed contact approaches after the impact in the outcome but not in the engine.

    The outcome's velocity is the pre-impact one plus the impulses of the forces the engine
    reports; the engine's own (``engine_v_plus``) is its state after its steps. Where the second
    leaves every closed contact at rest or separating (within `APPROACH` of the fastest
    approach) and the first does not, the forces the engine reports are not all it applied.
    """
    problem, outcome = trial.problem, trial.outcome
    engine = outcome.diagnostics.get("engine_v_plus")
    closed = problem.closed
    if engine is None or not closed.any():
        return False
    rest = APPROACH * float(-np.min(problem.un, initial=0.0))
    own = gap_rates(problem, np.asarray(engine))[closed]
    return bool(gap_rates(problem, outcome.v_plus)[closed].min() < 0.0 and own.min() >= -rest)


misreported_impulse = Region(
    "a closed contact approaches after the impact by the forces the engine reports, not by its "
    "own velocity",
    _misreported,
)


def slopped(slop: float, unsolved: float) -> Region:
    """Closed contacts left approaching within an engine's contact slop over its step.

    An engine with a contact slop asks a contact only ``d + slop >= 0`` after a step, d its
    distance, so a closed contact may go on approaching at up to ``slop / dt``; a solver that
    stops early leaves up to ``unsolved`` of the contact speed (the largest pre-impact normal or
    tangential contact velocity, the admissibility check's scale) beside it.
    """

    def contains(trial: Any) -> bool:
        problem, dt = trial.problem, trial.outcome.diagnostics.get("dt")
        closed = problem.closed
        if dt is None or not closed.any():
            return False
        speed = float(np.abs(np.concatenate([problem.un[closed], problem.ut])).max())
        after = float(gap_rates(problem, trial.outcome.v_plus)[closed].min())
        return after < 0.0 and -after <= slop / dt + unsolved * speed

    return Region(
        f"a closed contact left approaching slower than the engine's contact slop over the step "
        f"({slop:g} m / dt)",
        contains,
    )


def _overlapped(trial: Any) -> bool:
    """Whether the fastest approach covers less than the starting overlap within a step."""
    geometry = getattr(trial.problem, "geometry", None)
    dt = trial.outcome.diagnostics.get("dt")
    if geometry is None or dt is None:
        return False
    overlap = OVERLAP * min(min(body.size) for body in geometry.bodies if body.size)
    return float(-np.min(trial.problem.un, initial=0.0)) * dt < overlap


slower_than_overlap = Region(
    "the fastest approach covers less than the closed contacts' starting overlap within a step",
    _overlapped,
)


def overlap_given_back(source: str, example: str) -> Claim:
    """An engine gives back the energy of the starting overlap (`OVERLAP`) of a closed contact.

    ``example`` is the measured instance, in words.
    """
    return Claim(
        "energy_gain",
        slower_than_overlap,
        f"{source}; lawbench.laws.engines._base, the stepping rule (OVERLAP)",
        "a closed contact starts 1e-9 of the smallest body into its other body, so that the "
        "engine finds it, and the engine's contact gives back the energy of that overlap as it "
        "opens: where the approach covers less than the overlap within a step (a grazing "
        f"approach), that energy is of the order of the impact's or larger ({example})",
    )


def normal_turned(source: str, example: str) -> Claim:
    """At its defaults an engine's soft impact outlasts the configuration the problem froze.

    The friction-cone finding of `moving_impact`; ``example`` is the measured instance, in words.
    """
    return Claim(
        "friction_cone",
        option("settings", "default") & moving_impact,
        source,
        "at its defaults the impact lasts long enough for the contact's normal to turn with "
        "the bodies: the force along the normal the engine meets has a component along the "
        f"problem's frozen tangent, outside the frozen cone ({example})",
    )


elastic_contact = Region(
    "some closed contact is elastic (e = 1)",
    lambda trial: bool((trial.problem.restitution("kinematic")[trial.problem.closed] == 1).any()),
)
