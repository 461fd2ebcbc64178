"""The law protocol: what every impact law declares and how it is called.

A law subclasses `Law`, declares its name, summary, source, tags, options, findings and
guarantees, and implements `Law._resolve`. `Law.resolve` does what is common to all of them: it
checks the options and the problem against the tags, restricts the problem to its closed contacts
(a contact with a positive gap is not part of this impact), solves a problem of extreme scale in
units near it and scales the answer back (`ImpactProblem.units`), times the solve within the
budget its options set, and refuses to return a non-finite answer.

The budget is what one solve may spend (`lawbench.core.guards`): `Law.resolve` opens a `Budget`
from the law's options for the time of the solve: ``max_seconds`` (every law has it),
``max_steps`` (a law that steps: integrator steps, fixed-point iterations, binary impacts) and
``max_events`` (a law that restarts at events), each when the law declares it. The law's loops
spend from `current_budget()` (the event integrator of `lawbench.numerics.integrator` does it for
the integrating laws; an iterative solver calls `Budget.step` once per iteration), and a budget
that runs out raises `BudgetExceeded` naming the option, its amount and the seconds spent, which
is what a budget cell of a table shows. `lawbench.core.guards.alarm` stops from outside a solve
that ignores its own (`lawbench.core.trial.make_trial` sets it).

A law is code from anywhere, so `Law.resolve` holds every answer of `Law._resolve` to what the
checks read: a `SystemExit` or `KeyboardInterrupt` raised by the law (not by the user's Ctrl-C)
and a `MemoryError` are a `SolverFailure` of that law; so are an answer that is no `Outcome`, or
whose ``v_plus``, ``Pn`` or ``Pt`` has the wrong length, a problem or options the law wrote into
(a digest taken before and after: for a law from outside lawbench's own packages it hashes
every number of the problem; for lawbench's own, whose tests hold them to their inputs, it
checks that the problem holds the same read-only arrays and frozen contacts), and reported
numbers that disagree with the answer's own velocities: ``T_minus`` and ``T_plus`` against
``v @ M @ v / 2``, and the impulses against the velocity change, ``Wn Pn + Wt Pt = M (v+ - v-)``,
each beyond its rounding (`lawbench.core.guards`).

A law that also solves Coulomb's frictional contact problem in contact space (FCLIB's local
form, `lawbench.core.contact.ContactProblem`: no generalized coordinates, only ``W``, ``q`` and
``mu``) implements `Law._solve_contact`; `Law.solve_contact` gives it the same checked options,
budget, timing and refusal of non-finite answers. The other laws refuse such a problem with
`NotApplicable`.
"""

from __future__ import annotations

import dataclasses
import functools
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from lawbench.core.contact import ContactProblem, ContactSolution
from lawbench.core.errors import (
    InvalidProblem,
    LawbenchError,
    NotApplicable,
    SolverFailure,
)
from lawbench.core.guards import (
    Watch,
    from_user,
    inputs,
    refuse_beyond_units,
    refuse_non_finite,
    user_interrupts,
    verify_answer,
)
from lawbench.core.outcome import Outcome, embedded, scaled_back
from lawbench.core.problem import ImpactProblem, forget_shared_contacts
from lawbench.core.registry import Registry
from lawbench.core.spec import Spec
from lawbench.core.tags import Tags
from lawbench.core.verdicts import Claim

if TYPE_CHECKING:
    from lawbench.core.batch import OutcomeBatch, ProblemBatch


# Friction coefficients below this are treated as zero, and the answer says so: their impulses
# (at most mu times the normal ones) move no velocity beyond the checks' rounding, while cones
# that thin leave the frictional solvers ill-conditioned.
NEGLIGIBLE_MU = 1e-9
# The largest dense copy of a sparse problem made for a law that works on dense matrices: the
# 100000-ball chain's mass matrix alone would take 75 GiB.
DENSE_BYTES = 2**31


# The modules of lawbench's own laws: the digest of what such a law receives leaves out the
# hash of the numbers (`lawbench.core.guards.inputs`), since its tests hold it to its inputs.
OWN_PACKAGE = "lawbench."


MAX_SECONDS = Spec(
    "max_seconds", 60.0, "wall-clock budget of one solve", unit="s", low=0.0, low_open=True
)


class Law(ABC):
    """Base class of the impact laws.

    Subclasses set the class attributes and implement `_resolve`, which receives a problem
    whose contacts are all closed and the complete, checked options. ``tags`` say what the law
    treats (`lawbench.core.tags.Tags`); ``findings`` and ``guarantees`` are `Claim` objects that
    decide the verdict of a failed check (`lawbench.core.verdicts`).
    """

    name: ClassVar[str]
    summary: ClassVar[str]
    source: ClassVar[str]
    tags: ClassVar[Tags]
    options: ClassVar[tuple[Spec, ...]] = ()
    # Studies the law declares, as data (`lawbench.studies.declared` builds them when asked).
    studies: ClassVar[tuple[dict[str, Any], ...]] = ()
    # Whether the law follows contacts through their gaps (resolves time): then it receives the
    # whole problem; otherwise only the closed contacts, an open one being no part of the impact.
    follows_gaps: ClassVar[bool] = False
    # What the law's theory says of the checks: where one fails as the theory predicts
    # (findings), and where one must hold, so that a failure there is numerical (guarantees).
    findings: ClassVar[tuple[Claim, ...]] = ()
    guarantees: ClassVar[tuple[Claim, ...]] = ()
    # How the law treats a closed contact that separates before the impact, stated in the
    # diagnostics of every problem that has one; a law that states no rule refuses them.
    separating_rule: ClassVar[str] = ""
    # Whether `_resolve` takes a sparse problem (scipy.sparse M, Wn and Delassus matrix); a law
    # that does not receives it with numpy arrays.
    takes_sparse: ClassVar[bool] = False
    # The roles the law plays in ``lawbench bench`` (`lawbench.bench.roles.ROLES`).
    bench_roles: ClassVar[tuple[str, ...]] = ()
    # Whether the law is a rigid-body engine stepping a scene's geometry (option ``settings``
    # names the engine's settings): ``lawbench bench`` times each engine at each setting.
    engine: ClassVar[bool] = False
    # Whether the law's answer in other units of mass, velocity and time is its answer scaled:
    # true of a law that reads no dimensional contact parameter but the stiffness and the gaps.
    # `resolve` then solves a problem of extreme scale in units near it (`ImpactProblem.units`)
    # and scales the answer back; a law that reads a damping solves in the problem's own units.
    scale_free: ClassVar[bool] = True
    # The contact fields (`lawbench.core.problem.Contact`) the law reads and a fit to measured
    # impacts may free, each within its `CONTACT_RANGES`; the others keep their values.
    fitted: ClassVar[tuple[str, ...]] = ("e",)

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Give every law the wall-clock budget ``max_seconds`` (`lawbench.core.law`)."""
        super().__init_subclass__(**kwargs)
        if not any(spec.name == MAX_SECONDS.name for spec in cls.options):
            cls.options = (*cls.options, MAX_SECONDS)

    def rule_for_separating(self, options: dict[str, Any]) -> str:
        """The rule for separating contacts under ``options`` (``separating_rule`` by default)."""
        return self.separating_rule

    def prepare(self, problem: object = None) -> None:
        """Do the one-time work of this process that a solve of ``problem`` needs (None: any).

        Compiling a law's kernels, or loading them from a cache, is a cost of the process, not
        of a solve: the one way into a solve (`lawbench.core.trial.make_trial`) calls this
        before the solve's wall-clock bound and budget start, and the study runner before its
        workers start. Nothing by default.
        """

    def refusal(self, problem: ImpactProblem | ProblemBatch) -> str | None:
        """Why this law cannot treat ``problem`` (a feature its tags do not cover), or None.

        A batch is refused for what its problems share (friction, spatial rows, contacts).
        """
        tags = self.tags
        if problem.frictional and not tags.friction:
            return "the problem has friction (mu > 0) and this law is frictionless"
        if problem.d == 2 and problem.frictional and not tags.spatial:
            return "the problem is spatial (two tangential directions) and this law is planar"
        if problem.closed_count > 1 and not tags.several_contacts:
            return f"the problem has {problem.closed_count} closed contacts and this law treats one"
        return None

    def option_values(self, given: dict[str, Any] | None = None) -> dict[str, Any]:
        """Return every option of this law, defaults filled in, checked and converted.

        Raises
        ------
        InvalidProblem
            For an unknown option name or a bad value.
        """
        if not given:
            return dict(self._defaults)
        given = dict(given)
        specs = {spec.name: spec for spec in self.options}
        unknown = sorted(set(given) - set(specs))
        if unknown:
            known = ", ".join(specs) or "none"
            raise InvalidProblem(
                f"unknown option {unknown[0]!r} for law {self.name!r}; known: {known}"
            )
        return {name: spec.coerce(given.get(name, spec.default)) for name, spec in specs.items()}

    @functools.cached_property
    def _defaults(self) -> dict[str, Any]:
        return {spec.name: spec.coerce(spec.default) for spec in self.options}

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
            With ``diagnostics['wall_time_s']`` and ``diagnostics['options']`` filled in, and
            ``diagnostics['warnings']`` where the solve raised warnings (a library's, or a
            floating-point overflow): they are kept with the answer, never printed; and
            ``diagnostics['units']`` where a scale-free law solved in other units of mass,
            velocity and time (its path and other diagnostics are in those units).

        Raises
        ------
        InvalidProblem
            For a bad option.
        NotApplicable
            When the law cannot treat the problem.
        SolverFailure
            When the numerical method fails or would return a non-finite number.
        """
        if not isinstance(problem, ImpactProblem):
            raise TypeError(f"problem must be an ImpactProblem, not {type(problem).__name__}")
        values = self.option_values(options)
        reason = self.refusal(problem)
        if reason:
            raise NotApplicable(f"{self.name}: {reason}")
        problem, negligible = _without_negligible_friction(problem)
        separating = problem.separating
        rule = self.rule_for_separating(values) if separating else ""
        if separating and not rule:
            raise NotApplicable(
                f"{self.name}: closed contacts {list(separating)} separate before the impact, "
                "and the law states no rule for them"
            )
        if problem.sparse and not self.takes_sparse:
            dense_bytes = 8 * problem.n * max(problem.n, problem.W.shape[1])
            if dense_bytes > DENSE_BYTES:
                raise NotApplicable(
                    f"{self.name}: works on dense matrices, and this problem's {problem.n} "
                    f"coordinates would take {dense_bytes / 2**30:.3g} GiB dense (at most "
                    f"{DENSE_BYTES / 2**30:g} GiB): a law that takes sparse problems treats it"
                )
            problem = problem.dense()
        units = problem.units if self.scale_free else (1.0, 1.0, 1.0)
        solved = problem if units == (1.0, 1.0, 1.0) else problem.in_units(*units)
        with Watch(self.name, values) as watch:
            outcome = self._resolve_closed(solved, values)
        if solved is not problem:
            outcome = scaled_back(outcome, problem, units)
            refuse_beyond_units(  # scaled back, a number may overflow
                self.name,
                units,
                v_plus=outcome.v_plus,
                Pn=outcome.Pn,
                Pt=outcome.Pt,
                T_plus=outcome.T_plus,
            )
        if problem.Wt is not None and outcome.Pt.size == 0:
            outcome = dataclasses.replace(outcome, Pt=np.zeros(problem.m * problem.d))
        outcome.diagnostics["options"] = values
        if negligible:
            outcome.diagnostics["negligible_friction"] = (
                f"mu below {NEGLIGIBLE_MU:g} at contacts {negligible} treated as 0"
            )
        if separating:
            outcome.diagnostics["separating_contacts"] = list(separating)
            outcome.diagnostics["separating_rule"] = rule
        outcome.diagnostics.update(watch.record)
        return outcome

    def _resolve_closed(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        """`_resolve` on the closed contacts only (all of them for a law that follows gaps)."""
        if problem.closed_count == problem.m or self.follows_gaps:
            return self._answer(problem, options)
        if problem.closed_count:
            closed = problem.closed
            return embedded(self._answer(problem.select_contacts(closed), options), closed, problem)
        outcome = Outcome.from_impulses(problem, np.zeros(problem.m))
        outcome.diagnostics["formulation"] = "no closed contact"
        return outcome

    def _answer(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        """`_resolve`, its answer held to what the checks read (see the module docstring)."""
        checksum = not type(self).__module__.startswith(OWN_PACKAGE)
        given = inputs(problem, options, checksum)
        before = user_interrupts()
        try:
            outcome = self._resolve(problem, options)
        except KeyboardInterrupt:
            if from_user(before):
                raise
            raise SolverFailure(f"{self.name}: the law raised KeyboardInterrupt") from None
        except SystemExit as exc:
            raise SolverFailure(f"{self.name}: the law called sys.exit({exc.code!r})") from None
        except MemoryError:
            raise SolverFailure(f"{self.name}: out of memory (MemoryError)") from None
        except LawbenchError:
            raise
        except Exception as exc:
            if not checksum:  # a bug of lawbench's own: an internal error, said as one
                raise
            raise SolverFailure(f"{self.name}: the law raised {_named(exc)}") from None
        except BaseException as exc:  # neither an error nor a stop: GeneratorExit, its own
            raise SolverFailure(f"{self.name}: the law raised {_named(exc)}") from None
        now = inputs(problem, options, checksum)
        if now != given:
            what = "problem" if now[0] != given[0] else "options"
            if what == "problem":
                forget_shared_contacts()
            raise SolverFailure(f"{self.name}: the law wrote into the {what} it was given")
        verify_answer(self.name, problem, outcome, own=not checksum)
        return outcome

    @abstractmethod
    def _resolve(self, problem: ImpactProblem, options: dict[str, Any]) -> Outcome:
        """Resolve a problem whose contacts are all closed."""

    @property
    def vectorizes_batches(self) -> bool:
        """Whether the law solves a `ProblemBatch` in a few numpy calls (`_resolve_batch`)."""
        return type(self)._resolve_batch is not Law._resolve_batch

    @property
    def solves_contact_problems(self) -> bool:
        """Whether the law solves a `ContactProblem` (it implements `_solve_contact`)."""
        return type(self)._solve_contact is not Law._solve_contact

    def solve_contact(self, problem: ContactProblem, **options: Any) -> ContactSolution:
        """Solve Coulomb's frictional contact problem ``problem`` in contact space.

        Parameters
        ----------
        problem : ContactProblem
            ``u = W r + q`` with De Saxce's complementarity per contact, ``W`` as given.
        **options
            The law's options (see ``options``).

        Returns
        -------
        ContactSolution
            The impulses, local velocities and FC3D error on the problem's own ``W`` and
            ``q``; diagnostics with ``wall_time_s``, ``options``, ``W_asymmetry`` and
            ``warnings`` where the solve raised any.

        Raises
        ------
        InvalidProblem
            For a bad option.
        NotApplicable
            When the law solves impacts in generalized coordinates only, or cannot treat this
            problem.
        SolverFailure
            When the numerical method fails or would return a non-finite number.
        """
        if not isinstance(problem, ContactProblem):
            raise TypeError(f"problem must be a ContactProblem, not {type(problem).__name__}")
        values = self.option_values(options)
        if not self.solves_contact_problems:
            raise NotApplicable(
                f"{self.name}: resolves impacts in generalized coordinates; a contact-space "
                "problem (FCLIB's local form: W, q and mu only) has none"
            )
        with Watch(self.name, values) as watch:
            r, diagnostics = self._solve_contact(problem, values)
        refuse_non_finite(self.name, r=r)
        diagnostics.update(watch.record, W_asymmetry=problem.asymmetry)
        return ContactSolution(r, problem.velocity(r), problem.error(r), diagnostics)

    def _solve_contact(
        self, problem: ContactProblem, options: dict[str, Any]
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """The impulses (FCLIB's order) and diagnostics of a contact-space problem."""
        raise NotApplicable(f"{self.name}: solves no contact-space problem")

    def resolve_batch(self, batch: ProblemBatch, **options: Any) -> OutcomeBatch:
        """Resolve every problem of ``batch``: vectorized where the law can, else one by one.

        Parameters
        ----------
        batch : ProblemBatch
            Problems of one shape, validated once.
        **options
            The law's options, checked once for the whole batch.

        Returns
        -------
        OutcomeBatch
            Equal to resolving each problem with `resolve`, to rounding;
            ``diagnostics['one_by_one']`` counts the problems the vectorized path left to
            `resolve`.

        Raises
        ------
        InvalidProblem, NotApplicable, SolverFailure
            As `resolve`: the law's refusal for the whole batch; one by one, the first problem
            that raises stops the batch.
        """
        values = self.option_values(options)
        reason = self.refusal(batch)
        if reason:
            raise NotApplicable(f"{self.name}: {reason}")
        batch = _batch_without_negligible_friction(batch)
        # Problems of extreme scale are rescaled one by one, by `resolve`.
        scaled = self.scale_free and not batch.in_own_units
        with Watch(self.name, values) as watch:
            answer = None if scaled else self._resolve_batch(batch, values)
            result = self._completed(batch, answer, values)
        refuse_non_finite(self.name, v_plus=result.v_plus)
        result.diagnostics.update(watch.record)
        return result

    def _completed(
        self,
        batch: ProblemBatch,
        answer: tuple[np.ndarray, str] | None,
        options: dict[str, Any],
    ) -> OutcomeBatch:
        """The outcomes of ``answer``'s impulses, and `resolve`'s for the problems it left."""
        from lawbench.core.batch import OutcomeBatch  # on first use: a single solve needs no batch

        size, m = len(batch), batch.m
        if answer is None:
            P, formulation = np.full((size, m + m * batch.d), np.nan), "one by one"
        else:
            P, formulation = answer
        alone = np.flatnonzero(np.isnan(P).any(axis=1))
        if alone.size == size:
            formulation = "one by one"
        result = OutcomeBatch.from_impulses(
            batch, P[:, :m], P[:, m:] if P.shape[1] > m else None, formulation=formulation
        )
        for k in alone:
            outcome = self.resolve(batch.problem(k), **options)
            result.v_plus[k], result.Pn[k], result.Pt[k] = outcome.v_plus, outcome.Pn, outcome.Pt
            result.T_minus[k], result.T_plus[k] = outcome.T_minus, outcome.T_plus
        result.diagnostics["one_by_one"] = int(alone.size)
        return result

    def _resolve_batch(
        self, batch: ProblemBatch, options: dict[str, Any]
    ) -> tuple[np.ndarray, str] | None:
        """The impulses of every problem and the formulation, or None to go one by one.

        The impulses are (B, m), normal only, or (B, m + m*d), normal then tangential in
        `ProblemBatch.contact_delassus`' order; a row of NaN leaves its problem to `resolve`
        (an ambiguous or refused one, whose answer or reason is the one-by-one path's). A law
        with a vectorized path overrides this; it must give the answer of `_resolve`.
        """
        return None


def _batch_without_negligible_friction(batch: ProblemBatch) -> ProblemBatch:
    """``batch`` with every mu below `NEGLIGIBLE_MU` set to 0, as `resolve` treats them."""
    mu = batch.mu
    negligible = (mu > 0) & (mu < NEGLIGIBLE_MU)
    if not negligible.any():
        return batch
    coefficients = {**batch.coefficients, "mu": np.where(negligible, 0.0, mu)}
    return dataclasses.replace(batch, coefficients=coefficients)


def _without_negligible_friction(problem: ImpactProblem) -> tuple[ImpactProblem, list[int]]:
    """``problem`` with every mu below `NEGLIGIBLE_MU` set to 0, and the contacts changed."""
    if problem.Wt is None:
        return problem, []
    negligible = [j for j, c in enumerate(problem.contacts) if 0 < c.mu < NEGLIGIBLE_MU]
    if not negligible:
        return problem, []
    contacts = [
        dataclasses.replace(c, mu=0.0) if j in negligible else c
        for j, c in enumerate(problem.contacts)
    ]
    return dataclasses.replace(problem, contacts=contacts), negligible


def _named(exc: BaseException) -> str:
    """``Type: message`` of an exception, or its type alone when it says nothing."""
    said = str(exc)
    return f"{type(exc).__name__}: {said}" if said else type(exc).__name__


LAWS: Registry[Law] = Registry("law", "lawbench.laws", Law)
