"""Brach's bilinear law: normal restitution e, tangential restitution e_t, Coulomb bound mu.

Source: R.M. Brach, "Rigid body collisions", J. Appl. Mech. 56 (1989) 133-138, and
*Mechanical Impact Dynamics: Rigid Body Collisions* (Wiley, 1991): a kinematic normal
coefficient ``e`` and an impulse ratio bounded by Coulomb's ``mu``, the ratio being the one that
gives the tangential rebound ``e_t`` when it fits in the bound. For a particle (Brogliato,
*An introduction to impact dynamics*, 2010, equation 11)::

    pn = -(1 + e) m vn-
    pt = -min(mu pn, (1 + e_t) m |vt-|) sgn(vt-)

Conventions: ``un < 0`` approaches, ``Pn >= 0`` pushes apart; ``ut = Wt.T v``, one tangential
direction (planar) or two (spatial); ``e_t`` in [-1, 1]: 0 ends with no slip, 1 reverses the
slip, -1 leaves it unchanged, so the branch ``|Pt| < mu Pn`` gives ``ut+ = -e_t ut-``. The
friction opposes the pre-impact slip ``s = ut- / |ut-|`` (in 3D the law keeps this direction
throughout); Whittaker's law, by contrast, opposes the post-impact slip.

One contact, with the body's inertia through its contact Delassus matrix
``G = [[Gnn, Gnt], [Gtn, Gtt]]`` (effective normal mass ``1 / Gnn``, effective tangential mass
along the slip ``1 / (s.Gtt s)``). Coupling ``Gnt`` is kept, as in Brach's planar rigid-body
equations: both restitution conditions are imposed on the contact-point velocities.

- tangential restitution ("stick" regime): solve ``G (Pn, Pt) = (-(1 + e) un-, -(1 + e_t) ut-)``;
  accepted when ``Pn >= 0`` and ``|Pt| <= mu Pn``;
- otherwise ("slip" regime): ``Pt = -mu Pn s`` and ``un+ = -e un-``, so
  ``Pn = -(1 + e) un- / (Gnn - mu Gnt.s)``.

With ``Gnt = 0`` and an isotropic ``Gtt`` (a particle, a sphere, a disk) the two branches are
exactly equation (11) with the effective masses. Without pre-impact slip (``ut- = 0``, below
1e-12 of ``|un-|``) equation (11) gives no tangential impulse; a coupled body still slips when
the stick branch exceeds the cone, and then ``s`` is the direction opposite to that branch's
tangential impulse (the slip the impact would start). When ``Gnn - mu Gnt.s <= 0`` (strong
normal-tangential coupling) the slip branch has no non-negative normal impulse and the law
raises `NotApplicable` (in the plane this needs ``mu >= Gnn / |Gnt|``, where the stick branch
always fits in the cone, so it happens only in space). A contact that does not approach
(``un- >= 0``) receives no impulse. Without a tangential Jacobian, or with ``mu = 0``, the
law is Newton's.

Energy: ``dT = Pn (1 - e) un- / 2 + Pt.(ut- + ut+) / 2``. The first term is a loss; with
coupling the second can be a gain (the slip reverses and grows), which the ``energy_gain``
check reports on the coupled scenes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.checks.regions import coupled_friction
from lawbench.core.errors import NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.tags import Tags
from lawbench.core.verdicts import Claim
from lawbench.laws._claims import keeps_energy

if TYPE_CHECKING:
    from lawbench.core.batch import ProblemBatch

# Below this fraction of |un-| a slip velocity counts as zero.
NO_SLIP = 1e-12
# Contact Delassus matrices of a larger condition number are solved one by one (least squares).
CONDITION = 1e8

_REVERSAL_GAIN = (
    "the tangential impulse, bounded by mu Pn and opposing the pre-impact slip, drives the "
    "contact point through zero slip; through the normal-tangential coupling of the contact "
    "Delassus matrix the slip reverses and grows, and Pt.(ut- + ut+) / 2 > 0 outweighs the "
    "normal loss (Kane and Levinson's paradox, Brogliato 2010, after eq. 9)"
)


class Brach(Law):
    """Brach's bilinear law at one contact, with the body's contact Delassus matrix."""

    name = "brach"
    summary = "Brach's bilinear law (e, e_t, mu) at one contact, with effective masses"
    source = "Brach 1989, 1991; Brogliato 2010, eq. (11)"
    tags = Tags(friction=True, several_contacts=False, spatial=True)
    fitted = ("e", "e_t", "mu")
    separating_rule = "a separating contact takes no impulse"

    findings = (
        Claim(
            "energy_gain",
            coupled_friction,
            "Kane and Levinson 1985; Brogliato 2010, after eq. (9) and eq. (11)",
            _REVERSAL_GAIN,
            (("falling_rod", "energy gain"),),
        ),
    )
    guarantees = (
        keeps_energy(
            "Brach 1989; Brogliato 2010, eq. (11): without friction the normal law is Newton's",
            "at e = 1 the contact leaves with un+ = -un-, which keeps the energy",
        ),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        un = float(problem.un[0])
        if un >= 0.0:
            diagnostics = {"formulation": "no impulse (the contact does not approach)"}
            return Outcome.from_impulses(problem, np.zeros(1), diagnostics=diagnostics)
        e = float(problem.restitution("kinematic")[0])
        if problem.d == 0:
            Pn = -(1.0 + e) * un / problem.delassus[0, 0]
            diagnostics = {"formulation": "closed form (frictionless: Newton)"}
            return Outcome.from_impulses(problem, np.array([Pn]), diagnostics=diagnostics)
        contact = problem.contacts[0]
        Pn, Pt, regime, slip = _impulses(
            problem.contact_delassus, un, problem.ut, e, contact.e_t, contact.mu
        )
        G = problem.contact_delassus
        tangential = float(slip @ G[1:, 1:] @ slip)
        diagnostics = {
            "formulation": "closed form" if _decoupled(G) else "closed form (coupled Delassus)",
            "regime": regime,
            # Normal and tangential (along the slip) effective masses; None: infinite.
            "effective_masses": [1.0 / G[0, 0], 1.0 / tangential if tangential > 0 else None],
        }
        return Outcome.from_impulses(problem, np.array([Pn]), Pt, diagnostics=diagnostics)

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """Both branches in closed form for every problem (`_batch_impulses`)."""
        un = batch.un[:, 0]
        approaching = un < 0.0
        e = batch.restitution("kinematic")[:, 0]
        G = batch.contact_delassus
        if batch.d == 0:
            Pn = np.where(approaching, -(1.0 + e) * un / G[:, 0, 0], 0.0)
            return Pn[:, None], "closed form (batch)"
        P = _batch_impulses(G, un, batch.ut, e, batch.coefficients["e_t"][:, 0], batch.mu[:, 0])
        P[~approaching] = 0.0
        return P, "closed form (batch)"


def _decoupled(G: np.ndarray) -> bool:
    """Whether the normal and tangential directions are uncoupled and Gtt is isotropic."""
    Gtt = G[1:, 1:]
    return not np.any(G[0, 1:]) and not np.any(Gtt - Gtt[0, 0] * np.eye(len(Gtt)))


def _impulses(
    G: np.ndarray, un: float, ut: np.ndarray, e: float, e_t: float, mu: float
) -> tuple[float, np.ndarray, str, np.ndarray]:
    """Brach's impulses at one approaching contact: ``(Pn, Pt, regime, slip direction)``."""
    target = np.concatenate([[-(1.0 + e) * un], -(1.0 + e_t) * ut])
    stick, *_ = np.linalg.lstsq(G, target, rcond=None)
    reachable = np.allclose(G @ stick, target, rtol=0.0, atol=1e-12 * np.abs(target).max())
    Pn, Pt = float(stick[0]), stick[1:]
    speed = float(np.linalg.norm(ut))
    if speed > NO_SLIP * abs(un):
        slip = ut / speed
    elif np.linalg.norm(Pt) > 0:
        slip = -Pt / np.linalg.norm(Pt)
    else:
        slip = np.eye(len(ut))[0]
    if reachable and Pn >= 0.0 and np.linalg.norm(Pt) <= mu * Pn:
        return Pn, Pt, "stick", slip
    denominator = G[0, 0] - mu * float(G[0, 1:] @ slip)
    if denominator <= 0.0:
        raise NotApplicable(
            f"brach: strong normal-tangential coupling, Gnn - mu Gnt.s = {denominator:.3g} "
            "<= 0: the slip branch has no non-negative normal impulse"
        )
    Pn = -(1.0 + e) * un / denominator
    return Pn, -mu * Pn * slip, "slip", slip


def _batch_impulses(
    G: np.ndarray, un: np.ndarray, ut: np.ndarray, e: np.ndarray, e_t: np.ndarray, mu: np.ndarray
) -> np.ndarray:
    """`_impulses` for a batch: ``(Pn, Pt)`` (B, 1 + d), NaN where `_impulses` must decide.

    Left to it: a contact Delassus matrix too close to singular for the stick branch
    (`CONDITION`, where it solves by least squares), and strong coupling (it refuses).
    """
    target = np.concatenate([(-(1.0 + e) * un)[:, None], -(1.0 + e_t)[:, None] * ut], axis=1)
    values = np.linalg.eigvalsh(G)
    alone = ~(values[:, -1] < CONDITION * values[:, 0])
    stick = np.linalg.solve(
        np.where(alone[:, None, None], np.eye(G.shape[1]), G), target[..., None]
    )
    stick = stick[..., 0]
    Pn, Pt = stick[:, 0], stick[:, 1:]
    speed, tangential = np.linalg.norm(ut, axis=1), np.linalg.norm(Pt, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        slip = np.where(
            (speed > NO_SLIP * np.abs(un))[:, None],
            ut / speed[:, None],
            np.where((tangential > 0)[:, None], -Pt / tangential[:, None], np.eye(ut.shape[1])[0]),
        )
    sticks = (Pn >= 0.0) & (tangential <= mu * Pn)
    denominator = G[:, 0, 0] - mu * np.einsum("kj,kj->k", G[:, 0, 1:], slip)
    with np.errstate(divide="ignore", invalid="ignore"):
        Pn_slip = -(1.0 + e) * un / denominator
    P = np.where(
        sticks[:, None],
        stick,
        np.concatenate([Pn_slip[:, None], -(mu * Pn_slip)[:, None] * slip], axis=1),
    )
    P[alone | (~sticks & (denominator <= 0.0))] = np.nan
    return P


LAWS.register(Brach())
