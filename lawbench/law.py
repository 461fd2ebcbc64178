"""The law protocol: what every impact law declares and how it is called.

A law subclasses `Law`, declares its name, summary, source, capabilities and options, and
implements `Law._resolve`. `Law.resolve` does what is common to all of them: it checks the
options and the problem against the capabilities, restricts the problem to its closed contacts
(a contact with a positive gap is not part of this impact), times the solve, and refuses to
return a non-finite answer.
"""

from __future__ import annotations

import dataclasses
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from lawbench.errors import InvalidProblem, NotApplicable, SolverFailure
from lawbench.outcome import Outcome
from lawbench.problem import ImpactProblem
from lawbench.registry import Registry
from lawbench.spec import Spec


@dataclass(frozen=True)
class Capabilities:
    """What a law can treat.

    Attributes
    ----------
    friction : bool
        Coulomb friction (problems with a tangential Jacobian and mu > 0).
    several_contacts : bool
        More than one contact at once.
    spatial : bool
        Spatial contacts (two tangential directions).
    needs_stiffness : bool
        The law reads contact stiffness and exponent.
    accuracy_knob : str or None
        Name of the option that trades accuracy for cost; None for exact laws.
    """

    friction: bool = False
    several_contacts: bool = True
    spatial: bool = False
    needs_stiffness: bool = False
    accuracy_knob: str | None = None

    def refusal(self, problem: ImpactProblem) -> str | None:
        """Why a law with these capabilities cannot treat ``problem``, or None."""
        if problem.frictional and not self.friction:
            return "the problem has friction (mu > 0) and this law is frictionless"
        if problem.d == 2 and problem.frictional and not self.spatial:
            return "the problem is spatial (two tangential directions) and this law is planar"
        closed = int(problem.closed.sum())
        if closed > 1 and not self.several_contacts:
            return f"the problem has {closed} closed contacts and this law treats one"
        return None


class Law(ABC):
    """Base class of the impact laws.

    Subclasses set the class attributes and implement `_resolve`, which receives a problem
    whose contacts are all closed and the complete, checked options.
    """

    name: ClassVar[str]
    summary: ClassVar[str]
    source: ClassVar[str]
    capabilities: ClassVar[Capabilities]
    options: ClassVar[tuple[Spec, ...]] = ()
    # Whether the law follows contacts through their gaps (resolves time): then it receives the
    # whole problem; otherwise only the closed contacts, an open one being no part of the impact.
    follows_gaps: ClassVar[bool] = False
    # Known defects of the law: (case, example, check) -> why the check fails there.
    findings: ClassVar[dict[tuple[str, str, str], str]] = {}

    def option_values(self, given: dict[str, Any] | None = None) -> dict[str, Any]:
        """Return every option of this law, defaults filled in, checked and converted.

        Raises
        ------
        InvalidProblem
            For an unknown option name or a bad value.
        """
        given = dict(given or {})
        specs = {spec.name: spec for spec in self.options}
        unknown = sorted(set(given) - set(specs))
        if unknown:
            known = ", ".join(specs) or "none"
            raise InvalidProblem(
                f"unknown option {unknown[0]!r} for law {self.name!r}; known: {known}"
            )
        return {name: spec.coerce(given.get(name, spec.default)) for name, spec in specs.items()}

    def resolve(self, problem: ImpactProblem, **options: Any) -> Outcome:
        """Resolve the impact ``problem`` with this law.

        Parameters
        ----------
        problem : ImpactProblem
            The impact; it is not modified.
        **options
            The law's options (see ``options``).

        Returns
        -------
        Outcome
            With ``diagnostics['wall_time_s']`` and ``diagnostics['options']`` filled in.

        Raises
        ------
        InvalidProblem
            For a bad option.
        NotApplicable
            When the law cannot treat the problem.
        SolverFailure
            When the numerical method fails or would return a non-finite number.
        """
        values = self.option_values(options)
        reason = self.capabilities.refusal(problem)
        if reason:
            raise NotApplicable(f"{self.name}: {reason}")
        closed = problem.closed
        start = time.perf_counter()
        if closed.all() or self.follows_gaps:
            outcome = self._resolve(problem, values)
        elif closed.any():
            outcome = _embed(
                self._resolve(problem.select_contacts(closed), values), closed, problem
            )
        else:
            outcome = Outcome.from_impulses(problem, np.zeros(problem.m))
            outcome.diagnostics["formulation"] = "no closed contact"
        wall_time = time.perf_counter() - start
        if problem.Wt is not None and outcome.Pt.size == 0:
            outcome = dataclasses.replace(outcome, Pt=np.zeros(problem.m * problem.d))
        for field in ("v_plus", "Pn", "Pt", "T_plus"):
            if not np.all(np.isfinite(getattr(outcome, field))):
                raise SolverFailure(f"{self.name}: non-finite {field} {getattr(outcome, field)}")
        outcome.diagnostics["options"] = values
        outcome.diagnostics["wall_time_s"] = wall_time
        return outcome

    @abstractmethod
    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        """Resolve a problem whose contacts are all closed."""


def _embed(outcome: Outcome, closed: np.ndarray, problem: ImpactProblem) -> Outcome:
    """Give an outcome solved on the closed contacts the impulses of every contact."""
    Pn = np.zeros(problem.m)
    Pn[closed] = outcome.Pn
    Pt = outcome.Pt
    if Pt.size and problem.d:
        Pt = np.zeros((problem.m, problem.d))
        Pt[closed] = outcome.Pt.reshape(-1, problem.d)
        Pt = Pt.ravel()
    return dataclasses.replace(outcome, Pn=Pn, Pt=Pt)


LAWS: Registry[Law] = Registry("law", "lawbench.laws")
