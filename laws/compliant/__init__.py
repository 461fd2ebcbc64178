"""Compliant contacts: the impact resolved in time, each contact a unilateral force law.

Source: Brogliato, *An introduction to impact dynamics* (2010), compliant contacts: the
Kelvin-Voigt spring-dashpot ``F = k d + c d'`` and its two terminations with their restitution
coefficients; Hertz's law ``F = K d^n`` (n = 3/2) and Hertzian (Kuwabara-Kono) damping
``c d^(n-1) d'``; Hunt and Crossley's law ``F = K d^n (1 + c d')`` (J. Appl. Mech. 42, 1975),
with ``c`` from the restitution coefficient and the approach speed ``v0`` by a named rule:
Hunt and Crossley 1975, ``c = 3 (1 - e) / (2 v0)``; Lankarani and Nikravesh (J. Mech. Des.
112, 1990), ``c = 3 (1 - e^2) / (4 v0)``; Flores, Machado, Silva and Martins (Multibody Syst.
Dyn. 25, 2011), ``c = 8 (1 - e) / (5 e v0)``.

Conventions: the indentation of contact j is ``d_j = -g_j`` (g the gap, zero at first
contact), its rate ``d'_j = -un_j``; the contact force pushes apart and gives the impulse
``Pn_j``; ``M v' = Wn F``, gravity and every other force ignored during the impact. A contact
acts while ``d_j > 0``. With ``termination='gap'`` (Kelvin-Voigt only) its force is the law's
value even when the dashpot makes it attractive at the end; otherwise the force is
``max(0, law)``, so a contact releases when its force returns to zero.

Friction: where the problem has a tangential Jacobian, each contact also carries a tangential
spring (stiffness the normal one over the contact's ``tangential_stiffness_ratio``, Jia's
``eta0^2``) in series with a Coulomb slider (Jia, IJRR 32(1) 2013, the same springs in time;
Mindlin 1949 for the stiffness ratio), planar or spatial, at several contacts at once:
`lawbench.laws.compliant.friction`. ``Pt`` is the tangential impulse in the columns of ``Wt``,
``|Pt_j| <= mu_j Pn_j`` along the whole impact, and ``v+ = v- + M^-1 (Wn Pn + Wt Pt)``.

Damping: a contact's ``damping`` is the coefficient of the model's dashpot when positive (N s/m
for Kelvin-Voigt, N s / m^n for Hertzian damping, s/m for Hunt-Crossley); at zero it comes
from the contact's ``e``: Kelvin-Voigt inverts the lectures' closed form of the chosen
termination with the contact's effective mass ``1 / G_jj``; Hunt-Crossley applies its rule
with ``v0`` the largest pre-impact approach speed of the scene, for every contact and the whole
impact (a contact that a wave closes later has no approach speed of its own: taking its speed
at closure, which can be near zero, makes the damping unbounded); Hertz is elastic and refuses
``0 < e < 1``. Kelvin-Voigt ended where its force returns to zero reaches only e > exp(-2).

Plastic contacts: at ``e = 0`` with no damping given, no dashpot reaches the coefficient (a
critically damped gap never reopens; Hunt-Crossley's damping grows without bound), so the
contact is plastic whatever the model: its spring alone loads it while the indentation grows,
and where the indentation stops growing the force drops to zero and the indentation reached
stays, the gap measured again from there (a contact pushed in again loads its spring from
zero). This is Walton and Braun's hysteretic spring (J. Rheol. 30, 1986; unloading stiffness
``k / e^2``) as e tends to 0, except that a reload follows the loading law rather than a rigid
unloading line. Two bodies leave a plastic contact with one normal velocity, the binary impact
at e = 0, and the energy the spring held is lost; with friction the tangential spring is
released with it.

Numerics: scipy's ``solve_ivp`` (DOP853 by default) in contact space, ``g' = un``,
``un' = G F``, ``Pn' = F`` with ``G = Wn.T M^-1 Wn`` the Delassus matrix, in scaled variables
(velocities over the largest approach speed V, lengths over the largest static indentation
scale, time over their ratio); the velocity follows once from the impulses. It is restarted at
every event where a force law changes branch (a contact closes, opens, or its force crosses
zero), so the right-hand side is smooth between restarts. Between restarts only the closed
contacts and the contacts their columns of G reach are integrated; every other gap moves
linearly and the first of them to close is met in closed form, so a wave along an n-ball chain
costs O(n) and not O(n^2). The integrator resolves no speed below ``tol`` V: a contact that
approaches more slowly is at rest (the noise of the integration leaves the balls behind a
Hertz wave with speeds of that order, whose collisions would otherwise multiply the events as
n^2), and a contact acts once its spring holds the kinetic energy of its effective mass at that
speed. The impact ends when no spring is compressed and no contact approaches faster than
``tol`` V. The accuracy knob is ``tol`` (atol = tol times 1e-3 in scaled units). Order of
convergence: the error of ``v_plus`` against a tight-tolerance reference falls in proportion
to tol (slope 1 in log-log; on the three-ball chain it stays between 0.01 and 0.2 times tol
from 1e-3 to 1e-10, tested), while DOP853's step count grows only as about tol^(-1/8).
Budgets: ``max_steps`` solver steps and ``max_events`` restarts and ``max_seconds`` of
wall-clock time, each raising `SolverFailure` naming what ran out.
"""

from __future__ import annotations

from typing import Any

from lawbench.core.errors import NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.core.metric import all_finite
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.laws._claims import keeps_energy, never_creates_energy
from lawbench.laws._options import bound, path_option
from lawbench.laws.compliant.friction import FrictionalIntegration
from lawbench.laws.compliant.normal import (
    DAMPING_RULES,
    MODELS,
    Integration,
    kelvin_voigt_restitution,
)

__all__ = ["DAMPING_RULES", "MODELS", "Compliant", "kelvin_voigt_restitution"]


class Compliant(Law):
    """Time integration of unilateral compliant contacts, with tangential springs and sliders."""

    name = "compliant"
    summary = (
        "time integration of unilateral compliant contacts (Kelvin-Voigt, Hertz, Hunt-Crossley), "
        "with tangential springs and Coulomb sliders where there is friction"
    )
    source = "Brogliato 2010, compliant contacts; Hunt and Crossley 1975; Flores et al. 2011"
    tags = Tags(
        friction=True, several_contacts=True, spatial=True, stiffness=True, accuracy_knob="tol"
    )
    fitted = ("e", "mu", "tangential_stiffness_ratio")
    separating_rule = (
        "a separating contact carries a force only while its spring is compressed, if the "
        "motion closes it again"
    )
    follows_gaps = True
    # Its damping's unit depends on the model (N s/m, N s/m^n or s/m): it solves in the
    # problem's own units, which its integration scales by itself.
    scale_free = False
    guarantees = (
        keeps_energy(
            "Brogliato 2010, compliant contacts; Hunt and Crossley 1975",
            "at e = 1 every force law is a spring without damping, a conservative system",
        ),
        never_creates_energy(
            "Brogliato 2010, compliant contacts; Hunt and Crossley 1975",
            "springs with non-negative damping only give back what they stored",
        ),
    )
    options = (
        Spec("model", "hunt_crossley", "force law of every contact", kind="str", choices=MODELS),
        Spec(
            "tol", 1e-10, "relative tolerance of the integrator", low=0.0, high=1e-2, low_open=True
        ),
        Spec(
            "termination",
            "force",
            "Kelvin-Voigt: contact ends when the gap reopens or when its force returns to zero",
            kind="str",
            choices=("gap", "force"),
        ),
        Spec(
            "damping_rule",
            "flores",
            "Hunt-Crossley: rule giving the damping from e and the approach speed",
            kind="str",
            choices=tuple(DAMPING_RULES),
        ),
        Spec(
            "method",
            "auto",
            "solve_ivp method; auto: LSODA with spatial friction, DOP853 otherwise",
            kind="str",
            choices=("auto", "DOP853", "RK45", "Radau", "LSODA"),
        ),
        bound("max_steps", 200_000, "budget of integrator steps"),
        bound("max_events", 100_000, "budget of restarts at contact events"),
        path_option("time histories of forces and stored energies"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        G = problem.contact_delassus if problem.frictional else problem.delassus
        diagonal = G.diagonal()
        if not (all_finite(diagonal) and diagonal.min() > 0.0):
            raise NotApplicable(
                "compliant: integrates in the problem's own units (a damping's unit depends on "
                "the model), and this problem's inverse effective masses overflow or underflow "
                "(Delassus entries beyond 1.8e308 or below 2.2e-308): give it in units near "
                "its masses"
            )
        integration = FrictionalIntegration if problem.frictional else Integration
        return integration(problem, options).run()


LAWS.register(Compliant())
