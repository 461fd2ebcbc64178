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

Damping: a contact's ``damping`` is the coefficient of the model's dashpot when positive (N s/m
for Kelvin-Voigt, N s / m^n for Hertzian damping, s/m for Hunt-Crossley); at zero it comes
from the contact's ``e``: Kelvin-Voigt inverts the lectures' closed form of the chosen
termination with the contact's effective mass ``1 / G_jj``; Hunt-Crossley applies its rule
with ``v0`` the largest pre-impact approach speed of the scene, for every contact and the whole
impact (a contact that a wave closes later has no approach speed of its own: taking its speed
at closure, which can be near zero, makes the damping unbounded); Hertz is elastic and refuses
``e < 1``.

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

import math
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
import scipy.optimize
from lawbench.laws._claims import keeps_energy, never_creates_energy

from lawbench.core import budget
from lawbench.core.errors import NotApplicable
from lawbench.core.law import LAWS, Law
from lawbench.core.mechanics import for_products
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.numerics.integrator import EventIntegrator

MODELS = ("kelvin_voigt", "hertz", "hunt_crossley")
DAMPING_RULES = {
    "hunt_crossley": lambda e, v0: 3.0 * (1.0 - e) / (2.0 * v0),
    "lankarani_nikravesh": lambda e, v0: 3.0 * (1.0 - e * e) / (4.0 * v0),
    "flores": lambda e, v0: 8.0 * (1.0 - e) / (5.0 * e * v0) if e > 0 else math.inf,
}


def kelvin_voigt_restitution(ratio: float, termination: str) -> float:
    """Restitution coefficient of a Kelvin-Voigt contact, damping ratio ``c / (2 sqrt(k m))``.

    Brogliato 2010, 'Expressions for the kinematic restitution coefficient': termination at
    gap reopening ``exp(-pi z / sqrt(1 - z^2))``; when the force returns to zero
    ``exp(-2 z arccos(z) / sqrt(1 - z^2))`` (the lectures' arctan taken in (0, pi)). Zero from
    critical damping on.
    """
    if ratio >= 1.0:
        return 0.0
    angle = math.pi if termination == "gap" else 2.0 * math.acos(ratio)
    return math.exp(-ratio * angle / math.sqrt(1.0 - ratio * ratio))


def _kelvin_voigt_ratio(e: float, termination: str) -> float:
    """The damping ratio whose Kelvin-Voigt restitution coefficient is ``e``.

    Raises `NotApplicable` for the coefficients no underdamped contact reaches: ``e = 0`` (at
    critical damping the gap never reopens) and, when the contact ends as its force returns to
    zero, ``e < exp(-2)`` (the limit of that closed form as the ratio tends to 1).
    """
    if e >= 1.0:
        return 0.0
    lowest = 0.0 if termination == "gap" else math.exp(-2.0)
    if e <= lowest:
        raise NotApplicable(
            f"compliant: a Kelvin-Voigt contact ending at {termination} reaches only "
            f"e > {lowest:.4g} when underdamped; e = {e:g} is out of its reach"
        )
    return scipy.optimize.brentq(
        lambda z: kelvin_voigt_restitution(z, termination) - e, 0.0, 1.0 - 1e-15, xtol=1e-15
    )


class Compliant(Law):
    """Time integration of unilateral compliant contacts (Kelvin-Voigt, Hertz, Hunt-Crossley)."""

    name = "compliant"
    summary = (
        "time integration of unilateral compliant contacts (Kelvin-Voigt, Hertz, Hunt-Crossley)"
    )
    source = "Brogliato 2010, compliant contacts; Hunt and Crossley 1975; Flores et al. 2011"
    tags = Tags(several_contacts=True, stiffness=True, accuracy_knob="tol")
    separating_rule = (
        "a separating contact carries a force only while its spring is compressed, if the "
        "motion closes it again"
    )
    follows_gaps = True
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
        Spec("tol", 1e-10, "relative tolerance of the integrator", "", "float", 0.0, 1e-2, True),
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
            "DOP853",
            "solve_ivp method",
            kind="str",
            choices=("DOP853", "RK45", "Radau", "LSODA"),
        ),
        Spec("max_steps", 200_000, "budget of integrator steps", "", "int", 1),
        Spec("max_events", 100_000, "budget of restarts at contact events", "", "int", 1),
        Spec("path", False, "return time histories of forces and stored energies", "", "bool"),
    )

    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        return _Integration(problem, options).run()


LAWS.register(Compliant())


class _Integration:
    """One compliant impact in contact space: scaled gaps, gap rates and impulses.

    With ``G = Wn.T M^-1 Wn`` the Delassus matrix, the m contacts obey ``g' = un``,
    ``un' = G F`` and ``Pn' = F``; the velocity follows once, ``v+ = v + M^-1 Wn Pn``. Between
    restarts a set of contacts is closed and acts; the others carry no force, so only the gap
    rates a closed contact's column of G reaches change, and every other gap moves linearly.
    The integrator advances the closed contacts and their neighbours; the others are moved in
    closed form, and the first of them to close ends the integration there.
    """

    def __init__(self, problem: ImpactProblem, options: dict[str, Any]) -> None:
        import scipy.sparse

        self.problem, self.options = problem, options
        self.model = options["model"]
        contacts = problem.contacts
        self.k = np.array([c.stiffness for c in contacts])
        self.n = (
            np.ones(problem.m)
            if self.model == "kelvin_voigt"
            else np.array([c.exponent for c in contacts])
        )
        self.e = problem.restitution("kinematic")
        self.given_damping = np.array([c.damping for c in contacts])
        G = scipy.sparse.csc_array(problem.delassus)
        diagonal = G.diagonal()
        self.V = float(max(np.abs(problem.un).max(), 1e-300))
        indentation = ((self.n + 1) * self.V**2 / (2 * self.k * diagonal)) ** (1 / (self.n + 1))
        self.L = float(indentation.min())
        self.tau = self.L / self.V
        self.I = self.V / float(diagonal.max())
        # Scaled Delassus matrix: the scaled gap-rate change per scaled impulse.
        self.G = G / float(diagonal.max())
        self.clipped = not (self.model == "kelvin_voigt" and options["termination"] == "gap")
        self.c = self._initial_damping(diagonal)
        # The integrator resolves no speed below ``tol`` V (scaled: ``tol``): a contact that
        # approaches more slowly is at rest, and a contact acts once its spring holds more
        # energy than its effective mass carries at that speed, beyond the scaled indentation
        # ``band``. Neither changes a velocity by more than ``tol`` V.
        self.rest = options["tol"]
        stored = (self.rest * self.V) ** 2 / (2.0 * diagonal)
        self.band = (stored * (self.n + 1) / self.k) ** (1 / (self.n + 1)) / self.L

    def _initial_damping(self, G: np.ndarray) -> np.ndarray:
        c = self.given_damping.copy()
        derive = c == 0.0
        if self.model == "hertz" and (derive & (self.e < 1)).any():
            j = int(np.flatnonzero(derive & (self.e < 1))[0])
            raise NotApplicable(
                f"compliant: hertz is elastic unless a damping is given; contact {j} has "
                f"e = {self.e[j]:g} and damping 0 (use hunt_crossley or kelvin_voigt)"
            )
        if self.model == "kelvin_voigt":
            for j in np.flatnonzero(derive):
                ratio = _kelvin_voigt_ratio(self.e[j], self.options["termination"])
                c[j] = 2.0 * ratio * math.sqrt(self.k[j] / G[j])
        if self.model == "hunt_crossley":
            if (derive & (self.e <= 0)).any():
                raise NotApplicable("compliant: hunt_crossley needs e > 0 for its damping rule")
            rule = DAMPING_RULES[self.options["damping_rule"]]
            for j in np.flatnonzero(derive):
                c[j] = rule(self.e[j], self.V)
        return c

    def forces(self, g: np.ndarray, un: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Forces in newtons of the closed contacts ``j``, from their scaled gaps and rates.

        ``g`` and ``un`` hold one contact per entry of their last axis.
        """
        d, rate = -self.L * g, -self.V * un
        k, n, c = self.k[j], self.n[j], self.c[j]
        if self.model == "kelvin_voigt":
            law = k * d + c * rate
        else:
            # Zero where the contact is open (0^n = 0): the powers need no mask.
            dn = np.maximum(d, 0.0) ** n
            if self.model == "hertz":
                law = k * dn + c * np.maximum(d, 0.0) ** (n - 1) * rate
            else:
                law = k * dn * (1.0 + c * rate)
        return np.maximum(law, 0.0) if self.clipped else law

    def stored(self, g: np.ndarray) -> np.ndarray:
        """Elastic energy of every contact's spring at the scaled gaps ``g``."""
        d = np.maximum(-self.L * g, 0.0)
        return self.k * d ** (self.n + 1) / (self.n + 1)

    def at_rest(self, g: np.ndarray, un: np.ndarray) -> bool:
        """Whether no contact acts and none approaches faster than ``tol`` V."""
        return bool((g > -self.band).all()) and bool((un >= -self.rest).all())

    def run(self) -> Outcome:
        problem, options = self.problem, self.options
        m = problem.m
        g, un, P = problem.gaps / self.L, problem.un / self.V, np.zeros(m)
        rtol = options["tol"]
        integrator = EventIntegrator(options["method"], rtol, rtol * 1e-3)
        spend = budget.current()
        t, self.steps, events = 0.0, 0, 0
        self.peak = np.zeros(m)
        self.history: list[tuple[float, np.ndarray, np.ndarray]] = []
        # Gaps are never negative at the start: every contact is open.
        self._keep(t, g, np.zeros(m, dtype=bool), np.zeros(0))
        while not self.at_rest(g, un):
            closed = g <= -self.band
            closing = ~closed & (un < 0)
            # The first contact to close among those no closed contact pushes: in closed form.
            near = self._neighbours(closed)
            far = closing & ~near
            wait = np.full(m, np.inf)
            wait[far] = (g[far] + self.band[far]) / -un[far]
            first = int(np.argmin(wait))
            if near.any():
                mode = _Mode(self, closed, near)
                event = integrator.to_event(
                    mode.rhs,
                    t,
                    np.concatenate([g[near], un[near], P[closed]]),
                    mode.switches,
                    mode.direction,
                    t + wait[first],
                    on_step=partial(self._on_step, mode),
                )
                far_moved = ~near
                g[far_moved] += un[far_moved] * (event.x - t)
                t, fired = event.x, event.fired
                g[near], un[near], P[closed] = mode.split(event.y)
            else:
                spend.event()
                g += un * wait[first]
                t, fired = t + wait[first], ()
            if not fired:
                g[first] = -self.band[first]
            events += 1
        diagnostics = {
            "formulation": f"time integration ({self.model}, {options['method']})",
            "duration_s": t * self.tau,
            "peak_force": self.peak.tolist(),
            "damping": self.c.tolist(),
            "steps": self.steps,
            "events": events,
        }
        path = self._path() if options["path"] else None
        return Outcome.from_impulses(problem, self.I * P, diagnostics=diagnostics, path=path)

    def _neighbours(self, closed: np.ndarray) -> np.ndarray:
        """The contacts whose gap rate a closed contact's force changes (the closed included)."""
        near = closed.copy()
        near[self.G[:, np.flatnonzero(closed)].indices] = True
        return near

    def _on_step(self, mode: _Mode, dense: Callable, t_old: float, t: float) -> None:
        """Count the step, keep the peak forces (four points) and the path's point."""
        self.steps += 1
        y = dense(np.linspace(t_old, t, 5)[1:]).T
        g, un, _ = mode.split(y)
        forces = self.forces(g[:, mode.acting], un[:, mode.acting], mode.closed)
        self.peak[mode.closed] = np.maximum(self.peak[mode.closed], forces.max(axis=0))
        if self.options["path"]:
            full = np.full(self.problem.m, np.inf)
            full[mode.near] = g[-1]
            self._keep(t, full, mode.closed, forces[-1])

    def _keep(self, t: float, g: np.ndarray, closed: np.ndarray, forces: np.ndarray) -> None:
        """One point of the path: the forces of the closed contacts, the springs' energies."""
        if self.options["path"]:
            force = np.zeros(self.problem.m)
            force[closed] = forces
            self.history.append((t, force, self.stored(g)))

    def _path(self) -> dict[str, np.ndarray]:
        return {
            "t": np.array([t for t, _, _ in self.history]) * self.tau,
            "force": np.array([f for _, f, _ in self.history]),
            "stored_energy": np.array([s for _, _, s in self.history]),
        }


class _Mode:
    """The field between two restarts: closed contacts act on their neighbours' gap rates.

    State ``[g (near), un (near), Pn (closed)]`` in scaled units, ``near`` the closed contacts
    and those their forces reach.
    """

    def __init__(self, integration: _Integration, closed: np.ndarray, near: np.ndarray) -> None:
        self.integration, self.closed, self.near = integration, np.flatnonzero(closed), near
        rows = np.flatnonzero(near)
        self.size = rows.size
        self.acting = np.searchsorted(rows, self.closed)
        # Scaled: the time is over tau, so the scaled force is the impulse rate over I / tau.
        self.scale = integration.tau / integration.I
        self.G = for_products(integration.G[rows][:, self.closed].toarray())
        self.band = integration.band[rows]
        self.damped = integration.clipped and bool(integration.c[self.closed].any())
        # A gap fires only as it passes its band away from its side: a closed contact (on its
        # band at the restart that closed it) opening, an open one closing.
        self.direction = np.where(closed[rows], 1.0, -1.0)
        if self.damped:
            self.direction = np.concatenate([self.direction, np.zeros(self.closed.size)])

    def split(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Gaps, gap rates and impulses of a state (or of states along the last axis)."""
        s = self.size
        return y[..., :s], y[..., s : 2 * s], y[..., 2 * s :]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        g, un, _ = self.split(y)
        f = self.scale * self.integration.forces(g[self.acting], un[self.acting], self.closed)
        return np.concatenate([un, self.G @ f, f])

    def switches(self, t: float, y: np.ndarray) -> np.ndarray:
        """A gap passing its band; with clipped dashpots, the sign of each closed law."""
        g, un, _ = self.split(y)
        gaps = g + self.band
        if not self.damped:
            return gaps
        c, closed = self.integration.c[self.closed], self.closed
        rate = -self.integration.V * un[self.acting]
        if self.integration.model == "hunt_crossley":
            sign = 1.0 + c * rate
        else:
            sign = self.integration.k[closed] * (-self.integration.L * g[self.acting]) + c * rate
        return np.concatenate([gaps, np.where(c > 0, sign, 1.0)])
