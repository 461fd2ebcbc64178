"""Checks that read one trial, and what every check reads and returns, with their registry.

A check function reads a `Trial` and returns ``(value, passed, detail)``: ``passed`` None when
the check does not apply (the detail says why). `run_checks` turns that raw result into a
verdict of the taxonomy (`lawbench.core.verdicts`) from the law's findings and guarantees.

The single-solve checks here: energy, admissibility, impulses, friction, momentum and
references; the checks that solve again register themselves through `check` from their own
modules. They read the answer's velocities, never what a law says about itself: the energies
are ``v @ M @ v / 2`` of the problem's ``v`` and the answer's ``v_plus``, and the impulses are
judged only as a decomposition of the velocity change, ``Wn Pn + Wt Pt = M (v+ - v-)``
(`Law.resolve` refuses an answer whose impulses are not one; a trial made otherwise fails the
impulse checks). `broken_promise` is the judge this module registers with the one way into a
solve (`lawbench.core.trial.PROMISES`): an answer with a numerical failure is refused there.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.core.case import Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.guards import CONSISTENCY
from lawbench.core.law import Law
from lawbench.core.metric import is_sparse
from lawbench.core.outcome import gap_rates, generalized_impulse
from lawbench.core.problem import RESTITUTION_FIELDS, ImpactProblem
from lawbench.core.trial import PROMISES, Trial, make_trial
from lawbench.core.verdicts import Claim, Verdict

if TYPE_CHECKING:
    import pandas as pd

# Relative tolerance of the verdicts: a law that is exact must pass them to rounding.
TOLERANCE = 1e-9


@dataclass(frozen=True)
class CheckResult:
    """A check's value, raw result, verdict and reason.

    Attributes
    ----------
    name : str
        The check.
    value : float or None
        What it measured; None when it does not apply.
    passed : bool or None
        Its raw result; None when it does not apply.
    detail : str
        The reason, in words.
    verdict : Verdict
        The class of the taxonomy.
    claim : Claim or None
        The finding or guarantee of the law that decided a failed check's verdict.
    """

    name: str
    value: float | None
    passed: bool | None
    detail: str
    verdict: Verdict = Verdict.UNEXPLAINED
    claim: Claim | None = None

    def as_dict(self) -> dict[str, Any]:
        """The JSON form: value, raw result, verdict, detail and the deciding claim's reason."""
        return {
            "value": self.value,
            "passed": self.passed,
            "verdict": str(self.verdict),
            "detail": self.detail,
            "claim": self.claim.describe() if self.claim else None,
        }


class CheckResults(dict[str, CheckResult]):
    """Check name -> result, as `run_checks` returns them, with a tidy frame and HTML view."""

    def to_frame(self) -> pd.DataFrame:
        """One row per check: name, verdict, value, raw result, detail, deciding claim.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        rows = [{"check": name, **result.as_dict()} for name, result in self.items()]
        columns = ["check", "verdict", "value", "passed", "detail", "claim"]
        return pd.DataFrame(rows, columns=columns)

    def _repr_html_(self) -> str:
        return self.to_frame().to_html(index=False)


def judge(trial: Trial, check: str, passed: bool | None, promised: bool) -> tuple[Verdict, Any]:
    """The verdict of a check's raw result on ``trial``, and the claim that decided it.

    Parameters
    ----------
    trial : Trial
        The solve the check read.
    check : str
        The check's name.
    passed : bool or None
        The check's result; None when it does not apply.
    promised : bool
        Whether every law promises this check everywhere.
    """
    if passed is None:
        return Verdict.REFUSED, None
    if passed:
        return Verdict.HOLDS, None
    for claim in trial.law.findings:
        if claim.check == check and claim.region(trial):
            return Verdict.LAW_PROPERTY, claim
    for claim in trial.law.guarantees:
        if claim.check == check and claim.region(trial):
            return Verdict.NUMERICAL_FAILURE, claim
    if promised:
        return Verdict.NUMERICAL_FAILURE, None
    return Verdict.UNEXPLAINED, None


Check = Callable[[Trial], CheckResult]
CHECKS: dict[str, Check] = {}
# The checks that read the one outcome of a trial; the others solve the problem again.
SINGLE_SOLVE: list[str] = []
# The checks that run only where a study names them, never among "every check".
ON_REQUEST: list[str] = []


def check(
    name: str, several_solves: bool = False, promised: bool = False, on_request: bool = False
) -> Callable[[Callable[[Trial], tuple]], Check]:
    """Register a function returning ``(value, passed, detail)`` as the check ``name``.

    The function returns ``(None, None, reason)`` when the check does not apply.
    ``several_solves`` marks a check that solves the problem again (costly).
    ``promised`` marks a check every law promises everywhere (a failure is numerical unless a
    finding of the law says otherwise).
    ``on_request`` marks a check that runs only in the studies that name it (`ON_REQUEST`).
    """

    def register(function: Callable[[Trial], tuple]) -> Check:
        def run(trial: Trial) -> CheckResult:
            value, passed, detail = function(trial)
            verdict, claim = judge(trial, name, passed, promised)
            return CheckResult(name, value, passed, detail, verdict, claim)

        run.__doc__ = function.__doc__
        CHECKS[name] = run
        if on_request:
            ON_REQUEST.append(name)
        elif not several_solves:
            SINGLE_SOLVE.append(name)
        return run

    return register


def run_checks(
    law: str | Law | Trial,
    case: str | Case | ImpactProblem | None = None,
    options: Mapping[str, Any] | None = None,
    *,
    checks: str | Sequence[str] | None = None,
    **params: Any,
) -> CheckResults:
    """Solve ``law`` on a scene or a problem, as `lawbench.solve` does, and run the checks.

    Parameters
    ----------
    law : str, Law or Trial
        A registered law name or a law object; or a trial already solved (`lawbench.evaluate`),
        given alone.
    case : str, Case or ImpactProblem
        A registered scene name, a scene object, or an impact problem of your own.
    options : mapping, optional
        The law's options.
    checks : str or sequence of str, optional
        The checks to run, in order; by default every single-solve check.
    **params
        The scene's parameters; the others take their defaults.

    Returns
    -------
    CheckResults
        Check name -> result.

    Raises
    ------
    TypeError
        An argument of the wrong type, or a trial given with a scene, options or parameters.
    InvalidProblem
        An unknown check, or what `lawbench.solve` raises for bad input.

    Examples
    --------
    >>> import lawbench
    >>> results = lawbench.run_checks("newton", "three_ball_chain", e=0.5)
    >>> str(results["energy_gain"].verdict)
    'holds'
    """
    if isinstance(law, Trial):
        given = {"case": case, "options": options, **params}
        extra = {name: value for name, value in given.items() if value is not None}
        if extra:
            name, value = next(iter(extra.items()))
            raise TypeError(
                f"run_checks() takes a trial alone, but {name} was given with it ({value!r}); "
                "name the checks with checks=[...]"
            )
        trial = law
    elif case is None:
        raise TypeError(
            "run_checks() needs the argument case (a scene name, a Case or an ImpactProblem) "
            "with a law, or a trial alone"
        )
    else:
        trial = make_trial(law, case, params=params, options=options, judged=False)
    return CheckResults({name: _checked(trial, name) for name in _check_names(checks)})


def _checked(trial: Trial, name: str) -> CheckResult:
    """The result of check ``name`` on ``trial``, computed once per trial."""
    if name not in trial.checked:
        trial.checked[name] = CHECKS[name](trial)
    return trial.checked[name]


def broken_promise(trial: Trial) -> str:
    """Why the answer of ``trial`` breaks a promise, or '' (the judge of `PROMISES`).

    A promise is broken where a single-solve check is a numerical failure: it fails where a
    guarantee of the law, or a promise of every law, says it holds.
    """
    for name, result in run_checks(trial).items():
        if result.verdict == Verdict.NUMERICAL_FAILURE:
            promise = f" ({result.claim.describe()})" if result.claim else ""
            return f"{trial.law.name}: {name} fails where it must hold{promise}: {result.detail}"
    return ""


PROMISES.append(broken_promise)


def _check_names(checks: object) -> list[str]:
    """The argument ``checks`` as a list of known check names (every single-solve one if None)."""
    if checks is None:
        return list(SINGLE_SOLVE)
    names = [checks] if isinstance(checks, str) else checks
    if not isinstance(names, Sequence) or not all(isinstance(n, str) for n in names):
        raise TypeError(f"checks must be a check name or a sequence of them, not {checks!r}")
    unknown = [name for name in names if name not in CHECKS]
    if unknown:
        raise InvalidProblem(f"unknown check {unknown[0]!r}; known: {', '.join(CHECKS)}")
    return list(names)


# References are closed forms; the laws they describe are exact up to solver polishing.
REFERENCE_TOLERANCE = 1e-8
# Rounding allowed on a gap rate, relative to the sum of the velocities it is the difference of.
ROUNDING = 1e3 * float(np.finfo(float).eps)


def _scale(values: np.ndarray) -> float:
    return float(np.abs(values).max()) if values.size and np.abs(values).max() > 0 else 1.0


def _energies(trial: Trial) -> tuple[float, float, float]:
    """``dT``, ``T-`` and ``dT / T-`` (``dT`` when T- = 0) from the velocities before and after."""
    problem = trial.problem
    T_minus = problem.T_minus
    dT = problem.kinetic_energy(trial.outcome.v_plus) - T_minus
    return dT, T_minus, dT / T_minus if T_minus > 0 else dT


@check("energy_gain")
def energy_gain(trial: Trial) -> tuple:
    """Relative kinetic energy change ``dT / T-``; passes unless energy is created."""
    dT, T_minus, relative = _energies(trial)
    passed = relative <= TOLERANCE
    verb = "creates" if not passed else "keeps or dissipates"
    return relative, passed, f"{verb} energy: dT = {dT:.6g} J, T- = {T_minus:.6g} J"


@check("energy_kept")
def energy_kept(trial: Trial) -> tuple:
    """Relative kinetic energy change ``dT / T-`` of an elastic, frictionless impact.

    It applies where no contact has friction and every closed contact is elastic (e = 1 in
    Newton's, Poisson's and the energetic sense alike), where a law that keeps energy must
    keep it to rounding.
    """
    problem = trial.problem
    if problem.frictional:
        return None, None, "some contact has friction"
    closed = problem.closed
    if not all((problem.restitution(kind)[closed] == 1.0).all() for kind in RESTITUTION_FIELDS):
        return None, None, "some closed contact is not elastic (e < 1)"
    dT, T_minus, relative = _energies(trial)
    passed = abs(relative) <= TOLERANCE
    verb = "keeps" if passed else ("loses" if relative < 0 else "creates")
    return relative, passed, f"{verb} energy: dT = {dT:.6g} J, T- = {T_minus:.6g} J"


@check("admissible", promised=True)
def admissible(trial: Trial) -> tuple:
    """Smallest post-impact gap rate of the closed contacts over the pre-impact contact speed.

    The speed is the largest pre-impact contact velocity, normal or tangential: a grazing
    approach is judged against the speed at which the contact moves. Gap rates are
    differences of body velocities, so rounding of the order of ``ROUNDING |Wn|^T |v+|`` is
    allowed as well.
    """
    problem = trial.problem
    closed = problem.closed
    if not closed.any():
        return None, None, "no closed contact"
    speed = _scale(np.concatenate([problem.un[closed], problem.ut]))
    v_plus = trial.outcome.v_plus
    after = gap_rates(problem, v_plus)[closed]
    rounding = ROUNDING * float((abs(problem.Wn).T @ np.abs(v_plus))[closed].max())
    value = float(after.min()) / speed
    worst = int(np.flatnonzero(closed)[np.argmin(after)])
    if after.min() >= -(TOLERANCE * speed + rounding):
        return value, True, "no closed contact approaches after the impact"
    return value, False, f"contact {worst} approaches after the impact (un+ = {after.min():.6g})"


# Relative mismatch between ``Wn Pn + Wt Pt`` and ``M (v+ - v-)`` beyond which the impulses are
# not those of the velocity change (`lawbench.core.law.CONSISTENCY`, which `Law.resolve` holds).
IMPULSE_MISMATCH = CONSISTENCY


def _unexplained_impulses(trial: Trial) -> str:
    """Why the answer's impulses are not a decomposition of its velocity change, or ''."""
    problem, outcome = trial.problem, trial.outcome
    change = problem.M @ (outcome.v_plus - problem.v)
    impulse = generalized_impulse(problem, outcome.Pn, outcome.Pt)
    scale = max(_scale(problem.M @ problem.v), _scale(change), _scale(impulse))
    mismatch = float(np.abs(impulse - change).max()) / scale
    if mismatch <= IMPULSE_MISMATCH:
        return ""
    return (
        f"the impulses are not those of the velocity change: |Wn Pn + Wt Pt - M (v+ - v-)| is "
        f"{mismatch:.3g} of the momenta"
    )


@check("impulse_sign", promised=True)
def impulse_sign(trial: Trial) -> tuple:
    """Smallest normal impulse over the largest one; a negative impulse is tensile.

    The impulses judged are the answer's, once they are shown to produce its velocity change.
    """
    unexplained = _unexplained_impulses(trial)
    if unexplained:
        return None, False, unexplained
    Pn = trial.outcome.Pn
    value = float(Pn.min()) / _scale(Pn)
    if value >= -TOLERANCE:
        return value, True, "every normal impulse pushes apart"
    return value, False, f"contact {int(np.argmin(Pn))} has a tensile impulse {Pn.min():.6g}"


@check("friction_cone", promised=True)
def friction_cone(trial: Trial) -> tuple:
    """Largest excess ``|Pt_j| - mu_j Pn_j`` over the largest impulse; <= 0 inside the cones."""
    problem, outcome = trial.problem, trial.outcome
    if problem.Wt is None:
        return None, None, "the scene has no tangential direction (frictionless)"
    unexplained = _unexplained_impulses(trial)
    if unexplained:
        return None, False, unexplained
    # In units of the largest impulse, where the norms of impulses near 1e308 do not overflow;
    # a contact deep inside a wide cone (mu = 1e300) counts as an excess of -1 at most.
    scale = _scale(np.concatenate([outcome.Pn, outcome.Pt]))
    tangential = np.linalg.norm(outcome.Pt.reshape(problem.m, problem.d) / scale, axis=1)
    with np.errstate(over="ignore"):
        excess = np.maximum(tangential - problem.mu * (outcome.Pn / scale), -1.0)
    value = float(excess.max())
    if value <= TOLERANCE:
        return value, True, "every tangential impulse lies in its friction cone"
    j = int(np.argmax(excess))
    return (
        value,
        False,
        (
            f"contact {j}: |Pt| = {tangential[j] * scale:.6g} exceeds mu Pn = "
            f"{problem.mu[j] * outcome.Pn[j]:.6g}"
        ),
    )


# Coordinates up to which the momentum check finds a problem's free directions by a dense SVD
# (a 2000 x 2000 SVD takes a few seconds).
FREE_DIRECTIONS_N = 2000


@check("momentum", promised=True)
def momentum(trial: Trial) -> tuple:
    """Largest change of a conserved momentum over the largest momentum.

    The conserved momenta are the scene's (``Case.momentum_axes``), or for a problem given as it
    is, every ``a @ M @ v`` with ``W.T @ a = 0``: the directions no contact impulse can push,
    from a dense SVD of ``W`` up to `FREE_DIRECTIONS_N` coordinates.
    """
    M, v = trial.problem.M, trial.problem.v
    if trial.case is not None:
        axes = trial.case.momentum_axes(trial.params)
    elif trial.problem.n > FREE_DIRECTIONS_N:
        return (
            None,
            None,
            (
                f"a problem of {trial.problem.n} coordinates given without its scene: its free "
                f"directions are computed up to {FREE_DIRECTIONS_N}"
            ),
        )
    else:
        import scipy.linalg  # on first use: a scene's solve and check import no scipy.linalg

        W = trial.problem.W
        free = scipy.linalg.null_space((W.toarray() if is_sparse(W) else W).T)
        axes = free.T if free.size else None
    if axes is None:
        return None, None, "no momentum is conserved (a wall or a fixed point)"
    change = axes @ M @ (trial.outcome.v_plus - v)
    value = float(np.abs(change).max()) / _scale(M @ v)
    passed = value <= TOLERANCE
    return value, passed, f"momentum change {np.abs(change).max():.3g} kg m/s"


@check("reference", promised=True)
def reference(trial: Trial) -> tuple:
    """Largest error of ``v_plus`` against every reference that describes this run."""
    if trial.case is None:
        return None, None, "a problem given as it is has no references"
    errors, reasons = {}, []
    scale = max(float(np.abs(trial.problem.v).max()), 1e-300)
    for ref in trial.case.references:
        reason = ref.applies(trial.law.name, trial.outcome.diagnostics["options"], trial.params)
        if reason:
            reasons.append(f"{ref.name}: {reason}")
            continue
        expected = np.asarray(ref.v_plus(trial.params), dtype=float)
        errors[ref.name] = float(np.abs(trial.outcome.v_plus - expected).max()) / scale
    if not errors:
        return None, None, "no reference applies" + (f" ({'; '.join(reasons)})" if reasons else "")
    worst = max(errors, key=errors.get)
    passed = errors[worst] <= REFERENCE_TOLERANCE
    sources = ", ".join(f"{name} ({error:.2g})" for name, error in errors.items())
    return errors[worst], passed, f"relative error against {sources}"
