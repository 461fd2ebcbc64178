"""The case protocol: a named scene with documented parameters and references.

A case subclasses `Case`, declares its parameters as `Spec` objects, what it requires of a law,
its analytic or published references, and implements `Case._build`, which receives every
parameter checked and with defaults filled in and returns an `ImpactProblem`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.problem import ImpactProblem
from lawbench.core.registry import Registry
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags

Params = Mapping[str, Any]


def _always(params: Params) -> str | None:
    return None


@dataclass(frozen=True)
class Reference:
    """An analytic or published post-impact velocity for one law on a case.

    Attributes
    ----------
    name : str
        Short name, for tables.
    source : str
        Where it comes from (paper or book, equation).
    law : str
        The law it describes.
    v_plus : callable
        Complete parameters -> expected post-impact velocity.
    options : mapping
        Law options it assumes (for example a sequential ordering).
    condition : callable
        Complete parameters -> None when the reference holds, else why it does not.
    """

    name: str
    source: str
    law: str
    v_plus: Callable[[Params], np.ndarray]
    options: Mapping[str, Any] = field(default_factory=dict)
    condition: Callable[[Params], str | None] = _always

    def applies(self, law: str, options: Params, params: Params) -> str | None:
        """None when this reference describes ``law`` with ``options`` at ``params``."""
        if law != self.law:
            return f"describes {self.law}"
        for key, value in self.options.items():
            if options.get(key) != value:
                return f"assumes {key}={value}"
        if any(params.get("gaps", ())):
            return "assumes every contact closed (zero gaps)"
        return self.condition(params)


@dataclass(frozen=True)
class GroundTruth:
    """What a scene's outcomes are measured against: a closed form, a converged model, or both.

    With both, the closed form is the truth where its condition holds (it is exact there) and
    the model everywhere else.

    Attributes
    ----------
    why : str
        Why this is the truth of the scene (which physics it resolves that the others do not).
    reference : str or None
        The name of one of the case's `Reference` closed forms, exact where it holds.
    law : str or None
        The model whose converged solution is the truth (elsewhere, when there is a closed
        form): a stated model, never one of the rigid laws compared on the scene.
    options : mapping
        That model's options for the converged solution (its tightest accuracy knob).
    """

    why: str
    reference: str | None = None
    law: str | None = None
    options: Mapping[str, Any] = field(default_factory=dict)

    def describe(self) -> str:
        """A short label for table headers."""
        settings = ", ".join(
            f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in self.options.items()
        )
        model = f"{self.law} ({settings})" if settings else str(self.law)
        if self.reference is None:
            return model
        closed = f"closed form ({self.reference})"
        return closed if self.law is None else f"{closed} where it holds, else {model}"


class Case(ABC):
    """Base class of the scenes."""

    name: ClassVar[str]
    summary: ClassVar[str]
    params: ClassVar[tuple[Spec, ...]]
    requires: ClassVar[Tags] = Tags()
    # Studies the scene declares, as data (`lawbench.studies.declared` builds them when asked).
    studies: ClassVar[tuple[dict[str, Any], ...]] = ()
    # What the scene's outcomes are measured against (model error), and why.
    ground_truth: ClassVar[GroundTruth | None] = None
    references: ClassVar[tuple[Reference, ...]] = ()
    # Named parameter sets that exercise the scene; every law and check runs on each.
    examples: ClassVar[Mapping[str, Params]] = {"default": {}}
    # The roles the scene plays in ``lawbench bench`` (`lawbench.bench.roles.ROLES`).
    bench_roles: ClassVar[tuple[str, ...]] = ()
    # Whether the quick report steps the engines on the scene (their cells cost the most);
    # False leaves them to the full report.
    quick_engines: ClassVar[bool] = True

    def parameters(self, **given: Any) -> dict[str, Any]:
        """Every parameter, defaults filled in, checked and converted.

        Raises
        ------
        InvalidProblem
            For an unknown name or a bad value; the message names the parameter.
        """
        specs = {spec.name: spec for spec in self.params}
        unknown = sorted(set(given) - set(specs))
        if unknown:
            raise InvalidProblem(
                f"unknown parameter {unknown[0]!r} for case {self.name!r}; "
                f"known: {', '.join(specs)}"
            )
        values = {name: spec.coerce(given.get(name, spec.default)) for name, spec in specs.items()}
        self._check(values)
        return values

    def build(self, **given: Any) -> ImpactProblem:
        """Build the impact problem of this scene at the given parameters.

        ``build_from(parameters(**given))``: each parameter is checked and converted once.

        Raises
        ------
        InvalidProblem
            For a bad parameter, or parameters whose geometry overflows floating point (the
            message names the parameters that differ from the defaults).
        """
        return self.build_from(self.parameters(**given))

    def build_from(self, params: Mapping[str, Any]) -> ImpactProblem:
        """Build the impact problem of this scene from complete, checked parameters.

        Parameters
        ----------
        params : mapping
            Every parameter, as `parameters` returns them.

        Raises
        ------
        InvalidProblem
            For parameters whose geometry overflows floating point, or that give a problem no
            law can take; the message names the parameters that differ from the defaults.
        """
        try:
            return self._build(dict(params))
        except (OverflowError, FloatingPointError) as exc:
            reason = f"the geometry overflows ({exc})"
        except InvalidProblem as exc:
            # The scene's formulas at these parameters left double precision, or gave a
            # problem no law can take.
            reason = str(exc)
        raise InvalidProblem(f"{self.name}: {self._changed(params)}: {reason}") from None

    def _changed(self, params: Params) -> str:
        """The parameters that differ from their defaults, as ``name = value`` (for messages)."""
        defaults = self.parameters()
        changed = [
            f"{name} = {value!r}"
            for name, value in params.items()
            if not np.array_equal(value, defaults.get(name))
        ]
        return ", ".join(changed) or "the defaults"

    def _check(self, params: dict[str, Any]) -> None:
        """Check relations between parameters (list lengths); raise `InvalidProblem`."""

    @abstractmethod
    def _build(self, params: dict[str, Any]) -> ImpactProblem:
        """Build the problem from complete, checked parameters."""

    @abstractmethod
    def coordinates(self, params: Params) -> list[str]:
        """Names of the generalized velocities, in order, with units."""

    def momentum_axes(self, params: Params) -> np.ndarray | None:
        """Generalized directions (k, n) along which the impact conserves momentum, or None."""
        return None


def per_item(params: dict[str, Any], name: str, count: int, what: str) -> None:
    """Expand ``params[name]`` to ``count`` entries: one value serves all; else count must match."""
    values = params[name]
    if len(values) == 1:
        params[name] = values * count
    elif len(values) != count:
        raise InvalidProblem(
            f"{name} has {len(values)} values, expected 1 or {count} (one per {what})"
        )


def exactly(params: Params, name: str, count: int, what: str) -> None:
    """Raise `InvalidProblem` unless ``params[name]`` has ``count`` entries."""
    if len(params[name]) != count:
        raise InvalidProblem(
            f"{name} has {len(params[name])} values, expected {count} (one per {what})"
        )


CASES: Registry[Case] = Registry("case", "lawbench.cases", Case)
