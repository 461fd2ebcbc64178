"""Compliant contacts with friction: a tangential spring in series with a Coulomb slider.

Each closed contact j carries, besides its normal force law, a tangential spring of stretch
``s_j`` (d components: 1 planar, 2 spatial) in series with a Coulomb slider. The spring pulls
the bodies' contact points back, ``Ft_j = -kt_j s_j``. The slider holds while
``|Ft_j| < mu_j Fn_j`` (stick: ``s_j' = ut_j``) and slides otherwise: the stretch is held on the
cone ``|s_j| = r_j = mu_j Fn_j / kt_j``, the friction force is ``-mu_j Fn_j`` along the
stretch's direction ``n_j = s_j / |s_j|``, and ``s_j' = ut_j - lam_j n_j`` with the slip speed
``lam_j = n_j . ut_j - r_j' >= 0``. In 3D the stretch's direction, so the friction's, turns
toward the slip. A contact slides from where its stretch reaches the cone until ``lam_j``
falls to zero, and a contact that opens releases its spring.

Energy: the springs are conservative, the slider's power ``-lam_j mu_j Fn_j`` is never
positive and a dashpot only takes energy, so the contacts never create energy; without damping
and without slip they keep it.

Tangential stiffness: the normal one over the contact's ``tangential_stiffness_ratio``
``eta0^2`` (Mindlin's 17/14 when None), as in Jia's model: ``kt = k / eta0^2`` for a linear
contact, exactly the springs Jia integrates in impulse space. For a Hertz contact (exponent
``n``) Mindlin's no-slip solution fixes the ratio of the tangent stiffnesses, and the normal
tangent stiffness ``n K d^(n-1)`` grows with the indentation ``d``. A tangential spring that
follows it either creates energy as the contact unloads (its force updated by increments) or
needs the normal force ``kt'(d) |s|^2 / 2`` of its energy, with which the slip law is ill-posed
(the cone grows faster than the stretch that pushes on it) once
``mu^2 eta0^2 (n - 1) / n > 1``. So the stiffness is Mindlin's at the contact's indentation
scale ``d*`` (where its spring holds the kinetic energy of its effective mass at the largest
approach speed: the order of the peak indentation), ``kt = n K d*^(n-1) / eta0^2``, constant
through the impact: conservative, and Jia's for ``n = 1``.

Numerics: the state is integrated in contact space, ``g' = un``, ``s' = ut - slip``, ``u' = G F``,
``P' = F``, with ``G`` the Delassus matrix of the normal and tangential directions, every contact at
once (frictional scenes hold a few contacts), in the scaled variables of the frictionless
integration, and restarted at every event: a contact closing or opening, a damped force crossing
zero, a stretch reaching the cone, a slip stopping (the events are looked for at four points of
every step, so a slip that stops and starts again within one step is met). In 3D a sliding stretch
turns toward the slip at the rate ``|ut_perp| / |s|``, without bound as the cone closes with the
normal force at the start and the end of every contact, where an explicit integrator would need ever
shorter steps. On a cone narrower than ``tol^(1/2)`` (scaled by ``L``; tol taken at most 1e-4,
looser the switches chattered) the friction force follows the slip velocity instead: the limit of
the spring and slider as the stretch vanishes, its lag behind the slip dropped while the force is
below ``kt L tol^(1/2)``. Against the integration that follows the stretch throughout (Radau at tol
= 1e-11) the outcomes of the billiard's massé shot, the sphere on a wall, the pencil and the skewed
bouncing ball moved by at most 1e-9 at tol = 1e-10, for five to twenty times fewer steps. A contact
loaded so lightly that its cone stays just wider than that for the whole impact still turns stiffly
(a billiard shot with the ball pressed on the cloth at 8 mm/s: DOP853 did not finish in 60 s), so
with spatial friction ``method='auto'`` takes LSODA, which turns to implicit steps where the field
is stiff (that shot in 1.8 s; elsewhere about twice DOP853's time, within 1e-9 of it at tol = 1e-10;
at tol it lost 3.4e-9 of an elastic head-on impact's energy where DOP853 loses 1.6e-10, so it runs
at tol / 10, which brings that to 4.3e-10).

The slip follows its velocity only while the stretch's lag is small. Under a friction force on a
cone of radius ``r`` the slip velocity turns at about ``w^2 r / |ut|`` (``w`` the tangential
spring's angular frequency on the contact's effective tangential mass, the largest over its
tangential directions), and the stretch takes ``r / |ut|`` to follow it: it lags by the angle
``(w r / |ut|)^2``, and the slip follows its velocity only where that angle is below the same
``tol^(1/2)``. So a slip that slows down hands back to the stretch before it stops. A force along
the slip velocity turns over at once where the slip reverses, and on a cone that shrinks as the
contact unloads the slip speed ``lam = |ut| - r'`` never falls to zero: without the hand-over the
integration chattered about zero slip in steps of 1e-10 of the contact time, and the dropped lag
cost accuracy. A corner of the ContactNets cube (e = 0.35, mu = 0.25, stiffness 1e6) ran out of
its 60 s at ``tangential_stiffness_ratio`` 0.25 and below at tol = 1e-6, 0.1 and below at
1e-8, 0.5 at 1e-4 (the stiffer the tangential spring, the narrower its cone), and lost 1e-4 of
its spin at ratio 0.25 and tol = 1e-8. Now it is answered at every ratio from 0.02 to 10, within
1e-7 of its tol = 1e-12 answer at tol = 1e-6 and within 2e-9 at tol = 1e-8 (velocities relative
to the largest pre-impact one); the scenes above keep their steps.

A slip that stops where its speed only touches zero leaves the sticking stretch on its cone to
second order, and the integrator's own error (in LSODA's low-order first steps) can
carry it past: were the stick to end there, the slip it starts would run backward, stick again,
and the contact would restart without advancing. So a sticking stretch reaches its cone only
past the integrator's relative tolerance, and is put back on the cone as it starts to slide.
"""

from __future__ import annotations

from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.core.errors import NotApplicable
from lawbench.core.guards import current_budget
from lawbench.core.metric import all_finite
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem
from lawbench.laws.compliant.normal import Integration
from lawbench.numerics.integrator import EventIntegrator

if TYPE_CHECKING:
    from collections.abc import Callable

# The scaled stretch that carries the direction of a slip starting from zero stretch.
SEED = 1e-12
# In 3D a slip whose cone is narrower than tol^SHORT_POWER (scaled) follows the slip velocity,
# tol at most LOOSEST_SHORT: from tol = 1e-3 on, the cones it switched at were so wide that the
# switches met again and again (the bouncing ball and the sphere ran out of their 60 s).
LOOSEST_SHORT = 1e-4
SHORT_POWER = 0.5


class FrictionalIntegration(Integration):
    """One compliant impact with a tangential spring and a Coulomb slider at every contact.

    Scaled state ``[g (m), s (m d), un (m), ut (m d), Pn (m), Pt (m d), W]``: gaps and
    stretches over the length scale ``L``, velocities over ``V``, impulses over ``I``, time
    over ``tau``, and the work ``W`` the sliders took (J, ``diagnostics['slip_work']``);
    contact j's tangential entries are ``j d ... j d + d - 1``.
    """

    def __init__(self, problem: ImpactProblem, options: dict[str, Any]) -> None:
        super().__init__(problem, options)
        self.d = problem.d
        self.rtol = options["tol"]
        if options["method"] == "auto" and self.d > 1:
            # A lightly loaded 3D slip turns stiffly for the whole impact (see above); LSODA's
            # tolerance ten times tighter keeps energy as DOP853's does at tol.
            self.method, self.rtol = "LSODA", options["tol"] / 10
        self.mu = np.asarray(problem.mu, dtype=float)
        ratio = np.array([c.tangential_ratio for c in problem.contacts])
        self.kt = self.n * self.k * self.indentation ** (self.n - 1) / ratio
        self.Gc = np.asarray(problem.contact_delassus) / self.G_max
        self.slips = 0
        # Newtons per scaled stretch, and scaled cone radius per newton of normal force.
        self.kt_scaled = self.kt * self.L
        with np.errstate(over="ignore", divide="ignore"):
            self.cone = self.mu / self.kt_scaled
        if not (all_finite(self.cone) and all_finite(self.kt_scaled)):
            j = int(np.flatnonzero(~np.isfinite(self.cone * self.kt_scaled))[0])
            raise NotApplicable(
                f"compliant: contact {j}'s tangential spring, n k d^(n - 1) / ratio = "
                f"{self.kt[j]:.3g} at exponent n = {self.n[j]:.3g}, leaves double precision "
                f"against its Coulomb bound mu = {self.mu[j]:.3g}"
            )
        # Each tangential spring's angular frequency in scaled time, on the contact's stiffest
        # tangential direction (its largest diagonal entry of the Delassus matrix).
        tangential = np.diagonal(self.Gc)[problem.m :].reshape(problem.m, self.d)
        self.frequency = np.sqrt(self.scale * self.kt_scaled * tangential.max(axis=1))
        self.short = min(options["tol"], LOOSEST_SHORT) ** SHORT_POWER if self.d > 1 else 0.0
        m, md = problem.m, problem.m * self.d
        bounds = np.cumsum([0, m, md, m, md])
        self.parts = [slice(bounds[i], bounds[i + 1]) for i in range(4)]

    def split(self, y: np.ndarray) -> list[np.ndarray]:
        """Gaps, stretches (m, d), normal rates, tangential rates (m, d), impulses of ``y``.

        The state's last entry is the work the sliders took (J). ``y`` may stack states along
        leading axes; each part keeps them.
        """
        m, d, lead = self.problem.m, self.d, y.shape[:-1]
        g, s, un, ut = (y[..., part] for part in self.parts)
        impulses = y[..., self.parts[3].stop : -1]
        return [g, s.reshape(*lead, m, d), un, ut.reshape(*lead, m, d), impulses]

    def field(
        self,
        y: np.ndarray,
        closed: np.ndarray,
        slipping: np.ndarray,
        following: np.ndarray | None = None,
    ) -> dict[str, Any]:
        """What the field is at the scaled state ``y``, the contacts ``slipping`` sliding.

        ``following`` slides along the slip velocity rather than the stretch (narrow cones in
        3D). Normal forces (N), the cones' radii and growth rates and the stretches' sizes
        (scaled), the slip speeds ``lam`` along the friction's direction, and the state's rate;
        states stacked along leading axes of ``y`` give each of these stacked the same way.
        """
        g, s, un, ut, _ = self.split(y)
        lead = g.shape[:-1]
        j = np.flatnonzero(closed)
        Fn = np.zeros(g.shape)
        Fn[..., j] = self.forces(g[..., j], un[..., j], j)
        radius = self.cone * np.maximum(Fn, 0.0)
        size = np.sqrt(np.einsum("...jd,...jd->...j", s, s))
        direction = s / np.where(size > 0, size, 1.0)[..., None]
        if following is not None and following.any():
            speed = np.sqrt(np.einsum("...jd,...jd->...j", ut, ut))
            along = following & (speed > 0)
            slip = ut / np.where(along, speed, 1.0)[..., None]
            direction = np.where(along[..., None], slip, direction)
        Ft = -self.kt_scaled[:, None] * s
        if slipping.any():
            on_cone = -(self.kt_scaled * radius)[..., None] * direction
            Ft = np.where(slipping[:, None], on_cone, Ft)
        f = np.concatenate([Fn, Ft.reshape(*lead, -1)], axis=-1)
        f *= self.scale
        u_rate = f @ self.Gc.T
        Fn_rate = np.zeros(g.shape)
        Fn_rate[..., j] = self.force_rate(g[..., j], un[..., j], u_rate[..., j], j)
        cone_rate = self.cone * np.where(Fn > 0, Fn_rate, 0.0)
        along = np.einsum("...jd,...jd->...j", direction, ut)
        lam = along - cone_rate
        # A contact without friction has no tangential spring: its stretch stays zero.
        s_rate = ut * (closed & (self.mu > 0))[:, None]
        # The sliders' power, ``mu Fn lam`` (J per unit of scaled time).
        slid = np.where(slipping, radius * self.kt_scaled * lam * self.L, 0.0).sum(axis=-1)
        if slipping.any():
            # On the cone the stretch grows with it and turns toward the slip (it does not
            # turn where it follows the slip already): ``ut - lam n`` written as the slip
            # across the stretch plus the cone's growth, so that a slip much faster than the
            # cone grows (a grazing approach) does not leave the rounding of ``lam`` in it.
            across = ut - along[..., None] * direction
            s_rate = np.where(slipping[:, None], across + cone_rate[..., None] * direction, s_rate)
        return {
            "Fn": Fn,
            "radius": radius,
            "cone_rate": cone_rate,
            "size": size,
            "lam": lam,
            "rate": np.concatenate(
                [un, s_rate.reshape(*lead, -1), u_rate, f, slid[..., None]], axis=-1
            ),
        }

    def closing_slides(self, y: np.ndarray, closed: np.ndarray, j: int) -> bool:
        """Whether contact ``j``, closing at ``y`` with no stretch, starts by sliding.

        It slides where sticking would carry the stretch out of the cone at once: the slip
        speed ``|ut|`` exceeds the cone's growth ``r'`` (always, for a contact whose force
        starts at zero slope, as Hertz's does; for a linear undamped one, where
        ``|ut| > mu eta0^2 |un|``, Jia's condition).
        """
        _, _, _, ut, _ = self.split(y)
        at = self.field(y, closed, np.zeros(self.problem.m, dtype=bool))
        return self.mu[j] > 0 and float(np.linalg.norm(ut[j])) > at["cone_rate"][j]

    def follow_margin(self, y: np.ndarray, radius: np.ndarray) -> np.ndarray:
        """Positive where a 3D slip may follow its velocity, zero where it switches.

        ``y`` is a scaled state (or states stacked, see `split`) and ``radius`` its cones'
        radii. The slip follows its velocity on a cone narrower than ``short`` while its
        stretch's lag angle ``(frequency r / |ut|)^2`` is below ``short``: the margin is the
        smaller of ``short - r`` and ``short^(1/2) |ut| - frequency r``, continuous in ``y``.
        """
        ut = self.split(y)[3]
        speed = np.sqrt(np.einsum("...jd,...jd->...j", ut, ut))
        lag = self.short**0.5 * speed - self.frequency * radius
        return np.minimum(self.short - radius, lag)

    def on_cones(
        self, y: np.ndarray, closed: np.ndarray, slipping: np.ndarray, aligned: np.ndarray
    ) -> np.ndarray:
        """``y`` with each sliding stretch on its cone, and no sticking one outside it.

        A sliding stretch keeps its direction, or takes the slip's where it has none or is
        ``aligned`` (it followed the slip, or starts to), so the force is on the cone exactly
        whatever the integration's drift.
        """
        y = y.copy()
        _, s, _, ut, _ = self.split(y)
        at = self.field(y, closed, slipping)
        for j in np.flatnonzero(closed & (self.mu > 0)):
            size, radius = at["size"][j], at["radius"][j]
            slips = bool(np.any(ut[j]))
            along = ut[j] if (size == 0 or aligned[j]) and slips else s[j]
            norm = float(np.linalg.norm(along))
            if slipping[j] and norm > 0:
                s[j] = along / norm * max(radius, SEED)
            elif size > radius:
                s[j] *= radius / size
        return y

    def run(self) -> Outcome:
        """Integrate from first contact until no spring acts and no contact approaches."""
        problem, options = self.problem, self.options
        m, d = problem.m, self.d
        y = np.concatenate(
            [problem.gaps / self.L, np.zeros(m * d), problem.un / self.V, problem.ut / self.V]
        )
        y = np.concatenate([y, np.zeros(m + m * d + 1)])
        rtol = self.rtol
        # Four checks a step: a slip that stops and starts again within one step is still met.
        integrator = EventIntegrator(self.method, rtol, rtol * 1e-3, samples=4, stacked=True)
        spend = current_budget()
        t, self.steps, events = 0.0, 0, 0
        self.peak = np.zeros(m)
        self.history: list[tuple[float, np.ndarray, np.ndarray]] = []
        self._record(t, y, np.zeros(m, dtype=bool))
        slipping, was_closed = np.zeros(m, dtype=bool), np.zeros(m, dtype=bool)
        following = np.zeros(m, dtype=bool)
        while True:
            g, s, un, _, _ = self.split(y)
            self.let_go(g, un)
            if self.at_rest(g, un):
                break
            closed = g <= -self.band
            if not closed.any():
                spend.event()
                t += self._fly_to_contact(g, un)
                events += 1
                continue
            # A contact that opened released its spring; one that closes starts by sliding or
            # sticking; the others keep the mode the last event left them in.
            s[~closed] = 0.0
            slipping &= closed
            for j in np.flatnonzero(closed & ~was_closed):
                slipping[j] = self.closing_slides(y, closed, j)
            self.slips += int((slipping & ~was_closed).sum())
            # A fast 3D slip on a cone narrower than ``short`` follows the slip velocity.
            radius = self.field(y, closed, slipping)["radius"]
            narrow = slipping & (self.follow_margin(y, radius) > 0)
            y = self.on_cones(y, closed, slipping, narrow | following)
            # A stretch met on its cone where its slip would run backward (lam < 0: within
            # rounding of a slip that just stopped) sticks; sliding there would feed the slip.
            backward = slipping & (self.field(y, closed, slipping, narrow)["lam"] < 0)
            slipping &= ~backward
            following = narrow & slipping
            mode = _Mode(self, closed, slipping, following)
            event = integrator.to_event(
                mode.rhs, t, y, mode.switches, mode.direction, on_step=partial(self._on_step, mode)
            )
            t, y = event.x, event.y.copy()
            fired = np.asarray(event.fired, dtype=int)
            reached, stopped = (
                fired[(fired >= m) & (fired < 2 * m)] - m,
                fired[(fired >= 2 * m) & (fired < 3 * m)] - 2 * m,
            )
            slipping[reached] = True
            slipping[stopped] = False
            self.slips += len(reached)
            was_closed = closed
            events += 1
        P = self.split(y)[4]
        diagnostics = {
            "formulation": f"time integration ({self.model}, {self.method}) with "
            "tangential springs and Coulomb sliders",
            "duration_s": t * self.tau,
            "peak_force": self.peak.tolist(),
            "damping": self.c.tolist(),
            "tangential_stiffness": self.kt.tolist(),
            "slip_phases": self.slips,
            "slip_work": float(y[-1]),
            "steps": self.steps,
            "events": events,
        }
        path = self._path() if options["path"] else None
        return Outcome.from_impulses(
            problem, self.I * P[:m], self.I * P[m:], diagnostics=diagnostics, path=path
        )

    def _fly_to_contact(self, g: np.ndarray, un: np.ndarray) -> float:
        """Move the gaps ``g`` in free flight until the first contact closes; the time taken."""
        wait = np.where(un < 0, (g + self.band) / np.where(un < 0, -un, 1.0), np.inf)
        first = int(np.argmin(wait))
        g += un * wait[first]
        g[first] = -self.band[first]
        return float(wait[first])

    def _on_step(self, mode: _Mode, dense: Callable, t_old: float, t: float) -> None:
        """Count the step, keep the peak normal forces (four points) and the path's point."""
        self.steps += 1
        points = dense(np.linspace(t_old, t, 5)[1:])
        g, un, j = points[self.parts[0]], points[self.parts[2]], mode.acting
        self.peak[j] = np.maximum(self.peak[j], self.forces(g[j].T, un[j].T, j).max(axis=0))
        if self.options["path"]:
            self._record(t, dense(t), mode.closed)

    def _record(self, t: float, y: np.ndarray, closed: np.ndarray) -> None:
        """One point of the path: normal forces, and the energy each contact's springs hold."""
        if self.options["path"]:
            g, s, _, _, _ = self.split(y)
            Fn = self.field(y, closed, np.zeros(self.problem.m, dtype=bool))["Fn"]
            tangential = self.kt * (self.L * np.linalg.norm(s, axis=1)) ** 2 / 2
            self.history.append((t, Fn, self.stored(g) + tangential))


class _Mode:
    """The field between two restarts: which contacts are closed, and which of them slide."""

    def __init__(
        self,
        integration: FrictionalIntegration,
        closed: np.ndarray,
        slipping: np.ndarray,
        following: np.ndarray,
    ) -> None:
        self.integration, self.closed, self.slipping = integration, closed, slipping
        self.following = following
        self.acting = np.flatnonzero(closed)
        self.sticking = closed & ~slipping & (integration.mu > 0)
        self.damped = integration.clipped and bool(integration.c[closed].any())
        self.plastic = closed & integration.plastic
        # A gap fires as it passes its band away from its side; a sticking stretch as it passes
        # its cone by the integrator's relative tolerance, and a slip speed as it falls below
        # zero; a 3D slip's follow margin
        # as it leaves the side it started on; a plastic contact's gap rate as it turns from
        # approach to separation.
        gaps = np.where(closed, 1.0, -1.0)
        m = closed.size
        self.direction = np.concatenate(
            [
                gaps,
                -np.ones(2 * m),
                np.where(following, -1.0, 1.0),
                np.ones(m),
                np.zeros(m) if self.damped else np.zeros(0),
            ]
        )

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        return self.integration.field(y, self.closed, self.slipping, self.following)["rate"]

    def switches(self, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        """The event functions at ``y``, one state or a step's samples stacked (see `split`)."""
        integration = self.integration
        at = integration.field(y, self.closed, self.slipping, self.following)
        g, _, un, _, _ = integration.split(y)
        narrow = self.slipping & (integration.short > 0)
        parts = [
            g + integration.band,
            np.where(self.sticking, at["radius"] * (1 + integration.rtol) - at["size"], 1.0),
            np.where(self.slipping, at["lam"], 1.0),
            np.where(narrow, integration.follow_margin(y, at["radius"]), -1.0),
            np.where(self.plastic, un, -1.0),
        ]
        if self.damped:
            j = np.flatnonzero(self.closed)
            law = np.ones(g.shape)
            law[..., j] = integration.law_sign(g[..., j], un[..., j], j)
            parts.append(np.where(integration.c > 0, law, 1.0))
        return np.concatenate(parts, axis=-1)
