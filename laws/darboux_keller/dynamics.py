"""Impulse-time (Darboux-Keller) dynamics of one frictional contact, the normal impulse as clock.

At one contact with contact Delassus matrix ``G`` ((1 + d) x (1 + d), normal row first) the
contact velocity ``u = (un, ut)`` obeys ``du/dPn = G [1, dPt/dPn]``. A *phase* fixes the ratio
``r = dPt/dPn``:

- slip: ``r = -mu ut / |ut|`` (Coulomb at the force level);
- stick (``ut = 0`` kept): ``r = -Gtt^+ Gtn``, possible when ``|Gtt^+ Gtn| <= mu``;
- slip from rest when sticking is impossible: the direction ``s`` with ``(mu Gtt + k I) s = Gtn``,
  ``k > 0``, along which ``ut`` grows (``dut/dPn = k s``). Planar: ``s = sign(Gtn)``.

With a constant ``r`` the velocities are affine and the normal work ``W = int un dPn`` quadratic
in ``Pn``, so every event (slip stop, end of compression, termination) is a closed-form root.
Stick and slip from rest keep their ``r`` for the rest of the impact; planar slip with
``ut != 0`` is affine too, and so is spatial slip whose rate ``Gtn - mu Gtt ut/|ut|`` lies along
``ut`` (a sphere, or slip in a plane of symmetry). Other spatial slip turns its direction
(Brogliato 2010, eq. 15): it is integrated with the shared event integrator
(`lawbench.numerics.integrator`) until it stops, the impact ends, or the slip speed falls below a
threshold proportional to ``rtol``, where sticking or slip in a fixed direction (Darboux's
proposition) takes over exactly. Its clock is ``tau`` with
``dPn = |ut| dtau``, which makes the right-hand side smooth; near the stop the slip direction
relaxes much faster than the slip decays (stiff), hence the implicit Radau method with the
exact Jacobian.

A phase whose generalized impulse vanishes (``W [1, r] = 0``, so ``dun/dPn = 0``) in restitution
ends the impact: the impulse no longer moves anything (the lamina stuck on the anvil).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np
import scipy.optimize

from lawbench.core.errors import NotApplicable, SolverFailure
from lawbench.numerics.integrator import EventIntegrator

# Velocity-like quantities below this fraction of |u-| are zero; impulses likewise.
ROUNDING = 1e-12
# Two events closer than this fraction of the impulse happen together.
SIMULTANEOUS = 1e-10
SAMPLES = 17
MAX_PHASES = 12
# An impact whose impulse exceeds this many frictionless compression impulses does not end.
IMPULSE_BOUND = 1e8
# The order of the events of turning slip (`SingleContactImpact._events`).
SLIP_STOPS, BOUND = 0, 1


@dataclass(frozen=True)
class State:
    """Impulses, contact velocity and normal work at a point of the impact."""

    P: float
    Pt: np.ndarray
    u: np.ndarray
    W: float

    def advanced(self, r: np.ndarray, g: np.ndarray, x: float) -> State:
        """The state after ``x`` more normal impulse with ``dPt/dPn = r``, ``du/dPn = g``."""
        return State(
            self.P + x, self.Pt + r * x, self.u + g * x, self.W + self.u[0] * x + g[0] * x * x / 2
        )


@dataclass
class ImpactRecord:
    """What happened along the impact: phases, compression, path samples, ODE steps."""

    phases: list[str] = field(default_factory=list)
    phase_impulses: list[float] = field(default_factory=list)
    current: str | None = None
    compression: State | None = None
    steps: int = 0
    samples: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = field(
        default_factory=list
    )

    def enter(self, phase: str, P: float) -> None:
        """Note the phase in force from ``P`` when it differs from the current one."""
        if phase != self.current:
            self.event(phase, P)
            self.current = phase

    def event(self, name: str, P: float) -> None:
        """Note an event at normal impulse ``P``."""
        self.phases.append(name)
        self.phase_impulses.append(float(P))

    def sample(self, P: np.ndarray, Pt: np.ndarray, u: np.ndarray, W: np.ndarray) -> None:
        """Keep path points: impulses (k,), (k, d), velocities (k, 1 + d), work (k,)."""
        self.samples.append((P, Pt, u, W))


class SingleContactImpact:
    """The impulse-time dynamics of one contact, from first touch to the chosen termination.

    Parameters
    ----------
    G : array (1 + d, 1 + d)
        Contact Delassus matrix, normal row and column first.
    u_minus : array (1 + d,)
        Pre-impact contact velocity ``(un, ut)`` with ``un < 0``.
    mu : float
        Coulomb coefficient (0: frictionless).
    termination : str
        'newton', 'poisson' or 'energetic'.
    e : float
        The coefficient of that termination.
    rtol : float
        Relative tolerance of the ODE of spatial slip.
    """

    def __init__(
        self, G: np.ndarray, u_minus: np.ndarray, mu: float, termination: str, e: float, rtol: float
    ) -> None:
        self.G, self.u_minus, self.mu = G, u_minus, mu
        self.d = G.shape[0] - 1
        self.termination, self.e, self.rtol = termination, e, rtol
        self.speed = float(np.linalg.norm(u_minus))
        self.impulse_scale = -u_minus[0] / G[0, 0]
        self.slope_zero = ROUNDING * float(np.abs(G).max()) * (1.0 + mu)
        # Turning slip slower than this has stopped: what is left of it moves the impulses by
        # about rtol / 100 relative.
        self.slip_floor = 1e-2 * rtol * self.speed
        # Contact velocities below this are zero: rounding, or what the ODE resolves once used.
        self.velocity_zero = ROUNDING * self.speed
        self.record = ImpactRecord()
        self.final: State | None = None

    def run(self) -> State:
        """Integrate the impact; return the final state (``record`` holds the rest)."""
        state = State(0.0, np.zeros(self.d), self.u_minus.astype(float), 0.0)
        if self.d == 2 and self.mu > 0 and self._turns(state.u[1:]):
            state = self._turning_slip(state)
            if self.final is not None:
                return self.final
            self.velocity_zero = max(self.velocity_zero, self.rtol * self.speed)
        for _ in range(MAX_PHASES):
            state = self._affine_phase(state)
            if self.final is not None:
                return self.final
        raise SolverFailure(f"darboux_keller: the impact did not end within {MAX_PHASES} phases")

    def _turns(self, ut: np.ndarray) -> bool:
        """Whether spatial slip at ``ut`` turns: its rate is not along ``ut``."""
        speed = np.linalg.norm(ut)
        if speed <= self.slip_floor:
            return False
        direction = ut / speed
        rate = self.G[1:, 0] - self.mu * self.G[1:, 1:] @ direction
        cross = direction[0] * rate[1] - direction[1] * rate[0]
        return abs(cross) > ROUNDING * float(np.abs(self.G).max()) * (1.0 + self.mu)

    # --- phases with a constant impulse ratio -------------------------------------------------

    def _phase(self, state: State) -> tuple[str, np.ndarray, float]:
        """Name, ratio ``r`` and slip-stop distance (inf: the phase lasts) at ``state``."""
        if self.mu == 0 or self.d == 0:
            return "frictionless", np.zeros(self.d), math.inf
        ut, Gtn, Gtt = state.u[1:], self.G[1:, 0], self.G[1:, 1:]
        if np.linalg.norm(ut) > self.velocity_zero:
            # Planar slip, or spatial slip in a fixed direction (from rest, or along its rate).
            direction = ut / np.linalg.norm(ut)
            r = -self.mu * direction
            rate = float(direction @ (Gtn + Gtt @ r))
            stop = -float(np.linalg.norm(ut)) / rate if rate < 0 else math.inf
            return self.record.current or "slip", r, stop
        stick = -np.linalg.lstsq(Gtt, Gtn, rcond=None)[0]
        if np.linalg.norm(stick) <= self.mu * (1 + ROUNDING):
            return "stick", stick, math.inf
        direction = _slip_from_rest(Gtt, Gtn, self.mu)
        if self.d == 2:
            name = "slip (fixed direction)"
        else:
            earlier = [p for p in self.record.phases if p in ("slip", "slip reversal")]
            name = "slip reversal" if earlier else "slip"
        return name, -self.mu * direction, math.inf

    def _affine_phase(self, state: State) -> State:
        """Advance through one phase to its first event (``final`` set once the impact ends)."""
        name, r, stop = self._phase(state)
        self.record.enter(name, state.P)
        g = self.G[:, 0] + self.G[:, 1:] @ r
        if self.record.compression is None:
            if g[0] <= self.slope_zero and stop == math.inf:
                if -state.u[0] <= self.velocity_zero:
                    # A singular Delassus matrix: un vanishes with ut, up to the ODE's error.
                    return self._end_compression(state)
                raise NotApplicable(
                    "darboux_keller: compression never ends (the normal velocity stops "
                    f"growing in phase {name!r} before it vanishes)"
                )
            end = -state.u[0] / g[0] if g[0] > self.slope_zero else math.inf
        elif g[0] <= self.slope_zero and stop == math.inf:
            return self._finish(state, "end of impact (no expansion)")
        else:
            end = self._to_termination(state, g[0])
        x = min(stop, end)
        if not math.isfinite(x):
            raise NotApplicable(f"darboux_keller: phase {name!r} never ends")
        self._sample_affine(state, r, g, x)
        state = state.advanced(r, g, x)
        near = x * (1 + SIMULTANEOUS) + ROUNDING * self.impulse_scale
        if stop <= near:
            state = replace(state, u=np.concatenate([state.u[:1], np.zeros(self.d)]))
        if end <= near:
            if self.record.compression is not None:
                return self._finish(state, "end of impact")
            state = self._end_compression(state)
        return state

    def _to_termination(self, state: State, slope: float) -> float:
        """Normal impulse still to apply before the termination, at normal slope ``slope``."""
        c, un = self.record.compression, state.u[0]
        if self.termination == "poisson":
            return max((1 + self.e) * c.P - state.P, 0.0)
        if self.termination == "newton":
            target = -self.e * self.u_minus[0] - un
            if target <= 0:
                return 0.0
            return target / slope if slope > self.slope_zero else math.inf
        remaining = -(self.e**2) * c.W - (state.W - c.W)
        if remaining <= 0:
            return 0.0
        discriminant = un * un + 2 * slope * remaining
        if discriminant < 0 or un + math.sqrt(discriminant) <= 0:
            return math.inf
        # The positive root of un x + slope x^2 / 2 = remaining, without cancellation.
        return 2 * remaining / (un + math.sqrt(discriminant))

    def _end_compression(self, state: State) -> State:
        state = replace(state, u=np.concatenate([[0.0], state.u[1:]]))
        self.record.compression = state
        self.record.event("end of compression", state.P)
        return state

    def _finish(self, state: State, event: str) -> State:
        self.record.event(event, state.P)
        self.final = state
        return state

    def _sample_affine(self, state: State, r: np.ndarray, g: np.ndarray, x: float) -> None:
        s = np.linspace(0.0, x, SAMPLES)
        self.record.sample(
            state.P + s,
            state.Pt + np.outer(s, r),
            state.u + np.outer(s, g),
            state.W + state.u[0] * s + g[0] * s * s / 2,
        )

    # --- spatial slip whose direction turns ---------------------------------------------------

    def _velocity(self, P: float, Pt: np.ndarray) -> np.ndarray:
        return self.u_minus + self.G[:, 0] * P + self.G[:, 1:] @ Pt

    def _turning_slip(self, state: State) -> State:
        """Integrate slip with a turning direction to where it stops or the impact ends.

        The clock is ``tau`` with ``dPn = |ut| dtau``: ``dut/dtau = |ut| Gtn - mu Gtt ut`` is
        smooth, and ``ut = 0`` is a rest point the integrator cannot step across (in ``Pn`` the
        direction ``ut/|ut|`` jumps there and explicit steps chatter about zero).
        """
        self.record.enter("slip", 0.0)
        for _ in range(MAX_PHASES):
            if self.record.compression is not None and self._reached(state):
                return self._finish(state, "end of impact")
            # The work is integrated from 0 on each stretch, to the accuracy its termination
            # needs: the energetic one compares it with e^2 times the compression's.
            c = self.record.compression
            if c is None:
                work = -self.impulse_scale * self.u_minus[0] / 2
            elif self.termination == "energetic":
                work = -max(self.e**2, ROUNDING) * c.W
            else:
                work = -c.W
            scale = np.array([self.impulse_scale] * 3 + [work])
            integrator = EventIntegrator("Radau", self.rtol, self.rtol * scale)
            points = [np.concatenate([[state.P], state.Pt, [0.0]])]
            event = integrator.to_event(
                self._slip_rate,
                0.0,
                points[0],
                partial(_values, self._events(state.W)),
                np.array([-1.0, 1.0, 1.0]),
                x_end=IMPULSE_BOUND * self.impulse_scale / self.slip_floor,
                jac=self._slip_jacobian,
                on_step=partial(_keep_end, points),
            )
            self.record.steps += len(points) - 1
            y = np.array(points)
            P, Pt, W = y[:, 0], y[:, 1:3], state.W + y[:, 3]
            u = self.u_minus + np.outer(P, self.G[:, 0]) + Pt @ self.G[:, 1:].T
            self.record.sample(P, Pt, u, W)
            state = State(float(P[-1]), Pt[-1], u[-1], float(W[-1]))
            if not event.fired or event.fired[0] == BOUND:
                raise SolverFailure(
                    f"darboux_keller: slip goes on past {IMPULSE_BOUND:g} times the "
                    "frictionless compression impulse"
                )
            if event.fired[0] == SLIP_STOPS:
                return state
            if self.record.compression is not None:
                return self._finish(state, "end of impact")
            state = self._end_compression(state)
        raise SolverFailure("darboux_keller: the turning slip did not end")

    def _slip_rate(self, tau: float, y: np.ndarray) -> np.ndarray:
        u = self._velocity(y[0], y[1:3])
        speed = np.linalg.norm(u[1:])
        return np.concatenate([[speed], -self.mu * u[1:], [u[0] * speed]])

    def _slip_jacobian(self, tau: float, y: np.ndarray) -> np.ndarray:
        u = self._velocity(y[0], y[1:3])
        speed = np.linalg.norm(u[1:])
        direction = u[1:] / speed if speed > 0 else np.zeros(2)
        d_speed = direction @ self.G[1:]
        jacobian = np.zeros((4, 4))
        jacobian[0, :3] = d_speed
        jacobian[1:3, :3] = -self.mu * self.G[1:]
        jacobian[3, :3] = speed * self.G[0] + u[0] * d_speed
        return jacobian

    def _events(self, work: float) -> list[Callable[[float, np.ndarray], float]]:
        """Slip stop (falling), impulse bound, then end of compression or the termination.

        ``work`` is the normal work at the start of the stretch, where ``y[3]`` starts from 0.
        """
        c = self.record.compression

        def slip_stops(tau: float, y: np.ndarray) -> float:
            return float(np.linalg.norm(self._velocity(y[0], y[1:3])[1:])) - self.slip_floor

        def bound(tau: float, y: np.ndarray) -> float:
            return float(y[0]) - IMPULSE_BOUND * self.impulse_scale

        def normal(tau: float, y: np.ndarray) -> float:
            return float(self._velocity(y[0], y[1:3])[0])

        def newton(tau: float, y: np.ndarray) -> float:
            return normal(tau, y) + self.e * self.u_minus[0]

        def poisson(tau: float, y: np.ndarray) -> float:
            return float(y[0]) - (1 + self.e) * c.P

        def energetic(tau: float, y: np.ndarray) -> float:
            return float(y[3]) - (1 - self.e**2) * c.W + work

        last = (
            normal
            if c is None
            else {"newton": newton, "poisson": poisson}.get(self.termination, energetic)
        )
        return [slip_stops, bound, last]

    def _reached(self, state: State) -> bool:
        """Whether the termination holds at ``state`` (compression over)."""
        return self._to_termination(state, 0.0) == 0.0


def _slip_from_rest(Gtt: np.ndarray, Gtn: np.ndarray, mu: float) -> np.ndarray:
    """Unit direction ``s`` of the slip growing from rest: ``(mu Gtt + k I) s = Gtn``, ``k > 0``."""
    if Gtt.shape[0] == 1:
        return np.sign(Gtn)
    lam, Q = np.linalg.eigh(Gtt)
    c = Q.T @ Gtn
    keep = np.abs(c) > ROUNDING * np.linalg.norm(c)
    lam, c, Q = lam[keep], c[keep], Q[:, keep]

    def excess(k: float) -> float:
        return float(np.sum((c / (mu * lam + k)) ** 2) - 1.0)

    k = scipy.optimize.brentq(excess, 0.0, float(np.linalg.norm(c)), xtol=1e-300, rtol=1e-15)
    s = Q @ (c / (mu * lam + k))
    return s / np.linalg.norm(s)


def path_arrays(record: ImpactRecord) -> dict[str, np.ndarray]:
    """The samples of ``record`` joined: Pn, Pt (k, d), un, ut (k, d), Wn."""
    P, Pt, u, W = (np.concatenate(parts) for parts in zip(*record.samples, strict=True))
    return {"Pn": P, "Pt": Pt, "un": u[:, 0], "ut": u[:, 1:], "Wn": W}


def _values(
    functions: list[Callable[[float, np.ndarray], float]], tau: float, y: np.ndarray
) -> np.ndarray:
    """The event functions at ``(tau, y)``."""
    return np.array([function(tau, y) for function in functions])


def _keep_end(points: list[np.ndarray], dense: Callable, tau_old: float, tau: float) -> None:
    """Keep the state at the end of each step."""
    points.append(dense(tau))
