"""Drake as an impact law: the scene built as a MultibodyPlant and stepped through the impact.

Source: Drake 1.51 (R. Tedrake and the Drake development team, https://drake.mit.edu; pip
package ``drake``): MultibodyPlant's documentation, "Contact modeling" (point contact, the
"Modeling Dissipation" section for Hunt and Crossley's law, the lagged, similar, TAMSI and SAP
discrete approximations, output port sampling), MultibodyPlantConfig, DefaultProximityProperties
(point_stiffness 1e6 N/m, hunt_crossley_dissipation 50 s/m, friction 0.5 by default),
CoulombFriction (two geometries' coefficients combined as ``2 mu1 mu2 / (mu1 + mu2)``) and
QueryObject (signed distances: a half space with a sphere only). Drake has no restitution
coefficient: a compliant point contact pushes with ``f = k x (1 + d x')`` (x the penetration,
positive force only), Hunt and Crossley's law (J. Appl. Mech. 42, 1975) with a linear spring;
two geometries' stiffnesses combine in series, ``k = k1 k2 / (k1 + k2)``, and their
dissipations weighted by the other's stiffness, ``d = (k2 d1 + k1 d2) / (k1 + k2)``. Friction
is Coulomb's, regularized below the stiction tolerance in continuous time.

Conventions: the common stepping rule of the engine laws (`lawbench.laws.engines._base`). Bodies:
a rigid body per moving body, its frame at the centre of mass along the principal axes; a free
joint is Drake's floating body, a planar joint, a hinge and a slide Drake's PlanarJoint,
RevoluteJoint and PrismaticJoint between a frame of the world and one of the body, both at the
body's pose (a hinge's at its anchor) with z along the joint's axis; a fixed body's geometry
is the world body's (plane: HalfSpace, its normal the frame's z). Only the declared pairs
collide (every other two geometries are filtered out). Drake reports each point pair's force on
its second geometry (PointPairContactInfo.contact_force, world frame). Gravity is off. Drake
writes a warning for every half space, about deformable contact; it is filtered out of the
``drake`` logger.

Settings (option ``settings``):

- ``default``, what a user gets: MultibodyPlantConfig() (discrete, time_step 1e-3 s, contact
  model hydroelastic with fallback, here point contact since no geometry has hydroelastic
  properties, the lagged approximation, stiction tolerance 1e-4 m/s), one geometry per body
  with DefaultProximityProperties' stiffness and dissipation and its pairs' mean mu as its
  friction. The contact results are sampled: after a step, which ends at the time of one
  discrete update, they report the forces of that update. e has no effect: struck at v0, a
  contact of dissipation d leaves at about ``1 / (d v0)``, with Drake's d = 50 s/m 0.010 of
  the approach at 2 m/s and 0.005 at 3.9 m/s (measured on the sphere striking a wall head-on,
  for any e). The elastic three-ball chain ends at (0.314, 0.334, 0.353), a third of its energy
  (Moreau's (-1/3, 2/3, 2/3)). Point contact gives a box lying flat on a plane one contact
  point (the rocking block's landing finds one point on its face, and its force maps to one
  corner: v+ (-0.370, 0.202, 0.542) where Moreau's law gives (-0.350, 0.175, 0.700), 10 % of
  its motion off the problem's directions). The lagged approximation bounds a step's friction
  with the normal force of the step before, so the impulse leaves the friction cone where the
  normal force falls: 2.6 mu Pn on the slipping rocking block (the similar approximation keeps
  it within mu Pn).
- ``tuned``, as rigid and faithful to e and mu as Drake allows: continuous time (time_step 0)
  with Runge-Kutta 3 at target accuracy `ACCURACY` and steps of at most dt, point contact, one
  geometry per pair on each of its bodies (a box touching through a small sphere at the pair's
  point, `corner`), stiction tolerance `STICTION` times the largest pre-impact speed. Drake's
  point contact is linear, so each contact is a linear spring: its stiffness the contact's
  ``stiffness`` in the scene's ratios, scaled so that the stiffest contact (largest stiffness
  over effective mass) oscillates with the period `STEPS_PER_CONTACT` dt, dt 1e-5 s. With
  exponent 1 that is the scene's spring network: the outcome of linear springs without other
  forces does not depend on a factor common to their stiffnesses (it scales time and
  indentation alone), and the scene's own stiffness (1 N/m on the chains) would push the
  balls through each other. A Hertz contact (exponent 1.5) is built linear too. The
  dissipation is ``d = u / v0`` with v0 the scene's largest pre-impact approach speed and u
  the root of ``u - ln(1 + u) = -e u - ln(1 - e u)`` (`released_restitution`): exact for one
  contact struck at v0, the first integral of Drake's force law; Hunt and Crossley's
  ``1 - e = 2 d v0 / 3`` is its limit at e near 1 only, and a contact that a wave closes at
  another speed leaves at another e (Drake's e depends on the approach speed). An e below
  `LEAST_RESTITUTION` takes that one's dissipation. Each pair's impulse is integrated with the
  plant (its continuous state is the contact forces' integral), so a step's impulse is exact
  to the integrator's accuracy, not a sample.

Measured (this module's settings): tuned, the elastic three-ball chain of linear springs of
equal stiffness (exponent 1) ends at (-0.1303, 0.1502, 0.9800), the compliant law's
linear-spring answer to 1.4e-6 of the largest velocity; the rocking block is 7e-4 from
Moreau's law (its corners leave at 1e-3 of their approach, `LEAST_RESTITUTION`), the elastic
frictionless block 1e-5; the sphere on a wall 2e-4 from it, 3e-3 without spin (the sphere
rolls after the impact, and the regularized friction lets it creep). Struck head-on, a sphere
leaves at e to 1e-4 for e = 0.3, 0.5, 0.8 and 1. Against the compliant ground truth (the
``yardstick`` check, kinetic metric; the study ``drake_yardstick``): 2e-5 at most on the chains
with linear springs, 6e-4 with tangential springs 100 times stiffer than the normal ones;
at the scenes' defaults the Hertz contacts, the damping rule and the tangential springs each
make a difference, the findings on ``yardstick`` below. Cost per impact: some 15 ms at the defaults
(a third building the plant, the rest stepping it), 50 to 400 ms tuned.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.optimize

from lawbench.checks.regions import (
    damped_contacts,
    frictional,
    nonlinear_springs,
    oblique_contacts,
    option,
)
from lawbench.core.law import LAWS
from lawbench.core.problem import ImpactProblem
from lawbench.core.verdicts import Claim, Region
from lawbench.laws.engines._base import (
    LEAST_RESTITUTION,
    EngineLaw,
    Scene,
    Start,
    damping_for,
    engine_options,
    require,
)
from lawbench.laws.engines._drake_scene import DrakeScene, Tuning
from lawbench.laws.engines._regions import (
    elastic_contact,
    misreported_impulse,
    moving_impact,
    normal_turned,
    overlap_given_back,
    slower_than_overlap,
    turning_impact,
)

require("pydrake")

_DOCS = "Drake documentation, https://drake.mit.edu (MultibodyPlant: contact modeling)"
# Steps of dt over one period of the stiffest tuned contact.
STEPS_PER_CONTACT = 50
# The tuned integrator's target accuracy (Drake's relative error measure of the state).
ACCURACY = 1e-6
# The tuned stiction tolerance over the largest pre-impact speed: the slip speed below which
# Drake's regularized friction is proportional to the slip (Drake's default is 1e-4 m/s).
STICTION = 1e-3


def _box_on_plane(trial: Any) -> bool:
    """Whether a box of the trial's scene touches a plane at several declared points."""
    geometry = trial.problem.geometry
    if geometry is None:
        return False
    shapes = {body.name: body.shape for body in geometry.bodies}
    touching = [
        frozenset((pair.a, pair.b))
        for pair in geometry.pairs
        if {shapes[pair.a], shapes[pair.b]} == {"box", "plane"}
    ]
    return len(touching) > len(set(touching))


box_on_plane = Region("a box touches a plane at several points", _box_on_plane)


def released_restitution(u: float) -> float:
    """The restitution of a linear Hunt-Crossley contact whose dissipation times speed is ``u``.

    The contact ``m x'' = -k x (1 + d x')`` struck at ``x' = v0``, ``u = d v0``: its first
    integral ``v dv / (1 + d v) = -(k / m) x dx`` from ``x = 0`` back to ``x = 0`` gives the
    exit speed ``e v0`` as the root of ``u - ln(1 + u) = -e u - ln(1 - e u)`` with ``e u < 1``
    (the force stays positive until the gap reopens); neither k nor m enter. Written
    ``e u = 1 - exp(-s)``, it is ``s + expm1(-s) = u - ln(1 + u)``, whose left side grows with
    s: solved in s, without the cancellations of ``1 - e u`` near 0 (large u, where e tends to
    ``1 / u``) or of e near 1 (small u, where ``e = 1 - 2 u / 3 + O(u^2)``).
    """
    if u <= 0.0:
        return 1.0
    h = u - math.log1p(u)
    s = scipy.optimize.brentq(lambda s: s + math.expm1(-s) - h, 0.0, h + 1.0, xtol=1e-300)
    return -math.expm1(-s) / u


def dissipation_speed(e: float) -> float:
    """``u = d v0`` whose linear Hunt-Crossley contact leaves at restitution ``e``."""
    return damping_for(e, released_restitution, 2.0 / max(e, LEAST_RESTITUTION))


_TUNED = option("settings", "tuned")
_YARDSTICK_SOURCE = (
    f"{_DOCS}: point contact, Hunt and Crossley's dissipation, friction regularized below the "
    "stiction tolerance; Hunt and Crossley 1975; Flores et al. 2011; Jia 2013; Mindlin 1949"
)
# Drake tuned against the compliant ground truth (the ``yardstick`` check, kinetic metric):
# where the two differ, the physics each models, measured by matching it.
_YARDSTICK = (
    Claim(
        "yardstick",
        _TUNED & frictional,
        _YARDSTICK_SOURCE,
        "the ground truth gives each frictional contact a tangential spring (the normal "
        "stiffness over Jia's eta0^2, Mindlin's 17/14 unless the scene sets it) in series with "
        "a Coulomb slider, so a contact stores tangential energy, sticks and slips back within "
        "the impact; Drake's friction is rigid Coulomb, regularized below its stiction "
        "tolerance: the rocking block differs by 0.21 (its landing corner's tangential spring "
        "gives omega+/omega- 0.44 where Drake, as Housner's closed form, the scene's truth "
        "there, gives 0.70), the bouncing ball by 0.050, the sphere on a wall by 0.015; with "
        "tangential springs 100 times stiffer 6e-4 on the block, and on the ball and the "
        "sphere what remains (0.028, 0.0076) is the damped contact's restitution (the finding "
        "on 0 < e < 1), 6e-4 and 4e-4 at e = 1",
    ),
    Claim(
        "yardstick",
        _TUNED & nonlinear_springs,
        _YARDSTICK_SOURCE,
        "Drake's point contact is linear in the penetration, and the chains' Hertz contacts "
        "(exponent 1.5) are built as linear springs in the scene's stiffness ratios: the wave "
        "through the chain spreads the energy as linear springs do (three-ball chain 0.096, "
        "two balls and a wall 0.040, five-ball chain 0.19, bead column 0.16); with the scene's "
        "contacts given exponent 1 the two agree to 2e-5 (the stiffnesses in series, the common "
        "factor of Drake's stiffer springs scales time and indentation alone, its damping too)",
    ),
    Claim(
        "yardstick",
        _TUNED & damped_contacts,
        _YARDSTICK_SOURCE,
        "both damp a contact by Hunt and Crossley's law with one coefficient from e at the "
        "scene's largest approach speed, but Drake tuned takes the coefficient that leaves "
        "exactly at e (`released_restitution`, the force law's first integral, whatever the "
        "exponent) where the ground truth takes Flores' rule, which leaves at 0.947, 0.841, "
        "0.789 and 0.470 for e = 0.95, 0.85, 0.8 and 0.5: ping-pong differs by 0.0064, and "
        "by 2e-6 with elastic contacts",
    ),
)


class Drake(EngineLaw):
    """Drake: the scene stepped as a MultibodyPlant with Drake's compliant point contact."""

    name = "drake"
    summary = (
        "Drake: the scene's bodies stepped through the impact as a MultibodyPlant, at its "
        "defaults (discrete) or tuned (continuous, Hunt-Crossley from e)"
    )
    source = f"Drake 1.51 (Tedrake and the Drake development team); {_DOCS}"
    steps = {"default": 1e-3, "tuned": 1e-5}
    settings_words = {
        "default": "Drake at its defaults (discrete, lagged point contact; e has no effect)",
        "tuned": "Drake tuned (continuous, linear Hunt-Crossley point contact from e)",
    }
    separating_rule = (
        "Drake's own: a contact acts while its bodies overlap, so a separating contact takes "
        "a force only where its neighbours push it back into overlap"
    )
    options = engine_options(
        steps,
        "MultibodyPlantConfig(): time_step 1e-3 s, point contact (hydroelastic with point "
        "fallback), the lagged approximation, point stiffness 1e6 N/m and Hunt-Crossley "
        "dissipation 50 s/m per geometry, each geometry's friction its body's mu; e has no "
        "effect",
        f"continuous time (time_step 0), Runge-Kutta 3 to accuracy {ACCURACY:g}, point "
        "contact, one geometry per pair (a box touching through small spheres), linear springs "
        "of the scene's stiffness ratios, scaled so that the stiffest contact's period is "
        f"{STEPS_PER_CONTACT} dt, Hunt-Crossley dissipation from e at the largest approach "
        f"speed, stiction tolerance {STICTION:g} m/s",
    )
    findings = (
        overlap_given_back(
            f"{_DOCS}: DefaultProximityProperties (point_stiffness 1e6 N/m)",
            "the lamina approaching at 1e-8 m/s gains 1.1e-15 J where it brought 5e-17 J",
        ),
        Claim(
            "dispersion",
            option("settings", "tuned") & nonlinear_springs,
            f"{_DOCS}: point contact, Hunt and Crossley's law; Brogliato 2010, linear-spring "
            "limits of the three-ball chain",
            "Drake's point contact is a linear spring: tuned, a scene's Hertz contacts are built "
            "linear in their stiffness ratios, and the energy spreads as linear springs spread "
            "it (the elastic three-ball chain ends at (-0.130, 0.150, 0.980), Hertz's springs "
            "at (-0.071, 0.076, 0.995))",
        ),
        Claim(
            "dispersion",
            option("settings", "default"),
            f"{_DOCS}: DefaultProximityProperties; Brogliato 2010, energy dispersion in chains",
            "at its defaults every geometry has Drake's point stiffness (1e6 N/m) and "
            "dissipation (50 s/m), whatever the scene's stiffnesses: the energy spreads over the "
            "bodies as those decide",
            (("three_ball_chain", "default"),),
        ),
        Claim(
            "continuity",
            oblique_contacts,
            f"{_DOCS}; Paoli 2005; Brogliato 2010, kinetic angle and continuity",
            "Drake's contacts are far stiffer than the scene's (1e6 N/m at the defaults; tuned, "
            f"a period of {STEPS_PER_CONTACT} dt), and at the defaults a contact acts from the "
            "step that finds its bodies overlapping: a gap that vanishes against the scene's "
            "indentation does not against Drake's, and where the contacts share the impact (a "
            "kinetic angle other than 90 degrees) the outcome moves with it as a rigid law's "
            "does (0.5 % on the five-ball chain at the defaults, 0.6 % on the three-ball chain "
            "tuned)",
            (("ball_chain", "default"),),
        ),
        Claim(
            "energy_kept",
            option("settings", "default"),
            f"{_DOCS}: DefaultProximityProperties (hunt_crossley_dissipation 50 s/m)",
            "Drake has no restitution coefficient: at its defaults every contact has the "
            "dissipation 50 s/m whatever e, and leaves at about 1 / (50 s/m v0) of its approach "
            "v0: the elastic three-ball chain keeps a third of its energy, v+ = (0.314, 0.334, "
            "0.353)",
            (("three_ball_chain", "default"),),
        ),
        Claim(
            "energy_kept",
            option("settings", "tuned") & elastic_contact,
            f"{_DOCS}: Simulator, Runge-Kutta 3 with error control",
            "tuned, an elastic contact is an undamped spring integrated by Runge-Kutta 3 to the "
            f"target accuracy {ACCURACY:g}: the bodies leave with up to 1e-5 of the energy less "
            "than they brought",
        ),
        Claim(
            "friction_cone",
            option("settings", "default") & frictional,
            f"{_DOCS}: the lagged discrete approximation",
            "the default lagged approximation bounds a step's friction by the normal force of "
            "the step before, so where the normal force falls the impulse leaves the cone: "
            "2.6 mu Pn on the slipping rocking block (the similar approximation keeps mu Pn)",
            (("rocking_block", "slipping"),),
        ),
        Claim(
            "admissible",
            option("settings", "default") & box_on_plane,
            f"{_DOCS}: point contact (one point per pair of geometries)",
            "point contact gives a box lying on a plane one contact point, found where the box "
            "overlaps most and mapped to one declared corner: the other corner can be left "
            "approaching (the wide rocking block, un+ = -1.06 m/s)",
            (("rocking_block", "wide block"),),
        ),
        Claim(
            "energy_gain",
            option("settings", "default") & box_on_plane,
            f"{_DOCS}: point contact (one point per pair of geometries)",
            "point contact puts a box's one contact point where the box overlaps the plane most, "
            "and at the default step (1 ms) that point moves within a step from the middle of "
            "the face to a corner as the box tilts: the force the first point's penetration "
            "built acts at the second, with another lever arm (a flat block 10 m wide and 1 m "
            "high landing at 5 m/s with e = 0 leaves with 1.2 times the energy it brought; at "
            "dt = 1e-4 s with 0.22 times)",
            (),
        ),
        Claim(
            "admissible",
            option("settings", "default") & moving_impact,
            f"{_DOCS}: DefaultProximityProperties (point_stiffness 1e6 N/m), MultibodyPlantConfig "
            "(time_step 1 ms)",
            "at its defaults a contact is soft and stepped at 1 ms: the impact lasts long enough "
            "for the bodies to leave the configuration the problem is frozen at, and a contact "
            "the engine no longer meets is left approaching along its frozen normal (the "
            "billiard shot lasts 16 ms, the ball slides out from under the tip: un+ = -0.24 "
            "m/s)",
            (("billiard", "default"),),
        ),
        normal_turned(
            f"{_DOCS}: DefaultProximityProperties (point_stiffness 1e6 N/m), MultibodyPlantConfig "
            "(time_step 1 ms)",
            "the billiard shot at mu = 0 takes |Pt| = 0.0035 N s",
        ),
        Claim(
            "admissible",
            option("settings", "default") & slower_than_overlap & misreported_impulse,
            f"{_DOCS}: MultibodyPlantConfig (the lagged approximation, solved by SAP), "
            "get_contact_results_output_port (contact results of the discrete update)",
            "at its defaults the discrete solver stops at its tolerance on the momentum, and a "
            "step whose contact impulse is below it changes no velocity while the contact "
            "results report the contact's force: a grazing approach slower than the starting "
            "overlap pushes with that overlap's force for many steps before a step applies it "
            "(the three-ball chain grazing at 1e-8 m/s: 76 steps of 1 ms report up to 4.3e-7 N s "
            "each and change no velocity, the reported impulses add up to 1.8e-5 N s; Drake's "
            "own velocity separates the contacts at +2.0e-7 and +2.9e-7 m/s, the outcome leaves "
            "the second approaching at -7.4e-6)",
        ),
        Claim(
            "admissible",
            option("settings", "default") & turning_impact,
            f"{_DOCS}: DefaultProximityProperties (point_stiffness 1e6 N/m), MultibodyPlantConfig "
            "(time_step 1 ms)",
            "at its defaults a contact is soft, and a body spinning through the impact turns "
            "while it lasts: the engine lets go where the contact separates at the configuration "
            "reached, and the gap rate read at the frozen configuration is off by up to "
            "|omega|^2 r T (the falling rod grazing the floor at 1e-2 m/s with e = 0, spinning at "
            "3.4 rad/s: un+ = -3.2e-3 m/s after 7 ms, -5.8e-4 after 2.4 ms at dt = 1e-5 s; "
            "without the spin it leaves separating, +1.7e-3)",
        ),
        *_YARDSTICK,
    )
    # Tuned, Drake integrates each impact in time as the scenes' ground truth does: it checks
    # the yardstick on every scene with a geometry (the report's full mode).
    studies = ({"shape": "yardstick", "options": {"settings": "tuned"}},)

    def _open(self, start: Start) -> Scene:
        return DrakeScene(start, _tuning(start.problem, start.dt) if start.tuned else None)


def _tuning(problem: ImpactProblem, dt: float) -> Tuning:
    """The tuned settings of ``problem``'s scene at step ``dt``.

    The stiffnesses are the contacts' in their ratios, scaled so that the stiffest contact
    (the largest stiffness over effective mass, ``k_j G_jj``) has the period
    `STEPS_PER_CONTACT` dt; the dissipation of contact j is `dissipation_speed` of its e over
    the scene's largest pre-impact approach speed, and the stiction tolerance `STICTION` times
    the largest pre-impact speed of a body.
    """
    stiffness = np.array([contact.stiffness for contact in problem.contacts])
    G = np.diag(np.asarray(problem.delassus))
    scale = (2.0 * math.pi / (STEPS_PER_CONTACT * dt)) ** 2 / float((stiffness * G).max())
    approach = float(-np.min(problem.un, initial=0.0))
    e = problem.restitution("kinematic")
    springs = [
        (scale * k, dissipation_speed(float(e_j)) / approach if approach > 0 else 0.0)
        for k, e_j in zip(stiffness, e, strict=True)
    ]
    speeds = problem.geometry.body_velocities(problem.v)[:, :3]
    fastest = float(np.linalg.norm(speeds, axis=1).max())
    return Tuning(springs, STICTION * (fastest or approach or 1.0), ACCURACY)


LAWS.register(Drake())
