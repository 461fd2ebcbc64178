"""Compliant contacts without friction: unilateral force laws integrated in contact space.

The normal force laws, their damping from a restitution coefficient, and the integration of
the gaps, gap rates and impulses of every contact (`lawbench.laws.compliant` states the
model, its conventions and its numerics).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
import scipy.optimize

from lawbench.core.errors import NotApplicable
from lawbench.core.guards import current_budget
from lawbench.core.mechanics import for_products
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
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
    """The damping ratio whose Kelvin-Voigt restitution coefficient is ``e > 0``.

    Raises `NotApplicable` for the coefficients no underdamped contact reaches when the contact
    ends as its force returns to zero: ``e <= exp(-2)``, the limit of that closed form as the
    ratio tends to 1 (a gap that must reopen reaches every ``e > 0``; ``e = 0`` is the plastic
    contact).
    """
    if e >= 1.0:
        return 0.0
    if termination == "force" and e <= math.exp(-2.0):
        raise NotApplicable(
            f"compliant: a Kelvin-Voigt contact ending at force reaches only e > "
            f"{math.exp(-2.0):.4g} when underdamped; e = {e:g} is out of its reach"
        )
    return scipy.optimize.brentq(
        lambda z: kelvin_voigt_restitution(z, termination) - e, 0.0, 1.0 - 1e-15, xtol=1e-15
    )


class Integration:
    """One compliant impact in contact space: scaled gaps, gap rates and impulses.

    With ``G = Wn.T M^-1 Wn`` the Delassus matrix, the m contacts obey ``g' = un``,
    ``un' = G F`` and ``Pn' = F``; the velocity follows once, ``v+ = v + M^-1 Wn Pn``. Between
    restarts a set of contacts is closed and acts; the others carry no force, so only the gap
    rates a closed contact's column of G reaches change, and every other gap moves linearly.
    The integrator advances the closed contacts and their neighbours; the others are moved in
    closed form, and the first of them to close ends the integration there.
    """

    # The method of ``method='auto'``.
    AUTO = "DOP853"

    def __init__(self, problem: ImpactProblem, options: dict[str, Any]) -> None:
        import scipy.sparse

        self.problem, self.options = problem, options
        self.model = options["model"]
        self.method = self.AUTO if options["method"] == "auto" else options["method"]
        contacts = problem.contacts
        self.k = np.array([c.stiffness for c in contacts])
        self.n = (
            np.ones(problem.m)
            if self.model == "kelvin_voigt"
            else np.array([c.exponent for c in contacts])
        )
        self.e = problem.restitution("kinematic")
        self.given_damping = np.array([c.damping for c in contacts])
        # At e = 0 with no damping given a contact is plastic: its spring alone loads it, and
        # it lets go where its indentation stops growing.
        self.plastic = (self.e == 0.0) & (self.given_damping == 0.0)
        G = scipy.sparse.csc_array(problem.delassus)
        diagonal = G.diagonal()
        self.V = float(max(np.abs(problem.un).max(), 1e-300))
        with np.errstate(over="ignore", under="ignore", divide="ignore"):
            # Each contact's indentation scale: where its spring holds the kinetic energy of
            # its effective mass 1 / G_jj at the largest approach speed.
            self.indentation = ((self.n + 1) * np.square(self.V) / (2 * self.k * diagonal)) ** (
                1 / (self.n + 1)
            )
            self.L = float(self.indentation.min())
            self.tau = self.L / self.V
            self.G_max = float(diagonal.max())
            self.I = self.V / self.G_max
            # A force in newtons as a scaled impulse rate (time over tau, impulses over I).
            self.scale = self.tau / self.I
        self._refuse_scales_beyond_range()
        # Scaled Delassus matrix: the scaled gap-rate change per scaled impulse.
        self.G = G / self.G_max
        self.clipped = not (self.model == "kelvin_voigt" and options["termination"] == "gap")
        self.c = self._initial_damping(diagonal)
        # The integrator resolves no speed below ``tol`` V (scaled: ``tol``): a contact that
        # approaches more slowly is at rest, and a contact acts once its spring holds more
        # energy than its effective mass carries at that speed, beyond the scaled indentation
        # ``band``. Neither changes a velocity by more than ``tol`` V.
        self.rest = options["tol"]
        stored = (self.rest * self.V) ** 2 / (2.0 * diagonal)
        self.band = (stored * (self.n + 1) / self.k) ** (1 / (self.n + 1)) / self.L

    def _refuse_scales_beyond_range(self) -> None:
        """Refuse an impact whose length, time, impulse or gap scale leaves double precision.

        The integration runs in the problem's own units, scaled by these: an approach of 1e160
        m/s on a Delassus entry of 1e20 has an indentation scale the square of the speed
        overflows.
        """
        scales = {"indentation": self.L, "time": self.tau, "impulse": self.I, "force": self.scale}
        for name, value in scales.items():
            if not 0.0 < value < math.inf:
                raise NotApplicable(
                    f"compliant: integrates in the problem's own units, where this impact's "
                    f"{name} scale leaves double precision (approach speed "
                    f"{self.V:.3g}, largest Delassus entry {self.G_max:.3g}): give it in units "
                    "near its masses and speeds"
                )
        gap = float(self.problem.gaps.max())
        if not gap / self.L < math.inf:
            raise NotApplicable(
                f"compliant: a gap of {gap:.3g} m over the indentation scale ({self.L:.3g} m) "
                "leaves double precision, and the integration reads gaps in that scale"
            )

    def _initial_damping(self, G: np.ndarray) -> np.ndarray:
        c = self.given_damping.copy()
        derive = (c == 0.0) & ~self.plastic
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
            rule = DAMPING_RULES[self.options["damping_rule"]]
            for j in np.flatnonzero(derive):
                c[j] = rule(self.e[j], self.V)
        return c

    def law(self, g: np.ndarray, un: np.ndarray, j: np.ndarray) -> np.ndarray:
        """The force laws of the closed contacts ``j`` (N), before clipping at zero.

        ``g`` and ``un`` are scaled gaps and rates, one contact per entry of their last axis.
        """
        d, rate = -self.L * g, -self.V * un
        k, n, c = self.k[j], self.n[j], self.c[j]
        if self.model == "kelvin_voigt":
            return k * d + c * rate
        # Zero where the contact is open (0^n = 0): the powers need no mask.
        dn = np.maximum(d, 0.0) ** n
        if self.model == "hertz":
            return k * dn + c * np.maximum(d, 0.0) ** (n - 1) * rate
        return k * dn * (1.0 + c * rate)

    def forces(self, g: np.ndarray, un: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Forces in newtons of the closed contacts ``j``, from their scaled gaps and rates."""
        law = self.law(g, un, j)
        return np.maximum(law, 0.0) if self.clipped else law

    def force_rate(
        self, g: np.ndarray, un: np.ndarray, un_rate: np.ndarray, j: np.ndarray
    ) -> np.ndarray:
        """The rate of the force laws of the closed contacts ``j`` in scaled time (N).

        ``un_rate`` is the scaled rate of the gap rates; the indentation changes at
        ``-L un`` and its rate at ``-V un_rate`` per unit of scaled time.
        """
        d, rate = np.maximum(-self.L * g, 0.0), -self.V * un
        k, n, c = self.k[j], self.n[j], self.c[j]
        if self.model == "kelvin_voigt":
            by_d, by_rate = k, c
        elif self.model == "hertz":
            with np.errstate(divide="ignore", invalid="ignore"):
                damped = np.where(c > 0, (n - 1) * c * d ** (n - 2) * rate, 0.0)
            by_d, by_rate = n * k * d ** (n - 1) + damped, c * d ** (n - 1)
        else:
            by_d, by_rate = n * k * d ** (n - 1) * (1.0 + c * rate), k * d**n * c
        return by_d * (-self.L * un) + by_rate * (-self.V * un_rate)

    def law_sign(self, g: np.ndarray, un: np.ndarray, j: np.ndarray) -> np.ndarray:
        """A function of the closed contacts ``j`` with the sign of their force laws.

        The factor that decides it, ``1 + c d'`` (Hunt-Crossley) or ``k d + c d'``, rather than
        a law that vanishes with the indentation.
        """
        rate = -self.V * un
        if self.model == "hunt_crossley":
            return 1.0 + self.c[j] * rate
        return self.k[j] * (-self.L * g) + self.c[j] * rate

    def stored(self, g: np.ndarray) -> np.ndarray:
        """Elastic energy of every contact's spring at the scaled gaps ``g``."""
        d = np.maximum(-self.L * g, 0.0)
        return self.k * d ** (self.n + 1) / (self.n + 1)

    def let_go(self, g: np.ndarray, un: np.ndarray) -> None:
        """Open, in place, every closed plastic contact whose indentation no longer grows.

        Its force drops to zero and the indentation it reached stays: the scaled gap is measured
        again from there, so a contact pushed in again loads its spring from zero.
        """
        turned = self.plastic & (g <= -self.band) & (un >= 0.0)
        g[turned] = 0.0

    def at_rest(self, g: np.ndarray, un: np.ndarray) -> bool:
        """Whether no contact acts and none approaches faster than ``tol`` V."""
        return bool((g > -self.band).all()) and bool((un >= -self.rest).all())

    def run(self) -> Outcome:
        """Integrate from first contact until no spring acts and no contact approaches."""
        problem, options = self.problem, self.options
        m = problem.m
        g, un, P = problem.gaps / self.L, problem.un / self.V, np.zeros(m)
        rtol = options["tol"]
        integrator = EventIntegrator(self.method, rtol, rtol * 1e-3)
        spend = current_budget()
        t, self.steps, events = 0.0, 0, 0
        self.peak = np.zeros(m)
        self.history: list[tuple[float, np.ndarray, np.ndarray]] = []
        # Gaps are never negative at the start: every contact is open.
        self._keep(t, g, np.zeros(m, dtype=bool), np.zeros(0))
        while True:
            self.let_go(g, un)
            if self.at_rest(g, un):
                break
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
            "formulation": f"time integration ({self.model}, {self.method})",
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

    def __init__(self, integration: Integration, closed: np.ndarray, near: np.ndarray) -> None:
        self.integration, self.closed, self.near = integration, np.flatnonzero(closed), near
        rows = np.flatnonzero(near)
        self.size = rows.size
        self.acting = np.searchsorted(rows, self.closed)
        # Scaled: the time is over tau, so the scaled force is the impulse rate over I / tau.
        self.scale = integration.scale
        self.G = for_products(integration.G[rows][:, self.closed].toarray())
        self.band = integration.band[rows]
        self.damped = integration.clipped and bool(integration.c[self.closed].any())
        self.plastic = integration.plastic[rows] & closed[rows]
        # A gap fires only as it passes its band away from its side: a closed contact (on its
        # band at the restart that closed it) opening, an open one closing; a closed plastic
        # contact's gap rate as it turns from approach to separation.
        self.direction = np.where(closed[rows], 1.0, -1.0)
        self.direction = np.concatenate([self.direction, np.ones(self.size)])
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
        """Gaps passing their bands, plastic contacts turning, clipped laws changing sign."""
        g, un, _ = self.split(y)
        parts = [g + self.band, np.where(self.plastic, un, -1.0)]
        if self.damped:
            c = self.integration.c[self.closed]
            sign = self.integration.law_sign(g[self.acting], un[self.acting], self.closed)
            parts.append(np.where(c > 0, sign, 1.0))
        return np.concatenate(parts)
