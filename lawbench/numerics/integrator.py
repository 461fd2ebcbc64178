"""One event integrator for the laws that integrate an impact through events.

An integrating law (compliant contacts, the energetic multiple-impact law, Jia's springs, the
turning slip of Darboux-Keller dynamics) advances a smooth vector field between events where
its discrete state changes: a gap closing, a compression ending, a slip stopping. Its event
functions are smooth on the field's solutions and change sign at the event.

`EventIntegrator.to_event` steps a scipy ODE solver from a state until the first event function
changes sign in its stated direction, checked at ``samples`` points of each step's dense
output; the change is located by Brent's method (`lawbench.numerics.roots.crossing`), and the state
returned lies just past it, on the new branch. Every step and every event is spent from the
open `lawbench.core.law.Budget` of the solve, so ``max_steps``, ``max_events`` and
``max_seconds`` are honoured the same way by every integrating law; a callback sees every step
(and the last, partial one) with its dense output, for a recorded path or a peak.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import partial

import numpy as np

from lawbench.core.errors import SolverFailure
from lawbench.core.guards import current_budget
from lawbench.numerics.roots import crossing

Field = Callable[[float, np.ndarray], np.ndarray]
Dense = Callable[[float], np.ndarray]


@dataclass(frozen=True)
class Event:
    """Where the integration stopped: just past the sign change of the ``fired`` functions.

    ``fired`` lists the event functions whose change lies within the integrator's
    ``simultaneous`` distance of ``x``, the first one first; it is empty when the integration
    reached its end ``x_end`` without an event.
    """

    x: float
    y: np.ndarray
    fired: tuple[int, ...]


class EventIntegrator:
    """Integration of ``dy/dx = fun(x, y)`` to the first event.

    Parameters
    ----------
    method : str
        A scipy ``OdeSolver`` class name (``DOP853``, ``RK45``, ``Radau``, ``LSODA``).
    rtol, atol : float or array
        The solver's tolerances.
    samples : int
        Points of each step (evenly spaced, the step's end the last) where the event functions
        are checked: more catch an event function that changes sign twice within one step.
    simultaneous : float
        Sign changes closer than this to the first one are reported together.
    what : str
        What a step is, in budget messages.
    past : bool
        Whether the state returned lies just past the first change of sign (on the new
        branch), or at Brent's root of it, to rounding on either side (where a law applies
        the event's transition itself).
    stacked : bool
        Whether the event functions take a step's sample states at once: ``events(x, y)`` with
        ``y`` of shape ``(samples, n)`` returns ``(samples, functions)`` (one call a step, not
        ``samples``); a single state of shape ``(n,)`` still gives one row.
    """

    def __init__(
        self,
        method: str = "DOP853",
        rtol: float = 1e-10,
        atol: float | np.ndarray = 1e-13,
        samples: int = 1,
        simultaneous: float = 0.0,
        what: str = "integrator steps",
        past: bool = True,
        stacked: bool = False,
    ) -> None:
        import scipy.integrate  # on first use: registering a law imports no integrator

        self.method_name = method
        self.method = getattr(scipy.integrate, method)
        self.rtol, self.atol, self.samples = rtol, atol, samples
        self.simultaneous, self.what, self.past = simultaneous, what, past
        self.stacked = stacked

    def to_event(
        self,
        fun: Field,
        x0: float,
        y0: np.ndarray,
        events: Callable[[float, np.ndarray], np.ndarray],
        direction: float | np.ndarray = 0.0,
        x_end: float = np.inf,
        jac: Callable | None = None,
        on_step: Callable[[Dense, float, float], None] | None = None,
    ) -> Event:
        """Integrate from ``(x0, y0)`` to just past the first event, or to ``x_end``.

        Parameters
        ----------
        fun : callable
            The vector field, smooth until the next event.
        x0, y0 : float, array
            The start.
        events : callable
            ``events(x, y)``, an array of event functions.
        direction : float or array
            Per function: -1 fires when it falls from >= 0 below 0, +1 when it rises from
            <= 0 above 0, 0 at any change of sign.
        x_end : float
            Where the integration stops without an event.
        jac : callable or None
            The field's Jacobian, for the implicit methods.
        on_step : callable or None
            ``on_step(dense, x_old, x)`` after each step, the last one ending at the event.

        Raises
        ------
        BudgetExceeded
            When the open budget's steps, events or seconds run out.
        SolverFailure
            When the solver fails.
        """
        spend = current_budget()
        extra = {} if jac is None else {"jac": jac}
        solver = self.method(fun, x0, y0, x_end, rtol=self.rtol, atol=self.atol, **extra)
        direction = np.asarray(direction, dtype=float)
        before = np.asarray(events(x0, y0), dtype=float)
        while solver.status == "running":
            message = solver.step()
            spend.step(self.what)
            if solver.status == "failed":
                raise SolverFailure(f"{spend.law}: {self.method_name} failed: {message}")
            dense = solver.dense_output()
            start = solver.t_old
            xs = np.linspace(solver.t_old, solver.t, self.samples + 1)[1:]
            for x, after in zip(xs, self._values(events, dense, xs, solver.y), strict=True):
                self._finite(after, x)
                crossed = np.flatnonzero(_fires(before, after, direction))
                if crossed.size:
                    spend.event()
                    event = self._locate(events, dense, crossed, start, x)
                    if on_step is not None:
                        on_step(dense, solver.t_old, event.x)
                    return event
                before, start = after, x
            if on_step is not None:
                on_step(dense, solver.t_old, solver.t)
        return Event(float(solver.t), solver.y, ())

    def _values(
        self, events: Callable, dense: Dense, xs: np.ndarray, y_end: np.ndarray
    ) -> Iterator[np.ndarray]:
        """The event functions at the samples ``xs`` of a step that ends at ``y_end``."""
        if self.stacked:
            ys = np.asarray(dense(xs)).T.copy()
            ys[-1] = y_end
            yield from np.asarray(events(xs, ys), dtype=float)
            return
        for x in xs:
            yield np.asarray(events(x, y_end if x == xs[-1] else dense(x)), dtype=float)

    def _finite(self, values: np.ndarray, x: float) -> np.ndarray:
        """``values``, the event functions at ``x``, or `SolverFailure` if one left floating point.

        An event function that overflows (a contact force of a huge exponent) has no sign to
        follow: the step cannot say where the event is.
        """
        values = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(values)):
            raise SolverFailure(
                f"{current_budget().law}: {self.method_name}: event functions not finite at "
                f"{x:.6g} ({values.tolist()}): the state left floating point"
            )
        return values

    def _locate(
        self,
        events: Callable[[float, np.ndarray], np.ndarray],
        dense: Dense,
        crossed: np.ndarray,
        lo: float,
        hi: float,
    ) -> Event:
        def value(i: int, x: float) -> float:
            return float(self._finite(events(x, dense(x)), x)[i])

        where = np.array([crossing(partial(value, int(i)), lo, hi, self.past) for i in crossed])
        order = np.argsort(where, kind="stable")
        x = float(where[order[0]])
        together = where[order] <= x + self.simultaneous
        return Event(x, dense(x), tuple(int(i) for i in crossed[order][together]))


def _fires(before: np.ndarray, after: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Which functions changed sign in their direction between ``before`` and ``after``."""
    falls = (before >= 0) & (after < 0)
    rises = (before <= 0) & (after > 0)
    return np.where(
        direction < 0, falls, np.where(direction > 0, rises, np.sign(before) != np.sign(after))
    )
