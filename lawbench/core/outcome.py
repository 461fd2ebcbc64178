"""The result every law returns, with the same fields for all of them.

Also the kinematics of an answer: the velocity that impulses give, and the gap rates at it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.core.problem import ImpactProblem

if TYPE_CHECKING:
    import pandas as pd


def generalized_impulse(
    problem: ImpactProblem, Pn: np.ndarray, Pt: np.ndarray | None = None
) -> np.ndarray:
    """Return the generalized impulse ``Wn @ Pn + Wt @ Pt`` (Pt None or empty: no friction)."""
    impulse = problem.Wn.dot(Pn)
    if Pt is not None and len(Pt):
        impulse = impulse + problem.Wt.dot(Pt)
    return impulse


def velocity_after(
    problem: ImpactProblem, Pn: np.ndarray, Pt: np.ndarray | None = None
) -> np.ndarray:
    """Return ``v + M^-1 (Wn @ Pn + Wt @ Pt)``, the velocity after the impulses."""
    return problem.v + problem.solve_mass(generalized_impulse(problem, Pn, Pt))


def gap_rates(problem: ImpactProblem, v: np.ndarray) -> np.ndarray:
    """Return the normal gap rates ``Wn.T @ v`` of every contact at velocity ``v``."""
    return problem.Wn.T @ v


# The tangential impulse of a frictionless outcome: empty, shared, read-only.
_NO_IMPULSE = np.zeros(0)
_NO_IMPULSE.setflags(write=False)


@dataclass(frozen=True, eq=False)
class Outcome:
    """Post-impact state of an impact problem.

    Attributes
    ----------
    v_plus : array (n,)
        Post-impact generalized velocity.
    Pn : array (m,)
        Normal impulse of every contact (>= 0 pushes apart).
    Pt : array (m*d,)
        Tangential impulses; empty without friction.
    T_minus, T_plus : float
        Kinetic energy before and after.
    status : str
        'ok', or a word a law uses to flag a questionable answer (for example 'ambiguous').
    diagnostics : dict
        Formulation used, iterations or steps, solver status, wall time (``wall_time_s``).
    path : dict or None
        On request, quantities along the impact variable, for plots.
    v_minus : array (n,) or None
        Pre-impact generalized velocity, the problem's ``v`` (None when not given).
    """

    v_plus: np.ndarray
    Pn: np.ndarray
    Pt: np.ndarray
    T_minus: float
    T_plus: float
    status: str = "ok"
    diagnostics: dict[str, Any] = field(default_factory=dict)
    path: dict[str, np.ndarray] | None = None
    v_minus: np.ndarray | None = None

    def to_frame(self) -> pd.DataFrame:
        """The outcome as a tidy frame: one row per quantity and index (v_plus, Pn, Pt, energy).

        Returns
        -------
        pandas.DataFrame
            Columns ``quantity``, ``index`` (coordinate or contact; -1 for a scalar), ``value``.
        """
        import pandas as pd

        rows = [
            (name, i, float(x))
            for name in ("v_plus", "Pn", "Pt")
            for i, x in enumerate(getattr(self, name))
        ]
        rows += [(name, -1, float(getattr(self, name))) for name in ("T_minus", "T_plus", "dT")]
        return pd.DataFrame(rows, columns=["quantity", "index", "value"])

    def _repr_html_(self) -> str:
        formulation = self.diagnostics.get("formulation", "")
        head = f"<p>Outcome ({self.status}; {formulation})</p>"
        return head + self.to_frame().to_html(index=False)

    @property
    def dT(self) -> float:
        """Kinetic energy change ``T_plus - T_minus`` (positive: energy created)."""
        return self.T_plus - self.T_minus

    @classmethod
    def from_impulses(
        cls, problem: ImpactProblem, Pn: np.ndarray, Pt: np.ndarray | None = None, **fields: Any
    ) -> Outcome:
        """Build the outcome of applying impulses ``Pn`` (and ``Pt``) to ``problem``.

        ``fields`` are the optional fields (status, diagnostics, path). The outcome agrees
        with its impulses by construction: `impulses_of` says so for ``problem``.
        """
        outcome = cls.from_velocity(problem, velocity_after(problem, Pn, Pt), Pn, Pt, **fields)
        # The problem's identity, not the problem: an outcome pickles without its problem.
        object.__setattr__(outcome, "_impulses_of", id(problem))
        return outcome

    def impulses_of(self, problem: ImpactProblem) -> bool:
        """Whether `from_impulses` built this very outcome from ``problem``.

        Its velocity is then the impulses' and its energies the velocity's, by construction.
        A copy made with `dataclasses.replace` is not that outcome, nor is one built from an
        earlier problem whose identity ``problem`` took over after it was freed: the answer
        holds for an outcome built while ``problem`` is alive.
        """
        return self.__dict__.get("_impulses_of") == id(problem)

    @classmethod
    def from_velocity(
        cls,
        problem: ImpactProblem,
        v_plus: np.ndarray,
        Pn: np.ndarray,
        Pt: np.ndarray | None = None,
        *,
        status: str = "ok",
        diagnostics: dict[str, Any] | None = None,
        path: dict[str, np.ndarray] | None = None,
    ) -> Outcome:
        """Build an outcome from a post-impact velocity a law computed itself."""
        v_plus = np.asarray(v_plus, dtype=float)
        return cls(
            v_plus,
            np.asarray(Pn, dtype=float),
            _NO_IMPULSE if Pt is None else np.asarray(Pt, dtype=float),
            problem.T_minus,
            problem.kinetic_energy(v_plus),
            status,
            dict(diagnostics or {}),
            path,
            problem.v,
        )


def scaled_back(
    outcome: Outcome, problem: ImpactProblem, units: tuple[float, float, float]
) -> Outcome:
    """The outcome of ``problem`` from one solved in ``units`` of mass, velocity and time.

    Velocities are multiplied by the velocity unit and impulses by the product of both, and
    the energies are the problem's own. The path and the diagnostics stay in the units solved
    in, which ``diagnostics['units']`` names.
    """
    mass, velocity, time = units
    diagnostics = {
        **outcome.diagnostics,
        "units": {"mass": mass, "velocity": velocity, "time": time},
    }
    # A number that overflows here is refused by name by the caller.
    with np.errstate(over="ignore", invalid="ignore"):
        return Outcome.from_velocity(
            problem,
            outcome.v_plus * velocity,
            outcome.Pn * (mass * velocity),
            outcome.Pt * (mass * velocity),
            status=outcome.status,
            diagnostics=diagnostics,
            path=outcome.path,
        )


def embedded(outcome: Outcome, closed: np.ndarray, problem: ImpactProblem) -> Outcome:
    """Give an outcome solved on the closed contacts the impulses of every contact."""
    Pn = np.zeros(problem.m)
    Pn[closed] = outcome.Pn
    Pt = outcome.Pt
    if Pt.size and problem.d:
        Pt = np.zeros((problem.m, problem.d))
        Pt[closed] = outcome.Pt.reshape(-1, problem.d)
        Pt = Pt.ravel()
    return dataclasses.replace(outcome, Pn=Pn, Pt=Pt)
