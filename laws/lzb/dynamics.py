"""Integration of the energetic multiple-impact law (Liu, Zhao, Brogliato), contact by contact.

The law (``laws/lzb.py`` states it with its sources) advances every contact's normal impulse in
proportion to its force ``F_j = K_j^(1/(eta_j+1)) ((eta_j+1) E_j)^(eta_j/(eta_j+1))``, the force
of the spring that stores the energy ``E_j``. Writing the stored energy through the regular
variable ``s_j = ((eta_j+1) E_j / K_j)^(1/(eta_j+1))`` (an indentation: ``F_j = K_j s_j^eta_j``)
turns the energy balance ``dE_j = -un_j dP_j / xi_j`` into ``ds_j = -un_j dtau / xi_j`` with
``dtau = dP_j / F_j`` the same for every contact: the time of the springs. Units are scaled by
the largest pre-impact contact speed ``V``, the smallest indentation a contact would reach
alone at that speed ``L``, the time ``L / V``, the impulse ``V / max G_jj`` and the energy
``V`` times that impulse. The state is ``[Pn, Pt, s, Wn, Wt, tau]`` (impulses, indentations,
works of the normal and tangential forces, time); the contact velocities are
``u = u- + C P`` with ``C`` the contact Delassus matrix.

Each contact is idle (no energy, not approaching), in compression (``xi = 1``) or in expansion
(``xi = e^2`` for the bi-stiffness variant, ``1`` for the mono-stiffness one); with friction a
loaded contact also slips in a fixed direction or sticks. These discrete states are constant
between events (end of compression, recompression, end of expansion, approach of an idle
contact, slip stop, stick limit, change of primary contact or of variable), each located by
Brent's method on the integrator's dense output, sampled at the middle and the end of every
step; the integrator restarts just past each. The independent variable of a
segment is the impulse of the primary contact while its stored energy is at least
``PRIMARY_THRESHOLD`` times the reference energy, and ``tau`` otherwise (near the start and the
end of the loadings, where ``dtau/dP`` is unbounded).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from lawbench.core.errors import SolverFailure
from lawbench.core.mechanics import for_products
from lawbench.core.problem import ImpactProblem
from lawbench.numerics.integrator import EventIntegrator

IDLE, COMPRESSION, EXPANSION = 0, 1, 2
# The primary impulse is the independent variable while the primary contact stores at least
# this fraction of the reference energy max_j (un-_j)^2 / (2 G_jj).
PRIMARY_THRESHOLD = 1e-2
# The primary contact changes when another stores this much more energy (relative): exact ties
# (symmetric scenes) keep the current primary instead of switching at every step.
PRIMARY_HYSTERESIS = 1e-6
# A contact speed counts as rest below this many times rtol times the largest pre-impact one:
# closer to zero it is within the integrator's error.
REST_FACTOR = 10.0
# Points per step where the event functions are checked (and the path is kept).
SAMPLES = 2
RECORDED = 1000


@dataclass
class Cycle:
    """Works of one contact's force over one cycle (stored energy from zero back to zero)."""

    compression: float = 0.0
    restitution: float = 0.0
    residual: float = 0.0


@dataclass
class ContactRecord:
    """The history of one contact: cycles done, the one under way, peak indentation."""

    cycles: list[Cycle] = field(default_factory=list)
    current: Cycle | None = None
    mark: float = 0.0
    peak_s: float = 0.0


@dataclass
class Segment:
    """Discrete state between two events.

    ``phase`` of each contact; ``s_rate`` the factor ``1 / xi`` of ``ds/dtau = -un / xi``
    (0 when idle); ``s_floor`` where each expansion ends; ``slip`` the slip direction of each
    frictional contact (0: sticking or frictionless); ``primary`` the contact whose impulse is
    the independent variable (-1: time); ``rest`` the speed that counts as zero; ``stick`` the
    sticking contacts and ``stick_block`` their tangential Delassus block.
    """

    phase: np.ndarray
    s_rate: np.ndarray
    s_floor: np.ndarray
    slip: np.ndarray
    primary: int
    rest: float
    stick: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    stick_block: np.ndarray | None = None
    stick_solve: np.ndarray | None = None

    def __post_init__(self) -> None:
        # The first event function of contact j is sign_j un_j + offset_j: un + tolerance when
        # idle (approach), -un in compression (its end), un in expansion (recompression).
        self.sign = np.where(self.phase == COMPRESSION, -1.0, 1.0)
        self.offset = np.where(self.phase == IDLE, self.rest, 0.0)
        self.expanding = self.phase == EXPANSION
        self.loaded = self.phase != IDLE
        self.acting = np.flatnonzero(self.loaded)

    def hold(self, stick: np.ndarray, Ctt: np.ndarray) -> None:
        """Make ``stick`` the sticking contacts, ``Ctt`` the tangential Delassus matrix."""
        self.stick = stick
        self.stick_block = Ctt[np.ix_(stick, stick)]
        independent = np.linalg.matrix_rank(self.stick_block) == stick.size
        self.stick_solve = np.linalg.inv(self.stick_block) if independent else None

    def stick_forces(self, drive: np.ndarray, bound: np.ndarray) -> np.ndarray:
        """Tangential forces that hold the sticking contacts at rest against ``drive``.

        Unique when their tangential directions are independent. When they are not (two
        corners of a block on one floor line share a tangential velocity) only the sum along
        the shared directions is decided: each contact then takes a share in proportion to
        its cone's bound ``mu Fn``, ``x = -B A (A B A)^+ drive``, so a contact that carries no
        normal force carries no friction and every shared cone is reached at once.
        """
        if self.stick_solve is not None:
            return -self.stick_solve @ drive
        weighted = bound[:, None] * self.stick_block
        return -weighted @ np.linalg.pinv(self.stick_block @ weighted, rcond=1e-12) @ drive


class EnergeticImpact:
    """One impact under the energetic law.

    Parameters
    ----------
    problem : ImpactProblem
        Every contact closed; planar friction at most.
    variant : str
        'bi' or 'mono' stiffness.
    rtol : float
        Relative tolerance of the integrator (absolute: ``1e-3 rtol`` in scaled units).
    method : str
        scipy ``OdeSolver`` class name.
    record_path : bool
        Keep the states along the impact.
    """

    def __init__(
        self,
        problem: ImpactProblem,
        variant: str,
        rtol: float,
        method: str,
        record_path: bool,
    ) -> None:
        self.problem, self.variant, self.rtol = problem, variant, rtol
        self.integrator = EventIntegrator(method, rtol, rtol * 1e-3, samples=SAMPLES)
        self.record_path = record_path
        m = self.m = problem.m
        self.friction = problem.frictional
        C = problem.contact_delassus if self.friction else problem.delassus
        contacts = problem.contacts
        self.K = np.array([c.stiffness for c in contacts])
        self.eta = np.array([c.exponent for c in contacts])
        self.e = problem.restitution("energetic")
        self.mu = problem.mu if self.friction else np.zeros(m)
        G = np.diag(problem.delassus)
        u0 = problem.un
        self.V = float(np.abs(np.concatenate([u0, problem.ut])).max())
        # Lengths in the smallest indentation a contact would reach alone at speed V.
        indentation = ((self.eta + 1) * self.V**2 / (2 * self.K * G)) ** (1 / (self.eta + 1))
        self.L = float(indentation.min())
        self.tau0 = self.L / self.V
        self.I = self.V / float(G.max())
        self.C = for_products(C / float(G.max()))
        self.k = self.K * self.L**self.eta * self.tau0 / self.I
        self.k_energy = self.k / (self.eta + 1)
        self.u0 = u0 / self.V
        self.ut0 = problem.ut / self.V if self.friction else np.zeros(0)
        approach = np.maximum(-self.u0, 0.0)
        self.E_ref = float((approach**2 * float(G.max()) / (2 * G)).max())
        mt = m if self.friction else 0
        # State layout: Pn, Pt, s, Wn, Wt, tau.
        self.iPn = slice(0, m)
        self.iPt = slice(m, m + mt)
        self.iS = slice(m + mt, 2 * m + mt)
        self.iW = slice(2 * m + mt, 3 * m + mt)
        self.iWt = slice(3 * m + mt, 3 * m + 2 * mt)
        self.size = 3 * m + 2 * mt + 1
        self.records = [ContactRecord() for _ in range(m)]
        self.rest = REST_FACTOR * rtol
        # Where each expansion ends, as an indentation: 0 (bi), or that of (1 - e^2) W_c (mono).
        self.floor = np.zeros(m)
        # A cycle with e* = 0 ends with its compression: its expansion rate is never used.
        bi = np.divide(1.0, self.e**2, out=np.zeros(m), where=self.e > 0)
        self.expansion_rate = bi if variant == "bi" else np.ones(m)
        self.steps = {"impulse": 0, "time": 0}
        self.events = 0
        self.primaries: list[int] = []
        self.switches = 0
        self.history: list[np.ndarray] = []

    # --- the vector field ---------------------------------------------------------------------

    def velocities(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Scaled normal and tangential contact velocities at state ``y``."""
        P = y[: self.iPt.stop]
        w = self.C @ P
        m = self.m
        return self.u0 + w[:m], self.ut0 + w[m:]

    def energies(self, y: np.ndarray) -> np.ndarray:
        """Scaled stored energies ``k s^(eta+1) / (eta+1)``.

        The powers are taken where a spring is compressed (a wave loads a few contacts of a
        long chain at a time); every other energy is zero.
        """
        s = y[self.iS]
        j = np.flatnonzero(s > 0.0)
        E = np.zeros(self.m)
        E[j] = self.k_energy[j] * s[j] ** (self.eta[j] + 1)
        return E

    def forces(self, y: np.ndarray, seg: Segment) -> tuple[np.ndarray, np.ndarray]:
        """Scaled normal and tangential forces at ``y`` in segment ``seg``.

        Only the loaded contacts carry a force: the powers are taken there alone.
        """
        j = seg.acting
        Fn = np.zeros(self.m)
        Fn[j] = self.k[j] * np.maximum(y[self.iS][j], 0.0) ** self.eta[j]
        if not self.friction:
            return Fn, np.zeros(0)
        Ft = -self.mu * Fn * seg.slip
        if seg.stick.size:
            m = self.m
            drive = self.C[m:, :m] @ Fn + self.C[m:, m:] @ Ft
            Ft[seg.stick] = seg.stick_forces(drive[seg.stick], self.mu[seg.stick] * Fn[seg.stick])
        return Fn, Ft

    def rate(self, y: np.ndarray, seg: Segment) -> np.ndarray:
        """Derivative of the state with respect to the scaled time."""
        u, ut = self.velocities(y)
        Fn, Ft = self.forces(y, seg)
        dy = np.empty(self.size)
        dy[self.iPn], dy[self.iPt] = Fn, Ft
        dy[self.iS] = -u * seg.s_rate
        dy[self.iW], dy[self.iWt] = u * Fn, ut * Ft
        dy[-1] = 1.0
        return dy

    def field(self, seg: Segment) -> Callable[[float, np.ndarray], np.ndarray]:
        """Right-hand side in the segment's independent variable."""
        if seg.primary < 0:
            return lambda x, y: self.rate(y, seg)
        i = seg.primary
        # A trial stage may overshoot where the primary unloads: a floor far below its force at
        # the threshold energy keeps the field finite, and the step is rejected and shortened.
        s_threshold = ((self.eta[i] + 1) * PRIMARY_THRESHOLD * self.E_ref / self.k[i]) ** (
            1 / (self.eta[i] + 1)
        )
        floor = 1e-3 * self.k[i] * s_threshold ** self.eta[i]

        def in_impulse(x: float, y: np.ndarray) -> np.ndarray:
            dy = self.rate(y, seg)
            return dy / max(dy[i], floor)

        return in_impulse

    def switching(self, y: np.ndarray, seg: Segment) -> np.ndarray:
        """Event functions: each positive until its event, in a fixed layout."""
        u, ut = self.velocities(y)
        parts = [seg.sign * u + seg.offset, np.where(seg.expanding, y[self.iS] - seg.s_floor, 1.0)]
        if self.friction:
            Fn, Ft = self.forces(y, seg)
            stuck = np.zeros(self.m, dtype=bool)
            stuck[seg.stick] = True
            parts.append(
                np.where(
                    seg.slip != 0, seg.slip * ut, np.where(stuck, self.mu * Fn - np.abs(Ft), 1)
                )
            )
        E = self.energies(y)
        if seg.primary < 0:
            parts.append([PRIMARY_THRESHOLD * self.E_ref - E.max()])
        else:
            lead = E[seg.primary]
            parts.append(lead * (1 + PRIMARY_HYSTERESIS) - E)
            parts.append([lead - PRIMARY_THRESHOLD * self.E_ref])
        return np.concatenate(parts)

    # --- events and the discrete state --------------------------------------------------------

    def end_of_compression(self, j: int, y: np.ndarray) -> None:
        """Contact j's compression ends: add its work; set where the expansion will end."""
        record, W = self.records[j], y[self.iW][j]
        record.current.compression += record.mark - W
        record.mark = W
        record.peak_s = max(record.peak_s, float(y[self.iS][j]))
        if self.variant == "mono":
            # The energy falls to (1 - e^2) W_c, as an indentation.
            energy = (1 - self.e[j] ** 2) * record.current.compression
            self.floor[j] = (energy / self.k_energy[j]) ** (1 / (self.eta[j] + 1))

    def end_of_cycle(self, j: int, y: np.ndarray) -> None:
        """Contact j's energy is released (bi) or its residue dissipated (mono)."""
        record, W = self.records[j], y[self.iW][j]
        record.current.restitution += W - record.mark
        record.current.residual = float(self.energies(y)[j])
        record.cycles.append(record.current)
        record.current = None
        y[self.iS.start + j] = 0.0

    def classify(self, y: np.ndarray, old: Segment | None) -> tuple[np.ndarray, Segment | None]:
        """Apply the events that happened at ``y``; return the state and the next segment.

        The segment is None when the impact is over: every contact idle.
        """
        y = y.copy()
        phase = np.full(self.m, IDLE) if old is None else old.phase.copy()
        u, _ = self.velocities(y)
        s, W = y[self.iS], y[self.iW]
        compressed, expanded = phase == COMPRESSION, phase == EXPANSION
        changing = (compressed & (u > 0)) | ((phase == IDLE) & (u < -self.rest))
        changing |= expanded & ((u < 0) | (s <= self.floor) | (self.e == 0))
        for j in np.flatnonzero(changing):
            record = self.records[j]
            if phase[j] == COMPRESSION and u[j] > 0:
                self.end_of_compression(j, y)
                phase[j] = EXPANSION
            elif phase[j] == EXPANSION and u[j] < 0 and s[j] > self.floor[j]:
                record.current.restitution += W[j] - record.mark
                record.mark = W[j]
                phase[j] = COMPRESSION
            if phase[j] == EXPANSION and (self.e[j] == 0 or s[j] <= self.floor[j]):
                self.end_of_cycle(j, y)
                phase[j] = IDLE
            if phase[j] == IDLE and u[j] < -self.rest:
                record.current, record.mark = Cycle(), W[j]
                self.floor[j] = 0.0
                phase[j] = COMPRESSION
        if (phase == IDLE).all():
            return y, None
        seg = Segment(
            phase=phase,
            s_rate=np.select(
                [phase == COMPRESSION, phase == EXPANSION], [1.0, self.expansion_rate]
            ),
            s_floor=self.floor.copy(),
            slip=np.zeros(self.m),
            primary=self.choose_primary(y),
            rest=self.rest,
        )
        if self.friction:
            self.friction_modes(y, seg, old)
            if self.frozen(y, seg):
                for j in np.flatnonzero(phase != IDLE):
                    if phase[j] == COMPRESSION:
                        self.end_of_compression(j, y)
                    self.end_of_cycle(j, y)
                return y, None
        return y, seg

    def frozen(self, y: np.ndarray, seg: Segment) -> bool:
        """Whether nothing can change any more (the stored energy is then locked in).

        The loaded contacts are at rest and their forces, friction balancing the springs, give
        the bodies no impulse (the lamina stuck on the anvil).
        """
        u, ut = self.velocities(y)
        loaded = seg.phase != IDLE
        if np.abs(u[loaded]).max() > self.rest or np.abs(ut[loaded]).max() > self.rest:
            return False
        F = np.concatenate(self.forces(y, seg))
        return bool(np.abs(self.C @ F).max() <= 1e-9 * (np.abs(self.C) @ np.abs(F)).max())

    def choose_primary(self, y: np.ndarray) -> int:
        """The contact storing the most energy, or -1 (step in time) below the threshold."""
        E = self.energies(y)
        last = self.primaries[-1] if self.primaries else -1
        lead = int(np.argmax(E))
        if last >= 0 and E[last] * (1 + PRIMARY_HYSTERESIS) >= E[lead]:
            lead = last
        if E[lead] < PRIMARY_THRESHOLD * self.E_ref:
            return -1
        if lead != last:
            self.switches += last >= 0
            self.primaries.append(lead)
        return lead

    def friction_modes(self, y: np.ndarray, seg: Segment, old: Segment | None) -> None:
        """Slip direction or stick of each loaded frictional contact (Coulomb, planar).

        A slipping contact keeps its direction; a sticking one whose force reached its cone
        slips against that force; the others at rest stick when the tangential forces that
        keep them at rest lie in their cones, found as the box-constrained problem of
        Coulomb's law at the force level (the normal forces are known).
        """
        m = self.m
        _, ut = self.velocities(y)
        active = (seg.phase != IDLE) & (self.mu > 0)
        moving = active & (np.abs(ut) > self.rest)
        seg.slip[moving] = np.sign(ut[moving])
        if old is not None and old.stick.size:
            # At the cone the stick force is the limiting friction: slip starts against it.
            Fn, Ft = self.forces(y, old)
            limit = np.zeros(m, dtype=bool)
            limit[old.stick] = self.mu[old.stick] * Fn[old.stick] <= np.abs(Ft[old.stick])
            limit &= active & ~moving & (Ft != 0)
            seg.slip[limit] = -np.sign(Ft[limit])
            moving |= limit
        rest = np.flatnonzero(active & ~moving)
        if rest.size == 0:
            return
        Fn = np.where(seg.phase != IDLE, self.k * np.maximum(y[self.iS], 0.0) ** self.eta, 0.0)
        if not Fn.any():
            # Loading starts from zero energy: the forces grow as k (-un tau)^eta, so their
            # ratios are those of k (-un)^eta.
            u, _ = self.velocities(y)
            Fn = np.where(seg.phase != IDLE, self.k * np.maximum(-u, 0.0) ** self.eta, 0.0)
        Ctt = self.C[m:, m:]
        drive = (self.C[m:, :m] @ Fn + Ctt @ (-self.mu * Fn * seg.slip))[rest]
        A = Ctt[np.ix_(rest, rest)]
        Ft = _box_qp(A, drive, self.mu[rest] * Fn[rest])
        accel = A @ Ft + drive
        scale = max(float(np.abs(drive).max()), float(np.abs(A @ Ft).max()), 1e-300)
        slipping = np.abs(accel) > 1e-9 * scale
        seg.slip[rest[slipping]] = np.sign(accel[slipping])
        seg.hold(rest[~slipping], Ctt)

    # --- the driver ---------------------------------------------------------------------------

    def run(self) -> np.ndarray:
        """Integrate the impact; return the final scaled state."""
        y, seg = self.classify(np.zeros(self.size), None)
        self.keep(y, seg)
        while seg is not None:
            y, seg = self.segment(y, seg)
        return y

    def keep(self, y: np.ndarray, seg: Segment | None) -> None:
        """Keep ``y`` and the primary contact for the path, when asked."""
        if self.record_path:
            self.history.append(np.append(y, -1 if seg is None else seg.primary))

    def segment(self, y: np.ndarray, seg: Segment) -> tuple[np.ndarray, Segment | None]:
        """Integrate from ``y`` to the first event; return the state after it and what follows."""
        x = y[-1] if seg.primary < 0 else y[seg.primary]
        kind = "time" if seg.primary < 0 else "impulse"

        def on_step(dense: Callable[[float], np.ndarray], x_old: float, x_new: float) -> None:
            self.steps[kind] += 1
            if self.record_path:
                for x_k in np.linspace(x_old, x_new, SAMPLES + 1)[1:]:
                    self.keep(dense(x_k), seg)

        event = self.integrator.to_event(
            self.field(seg), x, y, lambda x, y: self.switching(y, seg), -1.0, on_step=on_step
        )
        self.events += 1
        y_new, seg_new = self.classify(event.y, seg)
        self.keep(y_new, seg_new)
        return y_new, seg_new


def _box_qp(A: np.ndarray, b: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """Minimise ``x A x / 2 + b x`` subject to ``|x| <= bound`` (projected Gauss-Seidel).

    ``A`` is symmetric positive semidefinite; a row with a zero diagonal gets ``x = 0``.
    """
    x = np.zeros(b.size)
    scale = max(float(np.abs(bound).max()), float(np.abs(b).max()), 1e-300)
    for _ in range(10_000):
        change = 0.0
        for r in range(b.size):
            if A[r, r] <= 0:
                continue
            new = min(max(x[r] - (A[r] @ x + b[r]) / A[r, r], -bound[r]), bound[r])
            change = max(change, abs(new - x[r]))
            x[r] = new
        if change <= 1e-15 * scale:
            return x
    raise SolverFailure("lzb: the stick/slip problem did not converge in 10000 sweeps")
