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

Numerics: scipy's ``solve_ivp`` (DOP853 by default) in scaled variables (velocities over the
largest approach speed V, lengths over the largest static indentation scale, time over their
ratio), restarted at every event where a force law changes branch (a contact closes, opens,
or its force crosses zero), so the right-hand side is smooth between restarts. The impact ends
when every contact is open and none approaches. The accuracy knob is ``tol`` (atol = tol
times 1e-3 in scaled units). Order of convergence: the error of ``v_plus`` against a
tight-tolerance reference falls in proportion to tol (slope 1 in log-log; on the three-ball
chain it stays between 0.01 and 0.2 times tol from 1e-3 to 1e-10, tested), while DOP853's
step count grows only as about tol^(-1/8). Budgets: ``max_steps`` solver steps and
``max_events`` restarts and ``max_seconds`` of wall-clock time, each raising `SolverFailure`
naming what ran out.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.optimize

from lawbench.claims import keeps_energy, never_creates_energy
from lawbench.errors import NotApplicable
from lawbench.integrator import EventIntegrator
from lawbench.law import LAWS, Law
from lawbench.mechanics import for_products
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem
from lawbench.spec import Spec
from lawbench.tags import Tags

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
    """One compliant impact: scaled state ``[gaps/L, v/V, impulses/I]`` integrated step by step."""

    def __init__(self, problem: ImpactProblem, options: dict[str, Any]) -> None:
        self.problem, self.options = problem, options
        self.model = options["model"]
        contacts = problem.contacts
        self.k = np.array([c.stiffness for c in contacts])
        self.n = (
            np.ones(problem.m)
            if self.model == "kelvin_voigt"
            else np.array([c.exponent for c in contacts])
        )
        self.e = problem.restitution("newton")
        self.given_damping = np.array([c.damping for c in contacts])
        self.WnT = for_products(problem.Wn.T)
        G = np.diag(problem.delassus)
        self.V = float(max(np.abs(problem.un).max(), 1e-300))
        indentation = ((self.n + 1) * self.V**2 / (2 * self.k * G)) ** (1 / (self.n + 1))
        self.L = float(indentation.min())
        self.tau = self.L / self.V
        self.I = self.V / float(G.max())
        # Scaled velocity change per newton of each contact force: (tau / V) M^-1 Wn.
        self.B = for_products((self.tau / self.V) * problem.solve_mass(problem.Wn))
        self.clipped = not (self.model == "kelvin_voigt" and options["termination"] == "gap")
        self.c = self._initial_damping(G)

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

    # Forces, in newtons, from physical gaps and gap rates.
    def forces(self, g: np.ndarray, un: np.ndarray) -> np.ndarray:
        d, rate = -g, -un
        if self.model == "kelvin_voigt":
            law = np.where(d > 0, self.k * d + self.c * rate, 0.0)
        else:
            # Zero where the contact is open (0^n = 0): the powers need no mask.
            dn = np.maximum(d, 0.0) ** self.n
            if self.model == "hertz":
                damper = np.where(d > 0, np.abs(d) ** (self.n - 1), 0.0)
                law = self.k * dn + self.c * damper * rate
            else:
                law = self.k * dn * (1.0 + self.c * rate)
        return np.maximum(law, 0.0) if self.clipped else law

    def switches(self, g: np.ndarray, un: np.ndarray) -> np.ndarray:
        """Functions whose zeros are the branch changes: the gaps, and the dashpot signs."""
        if not self.clipped or not self.c.any():
            return g
        rate = -un
        if self.model == "hunt_crossley":
            sign = 1.0 + self.c * rate
        else:
            sign = self.k * (-g) + self.c * rate
        return np.concatenate([g, np.where(self.c > 0, sign, 1.0)])

    def physical(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        m = self.problem.m
        g, v = self.L * y[:m], self.V * y[m : m + self.problem.n]
        return g, v, self.WnT @ v

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        g, _, un = self.physical(y)
        F = self.forces(g, un)
        return np.concatenate([un / self.V, self.B @ F, (self.tau / self.I) * F])

    def ended(self, y: np.ndarray) -> bool:
        g, _, un = self.physical(y)
        return not self.forces(g, un).any() and bool((un >= -1e-12 * self.V).all())

    def run(self) -> Outcome:
        problem, options = self.problem, self.options
        m, n = problem.m, problem.n
        y = np.concatenate([problem.gaps / self.L, problem.v / self.V, np.zeros(m)])
        rtol = options["tol"]
        integrator = EventIntegrator(options["method"], rtol, rtol * 1e-3)
        t, self.steps, events = 0.0, 0, 0
        self.peak = np.zeros(m)
        self.history: list[tuple[float, np.ndarray]] = [(0.0, y)]
        while not self.ended(y):
            event = integrator.to_event(self.rhs, t, y, self._switches, on_step=self._on_step)
            t, y, events = event.x, event.y, events + 1
        diagnostics = {
            "formulation": f"time integration ({self.model}, {options['method']})",
            "duration_s": t * self.tau,
            "peak_force": self.peak.tolist(),
            "damping": self.c.tolist(),
            "steps": self.steps,
            "events": events,
        }
        path = self._path(self.history) if options["path"] else None
        return Outcome.from_velocity(
            problem, self.V * y[m : m + n], self.I * y[m + n :], diagnostics=diagnostics, path=path
        )

    def _switches(self, t: float, y: np.ndarray) -> np.ndarray:
        return self.switches(*self.physical(y)[::2])

    def _on_step(self, dense: Callable[[float], np.ndarray], t_old: float, t: float) -> None:
        """Count the step, keep the peak forces (four points) and the path's point."""
        self.steps += 1
        for s in np.linspace(t_old, t, 5)[1:]:
            self.peak = np.maximum(self.peak, self.forces(*self.physical(dense(s))[::2]))
        if self.options["path"]:
            self.history.append((t, dense(t)))

    def _path(self, history: list[tuple[float, np.ndarray]]) -> dict[str, np.ndarray]:
        times = np.array([t for t, _ in history]) * self.tau
        forces, stored = [], []
        for _, y in history:
            g, _, un = self.physical(y)
            d = np.maximum(-g, 0.0)
            forces.append(self.forces(g, un))
            stored.append(self.k * d ** (self.n + 1) / (self.n + 1))
        return {"t": times, "force": np.array(forces), "stored_energy": np.array(stored)}
