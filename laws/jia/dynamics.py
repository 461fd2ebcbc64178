"""Impulse dynamics of Jia's compliant contacts: normal springs, tangential springs.

Normal springs (Jia, Mason and Erdmann 2013; Jia 2013): contact i is a linear spring
of stiffness ``k_i`` whose strain energy ``E_i`` changes with its normal impulse ``I_i`` as
``dE_i/dI_i = -u_i`` (``u_i`` the gap rate, negative while the contact closes) and whose force is
``F_i = sqrt(2 k_i E_i)``. At every end of compression (``u_i`` turns positive while the spring
is loaded) the stiffness rises to ``k_i / e_i^2`` with the force unchanged, so ``E_i`` drops to
``e_i^2 E_i``: ``e_i`` is the energetic coefficient. The stiffness stays as it is when a contact
returns from restitution to compression, when its spring empties (the contact becomes inactive,
its impulse frozen) and when it is reactivated (its gap rate turns negative again).

Rigid contacts. With ``e_i = 0`` the stiffness becomes infinite at the end of compression. A
contact kept loaded by its neighbours can also end compression, empty, and be reactivated
again and again, its stiffness growing by ``1/e_i^2`` each time: the sequence of states is
infinite (Jia, Mason and Erdmann, Theorem 4) and tends to a rigid, plastic contact. A contact
that ends compression ``LOCK`` times stiffer (in ``k_i G_ii``, its squared frequency) than the
softest other loaded spring expands before the others move: holding a stored energy above the
tolerance, it gives it back at once (``e_i^2`` of it, the locked contacts holding their gap
rates) and separates; holding less, or with ``e_i = 0``, the contact locks: its gap rate is
held at zero by the impulse rate the other springs require (``G_LL dI_L = -G_LA dI_A``), its
remaining energy (below the tolerance) is lost, and it releases when that rate would turn
negative (the contact would pull); approached again, it locks again. So a stiff elastic
contact struck alone rebounds (three balls with ``k2/k1 = 1e-12``, e = 1: ``(0, 0, 1)``) and
one loaded slowly by its neighbours moves them as one (``k2/k1 = 1e12``: ``(-1/3, 2/3, 2/3)``).
The state sequence of such chains is sensitive: a near-simultaneous release or a grazing
reactivation can change the answer discontinuously with the tolerance (on random chains of
10 to 20 balls with e uniform in (0, 1), answers at tolerances 1e-10 to 1e-12 differed by up
to 2 % of the largest velocity on some chains and by less than 1e-8 on others).

Tangential springs (Jia 2013; at several contacts at once, Jia's talk of 2012, part III): at
each frictional contact a massless particle joined to the body by the normal spring and by
tangential springs of stiffness ``k'``, with ``eta0^2 = k_0 / k'`` (``k_0`` the contact's normal
stiffness in compression). Writing ``s`` for the stretch of the tangential springs,
``F_t = -k' s``. The particle sticks (``ds/dt = ut``) while the tangential strain energy
``E_t = k' |s|^2 / 2`` stays below ``mu^2 eta^2 E_n`` (``eta^2 = k / k'``, k the current normal
stiffness), which is Coulomb's ``|F_t| <= mu F_n``; otherwise it slips with ``|F_t| = mu F_n``
and ``s`` along the slip velocity ``ut - ds/dt``. Slip turns to stick when the slip velocity
vanishes, stick to slip when ``E_t`` reaches the bound. A contact starts (or, reactivated,
starts again) slipping when ``|ut| > mu eta0^2 |un|`` (the talk's appendix 1). The springs hold
no energy at the end (the bound vanishes with ``E_n``); a contact that separates releases its
tangential spring. After a plastic end of compression at a single contact, what its tangential
springs hold is lost with the impact's end. With friction at several contacts a contact that
turns rigid (e = 0, or the lock below) is not treated: the lock holds normal gap rates only.

Jia writes these equations in the normal impulse; they are 0/0 where ``E_n`` vanishes, at the
start and at the end. They are integrated here along ``tau = sqrt(2 k_ref) t``, with
``y_i = sqrt(E_i)``, ``kappa_i = k_i / k_ref`` (``kappa0_i`` in compression) and
``g_i = sqrt(2 k_ref) s_i`` (Jia's G), where they are regular (multiplied by ``dI_n/dtau``)::

    dI_i/dtau = sqrt(kappa_i) y_i          dy_i/dtau = -sqrt(kappa_i) u_i / 2
    stick: dI_t/dtau = -kappa0 g / (2 eta0^2)   dg/dtau = ut
    slip:  dI_t/dtau = -mu dI_n/dtau ghat       dg/dtau = rho ghat + ut - (ut . ghat) ghat

with ``rho = -mu eta0^2 kappa un / kappa0`` (the rate of ``|g|`` that keeps
``|F_t| = mu F_n``), ``E_t = kappa0 |g|^2 / (4 eta0^2)`` and the stick bound
``|g| <= 2 mu eta0^2 sqrt(kappa) y / kappa0``, each per contact. Every
transition is an event of the shared event integrator (`lawbench.numerics.integrator`, DOP853); the
contact velocity is affine in the impulses, ``u = u- + G [I_n, I_t]`` with ``G`` the contact
Delassus matrix.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from lawbench.core.errors import NotApplicable, SolverFailure
from lawbench.core.mechanics import for_products
from lawbench.numerics.integrator import EventIntegrator

# Gap rates above -min(max(ROUNDING, 100 tolerance), NOT_APPROACHING) |u-| count as not
# approaching: a grazing contact is not reactivated by the integration's noise, and at a loose
# tolerance a contact that approaches at more than 1 % of the largest speed still acts.
ROUNDING = 1e-12
NOT_APPROACHING = 1e-2
# A contact this much stiffer than the softest other loaded spring is rigid (see above).
LOCK = 1e6
# Transitions whose roots lie closer than this many natural periods are one instant: the
# roots of dependent gap rates agree to Brent's relative rounding, not exactly.
SIMULTANEOUS = 1e-9
# A segment with no event within this many natural periods does not end.
PERIODS = 1e4


@dataclass(frozen=True)
class Springs:
    """Spring parameters of the contacts.

    Attributes
    ----------
    kappa : array (m,)
        Normal stiffness of each contact over a common reference (only ratios matter).
    e : array (m,)
        Energetic restitution coefficients.
    mu : array (m,)
        Coulomb coefficients (0: no tangential spring acts).
    eta0_sq : array (m,)
        Jia's ratios ``eta0^2`` of normal (compression) to tangential stiffness.
    """

    kappa: np.ndarray
    e: np.ndarray
    mu: np.ndarray
    eta0_sq: np.ndarray


@dataclass
class Record:
    """What happened: events, state or mode sequence, solver steps, energies, path samples."""

    events: list[dict] = field(default_factory=list)
    sequence: list[str] = field(default_factory=list)
    steps: int = 0
    compression_loss: float = 0.0
    samples: list[np.ndarray] = field(default_factory=list)
    released: set[int] = field(default_factory=set)
    recompressed: list[int] = field(default_factory=list)


class SpringImpact:
    """Jia's springs from first touch until no contact is loaded and none approaches.

    Parameters
    ----------
    G : array (m + m d, m + m d)
        Contact Delassus matrix, the m normal rows first, then d tangential rows per contact
        (d = 0: frictionless).
    u_minus : array (m + d,)
        Pre-impact contact velocities.
    springs : Springs
        Stiffness ratios, restitution, friction.
    tolerance : float
        Relative tolerance of the integration.
    keep_path : bool
        Whether to sample the impulse curve.
    """

    def __init__(
        self,
        G: np.ndarray,
        u_minus: np.ndarray,
        springs: Springs,
        tolerance: float,
        keep_path: bool,
    ) -> None:
        self.G, self.u_minus, self.springs = G, u_minus, springs
        # Products with G at every stage: banded (sparse) for a long chain.
        self.G_products = for_products(G)
        self.m = len(springs.kappa)
        self.nt = G.shape[0] - self.m
        self.d = self.nt // self.m
        self.tolerance, self.keep_path = tolerance, keep_path
        self.kappa = springs.kappa.astype(float).copy()
        self.kappa0 = self.kappa.copy()
        self.rough = (springs.mu > 0) & (self.d > 0)
        # State layout: normal impulses, sqrt(E_n), tangential impulses, Jia's g.
        self.It = slice(2 * self.m, 2 * self.m + self.nt)
        self.g = slice(2 * self.m + self.nt, 2 * self.m + 2 * self.nt)
        threshold = min(max(ROUNDING, 100 * tolerance), NOT_APPROACHING)
        self.approach = threshold * float(np.abs(u_minus).max())
        self.active = u_minus[: self.m] < -self.approach
        self.compressing = self.active.copy()
        # Rigid contacts: locked (holding the gap rate), or rigid but released.
        self.rigid = np.zeros(self.m, dtype=bool)
        self.locked = np.zeros(self.m, dtype=bool)
        # An inactive contact is reactivated when its gap rate falls below its floor.
        self.floor = np.full(self.m, -self.approach)
        self.lock = np.zeros((0, self.m))
        self.record = Record()
        self.stick = np.ones(self.m, dtype=bool)
        self.direction = np.zeros((self.m, self.d))
        # The stick margin at which a contact began to stick, where rounding left it above 0 (a
        # spring held at its bound while slipping): its slip fires when the margin passes it.
        self.excess = np.zeros(self.m)
        for j in np.flatnonzero(self.active & self.rough):
            self._start_friction(j, u_minus)
        diag = np.diag(G)[: self.m] * self.kappa
        frequency = math.sqrt(float(diag.min()) / 2.0)
        if not frequency > 0.0:
            # A stiffness ratio of 5e-324 on a unit Delassus entry: a period beyond any double.
            raise NotApplicable(
                f"jia: the softest spring (stiffness ratio {self.kappa.min():.3g}) has a period "
                "beyond double precision"
            )
        self.time_scale = 2.0 * math.pi / frequency
        # The impulse that stops the fastest normal approach at the contact of the lightest
        # effective mass (largest G_jj): the smallest impulse scale of the problem, so that the
        # absolute tolerance resolves the impulses of a light body (a 1e-6 kg striker) and
        # those of a grazing approach under a fast slip (the friction impulse is at most mu
        # times the normal one), and the springs' states at that impulse.
        approach = float(np.abs(u_minus[: self.m]).max())
        impulse = approach / float(np.diag(G)[: self.m].max())
        rate = float(np.abs(u_minus).max())
        energy = math.sqrt(impulse * approach)
        # A spring's stretch never exceeds its stick bound, 2 mu eta0^2 y / sqrt(kappa0) at
        # most: the tolerance resolves it at that scale, so that as mu -> 0 the integration's
        # error in the stretch stays a fixed fraction of the bound and the stick margin keeps
        # its sign (at the scale of the slip distance it would be all rounding and the
        # contact would chatter between stick and slip).
        bound = 2.0 * springs.mu * springs.eta0_sq * energy / np.sqrt(self.kappa0)
        travel = rate * self.time_scale
        stretch = np.where(self.rough, np.minimum(bound, travel), travel)
        self.scale = np.concatenate(
            [
                np.full(self.m, impulse),
                np.full(self.m, energy),
                np.full(self.nt, impulse),
                np.repeat(stretch, self.d),
            ]
        )

    # --- the equations --------------------------------------------------------------------------

    def velocity(self, s: np.ndarray) -> np.ndarray:
        """Contact velocities at state ``s``."""
        impulses = np.concatenate([s[: self.m], s[self.It]])
        return self.u_minus + self.G_products @ impulses

    def _tangential(self, x: np.ndarray, j: int) -> np.ndarray:
        """Contact j's block of a tangential part (``d`` entries) of ``x``."""
        return x[j * self.d : (j + 1) * self.d]

    def _ghat(self, j: int, g: np.ndarray) -> np.ndarray:
        norm = np.linalg.norm(g)
        return g / norm if norm > 0 else self.direction[j]

    def _start_friction(self, j: int, u: np.ndarray) -> None:
        """Stick or slip as contact j starts: slip when ``|ut| > mu eta0^2 |un|``."""
        springs = self.springs
        ut = self._tangential(u[self.m :], j)
        speed = float(np.linalg.norm(ut))
        self.stick[j] = speed <= springs.mu[j] * springs.eta0_sq[j] * -u[j]
        if not self.stick[j]:
            self.direction[j] = ut / speed

    def _rho(self, j: int, u: np.ndarray) -> float:
        """Rate of ``|g_j|`` that keeps contact j's spring force at ``mu F_n`` while it slips."""
        springs = self.springs
        return -springs.mu[j] * springs.eta0_sq[j] * self.kappa[j] * u[j] / self.kappa0[j]

    def _rate(self, tau: float, s: np.ndarray) -> np.ndarray:
        m, springs = self.m, self.springs
        u = self.velocity(s)
        root = np.sqrt(self.kappa) * self.active
        rate = np.zeros_like(s)
        rate[:m] = root * s[m : 2 * m]
        rate[m : 2 * m] = -root * u[:m] / 2.0
        if self.locked.any():
            rate[:m][self.locked] = self.lock @ rate[:m]
        impulse_rate, g_rate = rate[self.It], rate[self.g]
        g_all, ut_all = s[self.g], u[m:]
        for j in np.flatnonzero(self.active & self.rough):
            g, ut = self._tangential(g_all, j), self._tangential(ut_all, j)
            rows = slice(j * self.d, (j + 1) * self.d)
            if self.stick[j]:
                impulse_rate[rows] = -self.kappa0[j] * g / (2.0 * springs.eta0_sq[j])
                g_rate[rows] = ut
            else:
                ghat = self._ghat(j, g)
                impulse_rate[rows] = -springs.mu[j] * rate[j] * ghat
                g_rate[rows] = self._rho(j, u) * ghat + ut - (ut @ ghat) * ghat
        return rate

    def _lock_map(self) -> np.ndarray:
        """Matrix (locked, m) from the springs' impulse rates to the locked contacts' ones.

        The locked rates keep the locked gap rates constant: ``G_LL dI_L = -G_LA dI_A``.
        """
        L, A = self.locked, self.active
        Gnn = self.G[: self.m, : self.m]
        lock = np.zeros((int(L.sum()), self.m))
        lock[:, A] = -np.linalg.lstsq(Gnn[np.ix_(L, L)], Gnn[np.ix_(L, A)], rcond=None)[0]
        return lock

    def _spring_rate(self, s: np.ndarray) -> np.ndarray:
        return np.sqrt(self.kappa) * self.active * s[self.m : 2 * self.m]

    def _stick_margin(self, j: int, s: np.ndarray) -> float:
        """``|g_j|`` minus its stick bound: positive once the spring force exceeds mu F_n."""
        springs = self.springs
        bound = 2.0 * springs.mu[j] * springs.eta0_sq[j] * math.sqrt(self.kappa[j]) * s[self.m + j]
        return float(np.linalg.norm(self._tangential(s[self.g], j))) - bound / self.kappa0[j]

    def _slip_speed(self, j: int, s: np.ndarray, u: np.ndarray) -> float:
        """Slip velocity along the spring: ``ut . ghat - d|g|/dtau``; zero when slip stops."""
        ghat = self._ghat(j, self._tangential(s[self.g], j))
        return float(self._tangential(u[self.m :], j) @ ghat) - self._rho(j, u)

    def _events(self) -> list[tuple[str, int, int]]:
        """The armed events ``(name, contact, direction)``.

        Each starts on its quiet side, so none fires at its own start.
        """
        armed: list[tuple[str, int, int]] = []
        for j in range(self.m):
            if self.locked[j]:
                armed.append(("release", j, -1))
            elif not self.active[j]:
                armed.append(("reactivation", j, -1))
            elif self.compressing[j]:
                armed.append(("end of compression", j, 1))
            else:
                armed.append(("recompression", j, -1))
                armed.append(("separation", j, -1))
        for j in np.flatnonzero(self.active & self.rough):
            armed.append(("slip", j, 1) if self.stick[j] else ("stick", j, -1))
        return armed

    def _event_functions(
        self, armed: list[tuple[str, int, int]]
    ) -> Callable[[float, np.ndarray], np.ndarray]:
        """The armed events' functions, evaluated together at a state.

        A gap rate (reactivation: below its floor; end of compression, recompression), a
        spring's deflection (separation), a locked contact's force (release), the stick margin
        or the slip speed: the contact velocities are computed once for all of them, so a long
        chain's step costs O(m) and not O(m^2).
        """
        names = [name for name, _, _ in armed]
        contacts = np.array([j for _, j, _ in armed], dtype=int)

        def at(*kinds: str) -> np.ndarray:
            return np.flatnonzero([name in kinds for name in names])

        rates = at("reactivation", "end of compression", "recompression")
        rate_of, floored = contacts[rates], np.array([names[i] == "reactivation" for i in rates])
        springs = at("separation")
        spring_of = self.m + contacts[springs]
        releases = at("release")
        release_rows = (np.cumsum(self.locked) - 1)[contacts[releases]]
        slip, stick = at("slip"), at("stick")

        def values(tau: float, s: np.ndarray) -> np.ndarray:
            u = self.velocity(s)
            out = np.empty(len(names))
            out[rates] = u[rate_of] - np.where(floored, self.floor[rate_of], 0.0)
            out[springs] = s[spring_of]
            if releases.size:
                out[releases] = self.lock[release_rows] @ self._spring_rate(s)
            for i in slip:
                out[i] = self._stick_margin(int(contacts[i]), s) - self.excess[contacts[i]]
            for i in stick:
                out[i] = self._slip_speed(int(contacts[i]), s, u)
            return out

        return values

    # --- the run --------------------------------------------------------------------------------

    def run(self) -> np.ndarray:
        """Integrate the impact; return the final state ``[I_n, y, I_t, g]``.

        Each transition is an event of the solve's budget (``max_events``), each integrator
        step a step (``max_steps``).
        """
        integrator = EventIntegrator(
            "DOP853",
            self.tolerance,
            self.tolerance * self.scale,
            simultaneous=SIMULTANEOUS * self.time_scale,
            past=False,
        )
        tau, s = 0.0, np.zeros(2 * (self.m + self.nt))
        self._note_state(tau, s, ["stick" if self.stick[0] else "slip"] if self.nt else [])
        while True:
            s = self._settle(tau, s)
            if not self.active.any():
                return s
            armed = self._events()
            if self.keep_path:
                self.record.samples.append(np.append(tau, s))
            event = integrator.to_event(
                self._rate,
                tau,
                s,
                self._event_functions(armed),
                np.array([direction for *_, direction in armed], dtype=float),
                x_end=tau + PERIODS * self.time_scale,
                on_step=self._on_step,
            )
            if not event.fired:
                raise SolverFailure(
                    f"jia: no contact event within {PERIODS:g} natural periods: the impact "
                    "does not end"
                )
            tau, s = event.x, event.y.copy()
            # Transitions that coincide are applied together, in the order of their roots:
            # contacts whose gap rates are dependent (two springs on one degree of freedom)
            # end compression at one instant, and the root of one leaves the others' functions
            # a rounding past their zeros, where their own events could no longer fire. One
            # that an earlier transition of the same instant disarmed is dropped; a spring
            # that empties with them, a contact that then approaches or a lock that then pulls
            # is settled at the restart.
            fired = []
            for name, j, direction in (armed[i] for i in event.fired):
                if (name, j, direction) in self._events():
                    s = self._apply(name, j, s)
                    fired.append(name)
            self._note_state(tau, s, fired)

    def _on_step(self, dense: Callable[[float], np.ndarray], tau_old: float, tau: float) -> None:
        self.record.steps += 1
        if self.keep_path:
            self.record.samples.append(np.append(tau, dense(tau)))

    def _settle(self, tau: float, s: np.ndarray) -> np.ndarray:
        """Stop finished slips, empty springs, reactivate contacts, release pulling locks.

        A transition of another kind can leave a state past an event's zero, where its own event
        cannot fire: a slip whose speed the end of a compression (a stiffer spring) turned
        negative, a spring that empties at the instant of another event.
        """
        u = self.velocity(s)
        for j in np.flatnonzero(self.active & self.rough & ~self.stick):
            if self._slip_speed(int(j), s, u) < 0.0:
                s = self._apply("stick", int(j), s)
                self._note_state(tau, s, ["stick"])
        expanding = self.active & ~self.compressing
        emptied = expanding & (s[self.m : 2 * self.m] <= ROUNDING * self.scale[self.m])
        for j in np.flatnonzero(emptied):
            s = self._apply("separation", int(j), s)
        approaching = ~self.active & ~self.locked
        approaching &= self.velocity(s)[: self.m] < self.floor
        for j in np.flatnonzero(approaching):
            s = self._apply("reactivation", int(j), s)
        for _ in range(self.m + 1):
            self.lock = self._lock_map()
            if not self.locked.any():
                break
            spring_rate = self._spring_rate(s)
            rates = self.lock @ spring_rate
            if rates.min() >= -ROUNDING * float(np.abs(spring_rate).max(initial=0.0)):
                break
            s = self._apply("release", int(np.flatnonzero(self.locked)[np.argmin(rates)]), s)
        return s

    def _stiffest_ratio(self, j: int) -> float:
        """Squared frequency of contact j over that of the softest other loaded spring."""
        frequency = self.kappa * np.diag(self.G)[: self.m]
        others = self.active.copy()
        others[j] = False
        return float(frequency[j] / frequency[others].min()) if others.any() else 0.0

    def _apply(self, name: str, j: int, s: np.ndarray) -> np.ndarray:
        """Change the contact state for the event ``name`` at contact ``j``."""
        m, y = self.m, s[self.m + j]
        if name == "end of compression":
            e = self.springs.e[j]
            self.compressing[j] = False
            if e > 0:
                self.kappa[j] /= e * e
            stiff = self._stiffest_ratio(j) > LOCK
            negligible = y * y <= self.tolerance * self.scale[m] ** 2
            direction, compliance = self._expansion(j) if stiff else (None, 0.0)
            # A stiff spring whose expansion the locked contacts hold entirely (they share its
            # degree of freedom: the compliance along the expansion vanishes) cannot give its
            # energy back to the bodies before the others move: it locks with them.
            negligible |= stiff and compliance <= ROUNDING * float(self.G[j, j])
            if (e == 0 or stiff) and self.rough.any() and m > 1:
                raise NotApplicable(
                    f"jia: contact {j} turns rigid (e = 0, or {LOCK:g} times stiffer than the "
                    "softest other loaded spring) with friction at several contacts; the rigid "
                    "lock holds normal gap rates only"
                )
            if e == 0 or (stiff and negligible):
                self.record.compression_loss += float(y * y)
                self.active[j], self.rigid[j], self.locked[j], s[m + j] = False, True, True, 0.0
                return s
            self.record.compression_loss += float((1.0 - e * e) * y * y)
            s[m + j] = e * y
            if stiff:
                # The expansion is over before the softer springs move: the spring alone, with
                # the locked contacts holding their gap rates, gives back E = (e y)^2 to the
                # bodies through the impulse direction dI, an impulse e y sqrt(2 / dI.G.dI).
                s[:m] += direction * (e * y * math.sqrt(2.0 / compliance))
                s = self._apply("separation", j, s)
        elif name == "recompression":
            self.compressing[j] = True
        elif name == "separation":
            self.active[j], self.compressing[j], s[m + j] = False, False, 0.0
            # The contact releases its tangential spring.
            self._tangential(s[self.g], j)[:] = 0.0
            self.record.released.add(j)
        elif name == "release":
            self.record.released.add(j)
            # Held at its gap rate, it may sit at the threshold: reactivate only below it.
            self.locked[j] = False
            self.floor[j] = min(float(self.velocity(s)[j]), 0.0) - self.approach
        elif name == "reactivation":
            self.floor[j] = -self.approach
            if j in self.record.released and j not in self.record.recompressed:
                self.record.recompressed.append(j)
            if self.rigid[j]:
                self.locked[j] = True
            else:
                self.active[j], self.compressing[j] = True, True
                if self.rough[j]:
                    self._start_friction(j, self.velocity(s))
        elif name == "slip":
            self.stick[j] = False
            self.direction[j] = self._ghat(j, self._tangential(s[self.g], j))
        else:
            self.stick[j] = True
            # The slip function starts below its zero by the integration's error in the
            # stretch, so that rounding cannot fire it at once.
            allowance = self.tolerance * self.scale[self.g][j * self.d]
            self.excess[j] = max(self._stick_margin(j, s) + allowance, 0.0)
        return s

    def _expansion(self, j: int) -> tuple[np.ndarray, float]:
        """Contact j's expansion alone: its impulse direction and the compliance along it.

        The locked contacts hold their gap rates; the compliance is ``dI.G.dI``.
        """
        direction = np.zeros(self.m)
        direction[j] = 1.0
        if self.locked.any():
            self.lock = self._lock_map()
            direction[self.locked] = self.lock @ direction
        return direction, float(direction @ self.G[: self.m, : self.m] @ direction)

    def _note_state(self, tau: float, s: np.ndarray, fired: list[str]) -> None:
        """Record the events at ``tau`` and the state (several contacts) or mode that follows."""
        self.record.events.append({"tau": tau, "events": fired, "Pn": s[: self.m].tolist()})
        if self.m > 1 or not self.nt:
            active = [str(j) for j in np.flatnonzero(self.active)]
            active += [f"{j} locked" for j in np.flatnonzero(self.locked)]
            labels = ["{" + ", ".join(active) + "}" if self.active.any() else "end of impact"]
        else:
            labels = [_PHASE_NAMES.get(name, name) for name in fired]
            if not self.active[0]:
                labels = [*(x for x in labels if x not in ("stick", "slip")), "end of impact"]
        for label in labels:
            if not self.record.sequence or self.record.sequence[-1] != label:
                self.record.sequence.append(label)


_PHASE_NAMES = {"separation": "end of impact"}
