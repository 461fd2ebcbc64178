"""A law fitted on a measured set's training impacts and judged on its test impacts.

For each law, the contact fields it declares it reads (`Law.fitted`) are freed within their
`CONTACT_RANGES` and set alike on every contact of every impact; scipy's bounded least squares
(`lawbench.fitting.model.least_squares`) finds them on the training half, the residual of an
impact being ``L^T (v_pred - v_meas) / sqrt(v^T M v)`` (`lawbench.fitting.heldout.weights`),
and their uncertainty comes from the Jacobian at the optimum (`lawbench.fitting.uncertainty`).
The fitted law then predicts the test half, and so does the law at each published set of
coefficients the set's facts give (for a law all of whose fitted fields they give), and the two
baselines fitted on the same training impacts.

Every solve goes through `predict`: a law with a vectorized path (`Law.vectorizes_batches`)
solves the impacts of each shape as one `ProblemBatch` (its closed forms, exact), the others one
by one. Each law solves with its accuracy knob ``tol`` at `TOL` (far below the measurements'
noise) and a per-solve budget of `MAX_SECONDS`. A law that fits no friction coefficient is
refused on impacts measured with friction (a tangential row), and a law's own `NotApplicable`
refuses an impact; a `SolverFailure` is counted, its impact left out of the errors.

Cost: a fit solves the law tens of times per training impact. A law that follows the impact
through time (an engine stepping the set's geometry, or a law that reads the contacts'
stiffness: `lawbench.studies.study.costly`; milliseconds to hundreds of milliseconds a solve,
against microseconds for a closed form) is fitted on a fixed,
evenly spaced subsample of `COSTLY_FIT` training impacts and judged on every test impact
(`COSTLY_JUDGE`); the columns ``fitted_on`` and ``judged_on`` say so. The quick mode keeps `QUICK`
impacts of each half, evenly spaced, and `QUICK_COSTLY_FIT` and `QUICK_COSTLY_JUDGE` of them for
a law that integrates in time. Rows that refused or failed some impacts are ranked on the
impacts every row judged on all of them solved; a row judged on a subsample follows
(`ranked`). ``workers`` processes study the laws side by side.
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import time
from collections import Counter
from collections.abc import Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from lawbench.core.batch import COEFFICIENTS as BATCH_COEFFICIENTS
from lawbench.core.batch import ProblemBatch
from lawbench.core.errors import InvalidProblem, LawbenchError, NotApplicable, SolverFailure
from lawbench.core.law import LAWS, Law
from lawbench.core.problem import CONTACT_RANGES, MINDLIN_RATIO, Contact, ImpactProblem
from lawbench.core.spec import Spec
from lawbench.fitting import heldout
from lawbench.fitting.coefficients import Free, start_point
from lawbench.fitting.model import least_squares
from lawbench.fitting.uncertainty import FLAT_TOL, summarize
from lawbench.measurements import MEASUREMENTS, MeasuredImpact, MeasurementSet
from lawbench.studies.study import costly, evenly

# The accuracy knob of every law that has one, and the wall-clock budget of one solve.
TOL = 1e-6
MAX_SECONDS = 10.0
# The least squares' tolerances and finite-difference step, above the laws' accuracy at `TOL`. The
# fit stops where the cost, the coefficients or the gradient change by less than `FIT_TOL`
# relative: a Jacobian by differences of relative step `DIFF_STEP` resolves no finer. Asked for
# 1e-6, the compliant law's fit on the cube's quick impacts took 28 s for the coefficients it
# finds in 19 s at 1e-4, the same to 3e-4 (their standard errors: 0.05 and more).
FIT_TOL = 1e-4
DIFF_STEP = 1e-3
# Where each fitted field starts: inside its range, friction moderate, Mindlin's stiffness ratio;
# another field a law declares starts at the contact's default.
START = {"e": 0.5, "e_t": 0.0, "mu": 0.2, "tangential_stiffness_ratio": MINDLIN_RATIO}
# The impacts a law that integrates in time is fitted and judged on (None: every test impact, so
# that its held-out error is the other laws'; on the cube's 174, 154 s for the compliant law).
COSTLY_FIT = 8
COSTLY_JUDGE: int | None = None
# The same in the quick mode.
QUICK_COSTLY_FIT = 2
QUICK_COSTLY_JUDGE = 4
# The impacts of each half the quick mode keeps.
QUICK = 40
# The ``coefficients`` of a row whose coefficients were fitted on the training impacts.
FITTED = "fitted"
# The table's columns besides the fitted fields and their standard errors.
COLUMNS = (
    "law",
    "coefficients",
    "median_error",
    "common_error",
    "ci_low",
    "ci_high",
    "iqr",
    "normal_error",
    "tangential_error",
    "cost_s",
    "fitted_on",
    "judged_on",
    "refused",
    "failed",
    "reason",
    "wall_s",
)


@dataclass
class MeasuredStudy:
    """The study of laws on one measured set.

    Attributes
    ----------
    set_name : str
        The measurement set.
    table : DataFrame
        One row per law or baseline and coefficient source (``coefficients``: ``fitted`` or
        a published source's name), ranked by held-out median error on the test impacts every
        row solved (``common_error``; `COLUMNS`, with one column per fitted field and
        ``<field>_se`` for its standard error).
    common_count : int
        The impacts every row with an answer solved, where ``common_error`` is taken.
    predictions : DataFrame
        One row per judged impact and row of ``table``: ``law``, ``coefficients``, ``index``
        (the impact's index in its source), ``status`` (ok, refused, failed), the errors and
        the predicted and measured velocities (list columns).
    """

    set_name: str
    table: pd.DataFrame
    predictions: pd.DataFrame
    common_count: int = 0


def predict(
    law: Law,
    impacts: Sequence[MeasuredImpact],
    coefficients: Mapping[str, float],
    options: Mapping[str, Any],
) -> tuple[np.ndarray, dict[int, LawbenchError]]:
    """Solve each impact with ``coefficients`` set on every contact.

    Parameters
    ----------
    law : Law
        The law that resolves the impacts.
    impacts : sequence of MeasuredImpact
        Impacts of one number ``n`` of generalized coordinates.
    coefficients : mapping of str to float
        Contact fields and their values, set alike on every contact.
    options : mapping
        The law's options.

    Returns
    -------
    velocities : ndarray (impacts, n)
        The predicted velocities after; NaN in the rows of failures.
    failures : dict of int to LawbenchError
        Position of each impact the law refused (`NotApplicable`) or failed on
        (`SolverFailure`), with the error.
    """
    n = impacts[0].problem.n if impacts else 0
    velocities = np.full((len(impacts), n), np.nan)
    failures: dict[int, LawbenchError] = {}
    alone = list(range(len(impacts)))
    if law.vectorizes_batches and set(coefficients) <= set(BATCH_COEFFICIENTS):
        alone = _predict_batches(law, impacts, coefficients, options, velocities)
    for k in alone:
        try:
            outcome = law.resolve(with_coefficients(impacts[k].problem, coefficients), **options)
        except (NotApplicable, SolverFailure) as exc:
            failures[k] = exc
            continue
        velocities[k] = outcome.v_plus
    return velocities, failures


def with_coefficients(problem: ImpactProblem, coefficients: Mapping[str, float]) -> ImpactProblem:
    """``problem`` with ``coefficients`` set on every contact, and on its geometry's pairs."""
    contacts = tuple(dataclasses.replace(c, **coefficients) for c in problem.contacts)
    geometry = problem.geometry
    if geometry is not None:
        e = [c.restitution("kinematic") for c in contacts]
        geometry = geometry.with_coefficients(e, [c.mu for c in contacts])
    return dataclasses.replace(problem, contacts=contacts, geometry=geometry)


def _predict_batches(
    law: Law,
    impacts: Sequence[MeasuredImpact],
    coefficients: Mapping[str, float],
    options: Mapping[str, Any],
    velocities: np.ndarray,
) -> list[int]:
    """Solve the impacts of each shape as one `ProblemBatch`; return the positions left.

    A batch that raises (a problem the vectorized path leaves to the one-by-one solve, which
    refuses or fails it) is left whole to `predict`'s loop, which records each impact's error.
    """
    shapes: dict[tuple[int, int, int], list[int]] = {}
    for k, impact in enumerate(impacts):
        problem = impact.problem
        shapes.setdefault((problem.n, problem.m, problem.d), []).append(k)
    alone: list[int] = []
    for positions in shapes.values():
        stacked = ProblemBatch.from_problems([impacts[k].problem for k in positions])
        given = {
            name: np.full((len(positions), stacked.m), value)
            for name, value in coefficients.items()
        }
        try:
            batch = dataclasses.replace(stacked, coefficients={**stacked.coefficients, **given})
            velocities[positions] = law.resolve_batch(batch, **options).v_plus
        except LawbenchError:
            alone += positions
    return sorted(alone)


def free_fields(law: Law) -> list[Free]:
    """The law's fitted contact fields as free coefficients, bounded by `CONTACT_RANGES`.

    A field bounded only below by an excluded zero (a stiffness ratio) is fitted on a log
    scale, as `lawbench.fitting.coefficients` does for scene parameters.
    """
    ranges = {name: (low, high, positive) for name, low, high, positive in CONTACT_RANGES}
    free = []
    for name in law.fitted:
        low, high, positive = ranges[name]
        start = START.get(name, getattr(Contact(), name))
        spec = Spec(name, start, f"contact field {name}", low=low, high=high)
        log = positive and high is None
        free.append(Free(name, spec, None, low, math.inf if high is None else high, log))
    return free


class _Model:
    """A law's weighted predictions of measured impacts, as `least_squares` reads a model.

    A trial is a row of the impacts; its prediction is ``L^T v_pred / sqrt(v^T M v)``.
    """

    def __init__(self, law: Law, free: list[Free], impacts: Sequence[MeasuredImpact]) -> None:
        self.law, self.free, self.impacts = law, free, impacts
        self.options = study_options(law)
        self.weights = heldout.weights(impacts)
        # A failed solve of the fit stands for no impact at all: finite, and never better.
        self.fallback = np.array([i.problem.v for i in impacts])

    def params(self, x: np.ndarray) -> dict[str, float]:
        """The contact fields at the point ``x`` of the search."""
        return {f.name: f.to_value(float(xi)) for f, xi in zip(self.free, x, strict=True)}

    def predict(self, x: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """The weighted predictions of the impacts at ``rows``."""
        impacts = [self.impacts[r] for r in rows]
        velocities, failures = predict(self.law, impacts, self.params(x), self.options)
        for k in failures:
            velocities[k] = self.fallback[rows[k]]
        return np.einsum("kij,kj->ki", self.weights[rows], velocities)

    def targets(self) -> tuple[np.ndarray, np.ndarray]:
        """The weighted velocities before and measured after every impact."""
        before = np.einsum("kij,kj->ki", self.weights, self.fallback)
        after = np.einsum("kij,kj->ki", self.weights, np.array([i.v_after for i in self.impacts]))
        return before, after


def study_options(law: Law) -> dict[str, Any]:
    """The law's options in the study: ``tol`` at `TOL` where it has it, a budget per solve.

    An engine steps at its ``tuned`` settings, where ``e`` and ``mu`` set its own parameters
    (MuJoCo's solref damping, PyBullet's restitution and friction, Drake's Hunt-Crossley
    dissipation and friction): at their defaults MuJoCo and Drake ignore ``e``, and a fit of it
    finds nothing.
    """
    names = {spec.name for spec in law.options}
    given = {"tol": TOL} if "tol" in names else {}
    if law.engine:
        given["settings"] = "tuned"
    return law.option_values({**given, "max_seconds": MAX_SECONDS})


def measured_study(
    measured: str | MeasurementSet,
    laws: Sequence[str | Law] | None = None,
    quick: bool = False,
    workers: int = 1,
) -> MeasuredStudy:
    """Fit every law on a set's training impacts and judge it, with the baselines, on its test.

    Parameters
    ----------
    measured : str or MeasurementSet
        A registered set (``lawbench measurements`` lists them) or a set of one's own.
    laws : sequence of str or Law, optional
        The laws (default: every registered law).
    quick : bool
        Keep `QUICK` impacts of each half, evenly spaced (`QUICK_COSTLY_FIT` and
        `QUICK_COSTLY_JUDGE` for a law that integrates in time).
    workers : int
        Processes that study the laws side by side (1: in this process); the table is the
        same for any number.

    Returns
    -------
    MeasuredStudy
        The table ranked by held-out median error, and the per-impact predictions.

    Raises
    ------
    InvalidProblem
        An unknown set or law name, or fewer than one worker.
    """
    chosen = MEASUREMENTS.get(measured)
    law_objects = [LAWS.get(law) for law in (LAWS.names() if laws is None else laws)]
    if workers < 1:
        raise InvalidProblem(f"workers = {workers}: must be at least 1")
    halves = _Halves.of(chosen, quick)
    sources = heldout.published(chosen.facts)
    if workers == 1 or len(law_objects) < 2 or chosen.name not in MEASUREMENTS.names():
        studied = [_study_law(law, halves, sources) for law in law_objects]
    else:
        jobs = [(law.name, chosen.name, quick) for law in law_objects]
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=context) as pool:
            studied = list(pool.map(_study_law_by_name, jobs))
    rows: list[dict[str, Any]] = []
    predictions: list[pd.DataFrame] = []
    for results in studied:
        for row, judged in results:
            rows.append(row)
            predictions.append(judged)
    for name, basis in heldout.BASELINES.items():
        row, judged = _study_baseline(name, basis, halves)
        rows.append(row)
        predictions.append(judged)
    fields = list(dict.fromkeys(name for law in law_objects for name in law.fitted))
    columns = [*COLUMNS[:2], *fields, *(f"{f}_se" for f in fields), *COLUMNS[2:]]
    judged = pd.concat(predictions)
    table, common = ranked(pd.DataFrame(rows).reindex(columns=columns), judged)
    return MeasuredStudy(chosen.name, table, judged, common)


def _study_law_by_name(job: tuple[str, str, bool]) -> list[tuple[dict[str, Any], pd.DataFrame]]:
    """`_study_law` in a worker process, from the names of the law and the registered set."""
    law, measured, quick = job
    chosen = MEASUREMENTS.get(measured)
    return _study_law(LAWS.get(law), _Halves.of(chosen, quick), heldout.published(chosen.facts))


def ranked(table: pd.DataFrame, judged: pd.DataFrame) -> tuple[pd.DataFrame, int]:
    """The table with ``common_error``, ranked by it, and the number of impacts it is taken on.

    Rows that refused or failed some impacts are ranked on the impacts that every row offered
    all the test impacts solved (`_offered`): ``common_error`` is the median error there. A
    row judged on a subsample (a law that integrates in time, quick) has none and follows by
    ``median_error``: its few impacts would decide every rank, and its seconds the order.
    """
    rows, solved = ["law", "coefficients"], judged
    if len(judged):
        offered = _offered(table, judged)
        whole = judged.set_index(rows).index.isin(offered.index[offered == offered.max()])
        solved = judged[(judged["status"] == "ok").to_numpy() & whole]
    per_row = [set(group) for _, group in solved.groupby(rows)["index"]]
    common = set.intersection(*per_row) if per_row else set()
    medians = solved[solved["index"].isin(common)].groupby(rows)["error"].median()
    keys = zip(table["law"], table["coefficients"], strict=True)
    table["common_error"] = [medians.get(key, math.nan) for key in keys]
    table = table.sort_values(["common_error", "median_error"], na_position="last", kind="stable")
    return table.reset_index(drop=True), len(common)


def _offered(table: pd.DataFrame, judged: pd.DataFrame) -> pd.Series:
    """Per row of ``table`` (law, coefficients), the test impacts it was offered.

    Those it judged (answered, refused or failed while judging), and those it refused before
    (``refused`` counts both kinds of refusal): all the test impacts but for a subsample.
    """
    rows = ["law", "coefficients"]
    tried = judged.groupby(rows)["index"].nunique()
    refused_judging = judged[judged["status"] == "refused"].groupby(rows)["index"].nunique()
    refused = table.set_index(rows)["refused"].fillna(0).groupby(level=rows).max()
    before = (refused - refused_judging.reindex(refused.index, fill_value=0)).clip(lower=0)
    return tried.add(before.reindex(tried.index, fill_value=0), fill_value=0)


@dataclass(frozen=True)
class _Halves:
    """The training and test impacts of a study, and how they were chosen from the set."""

    train: list[MeasuredImpact]
    test: list[MeasuredImpact]
    train_total: int
    test_total: int
    quick: bool

    @classmethod
    def of(cls, measured: MeasurementSet, quick: bool) -> _Halves:
        train, test = list(measured.train), list(measured.test)
        if quick:
            return cls(evenly(train, QUICK), evenly(test, QUICK), len(train), len(test), True)
        return cls(train, test, len(train), len(test), False)

    @property
    def costly(self) -> tuple[int, int | None]:
        """How many impacts a law that integrates in time is fitted and judged on."""
        return (QUICK_COSTLY_FIT, QUICK_COSTLY_JUDGE) if self.quick else (COSTLY_FIT, COSTLY_JUDGE)

    def label(self, half: str, used: int, refused: int = 0) -> str:
        """How many impacts of ``half`` a row was fitted or judged on, and why not all."""
        total = self.train_total if half == "train" else self.test_total
        text = f"{half} {used}" if used == total else f"{half} {used} of {total} evenly spaced"
        text = f"{half} none of {total}" if not used else text
        text = f"quick: {text}" if self.quick else text
        return f"{text}, {refused} refused" if refused else text


def _screen(
    law: Law, impacts: Sequence[MeasuredImpact], coefficients: Mapping[str, float]
) -> tuple[list[MeasuredImpact], Counter[str]]:
    """The impacts the law may treat, and the reasons of those it refuses, with their counts.

    An impact measured with friction (a tangential row) is refused to a law that fits no
    friction coefficient; the others are put to the law's tags (`Tags.refusal`) with the
    ``coefficients`` set: what the law refuses whatever the coefficients' values.
    """
    kept, refused = [], Counter()
    for impact in impacts:
        problem = impact.problem
        if problem.Wt is not None and "mu" not in law.fitted:
            reason = "fits no friction coefficient, and the impacts were measured with friction"
        else:
            reason = law.refusal(with_coefficients(problem, coefficients))
        if reason:
            refused[f"{law.name}: {reason}"] += 1
        else:
            kept.append(impact)
    return kept, refused


def _study_law(
    law: Law, halves: _Halves, sources: Mapping[str, Mapping[str, float]]
) -> list[tuple[dict[str, Any], pd.DataFrame]]:
    """The rows of one law: fitted, then at each published source that gives all its fields."""
    started = time.perf_counter()
    free = free_fields(law)
    start = {f.name: f.spec.default for f in free}
    train, refused_train = _screen(law, halves.train, start)
    test, refused_test = _screen(law, halves.test, start)
    fitted = None
    fit_count, judge_count = halves.costly if costly(law) else (None, None)
    if train and test:
        fitted, fitted_on, refused_fit = _fit(law, free, start, evenly(train, fit_count))
        refused_train += refused_fit
    if fitted is None:
        row = _row(law.name, FITTED, np.zeros(0), heldout.Errors(*[np.zeros(0)] * 3))
        row.update(
            fitted_on=halves.label("train", 0, sum(refused_train.values())),
            judged_on=halves.label("test", 0, sum(refused_test.values())),
            refused=sum(refused_test.values()) or len(halves.test),
            reason=_reasons(refused_test or refused_train) or f"{law.name}: no impact to fit",
            wall_s=time.perf_counter() - started,
        )
        return [(row, pd.DataFrame())]
    judged = evenly(test, judge_count)
    results = []
    choices = {FITTED: fitted.values}
    choices.update(
        {name: dict(given) for name, given in sources.items() if set(law.fitted) <= set(given)}
    )
    for name, coefficients in choices.items():
        row, frame = _judge(law, name, judged, coefficients, refused_test)
        row.update(
            {f.name: coefficients[f.name] for f in free},
            fitted_on=halves.label("train", fitted_on, sum(refused_train.values())),
            judged_on=halves.label("test", len(judged), sum(refused_test.values())),
        )
        if name == FITTED:
            row.update({f"{f.name}_se": fitted.standard_errors[f.name] for f in free})
        results.append((row, frame))
    for row, _ in results:
        row["wall_s"] = time.perf_counter() - started
    return results


def _fit(
    law: Law, free: list[Free], start: Mapping[str, float], impacts: list[MeasuredImpact]
) -> tuple[Any, int, Counter[str]]:
    """The law's fields fitted on ``impacts``, how many it was fitted on, what it refused.

    An impact the law refuses at ``start`` is left out of the fit, its reason counted; the
    fit is None when the law refuses them all.
    """
    _, failures = predict(law, impacts, start, study_options(law))
    refused = Counter(str(e) for e in failures.values() if isinstance(e, NotApplicable))
    kept = [i for k, i in enumerate(impacts) if not isinstance(failures.get(k), NotApplicable)]
    if not kept:
        return None, 0, refused
    model = _Model(law, free, kept)
    before, after = model.targets()
    x0 = start_point(free, dict(start), {})
    rows = np.arange(len(kept))
    solution = least_squares(model, x0, rows, after, FIT_TOL, DIFF_STEP)
    return summarize(model, solution, before, after, None, FLAT_TOL), len(kept), refused


def _judge(
    law: Law,
    name: str,
    impacts: list[MeasuredImpact],
    coefficients: Mapping[str, float],
    refused_before: Counter[str],
) -> tuple[dict[str, Any], pd.DataFrame]:
    """The row and per-impact predictions of ``law`` at ``coefficients`` on ``impacts``."""
    began = time.perf_counter()
    velocities, failures = predict(law, impacts, coefficients, study_options(law))
    cost = (time.perf_counter() - began) / max(len(impacts), 1)
    ok = [k for k in range(len(impacts)) if k not in failures]
    solved = [impacts[k] for k in ok]
    errors = heldout.errors(solved, velocities[ok])
    refused = Counter(str(e) for e in failures.values() if isinstance(e, NotApplicable))
    failed = Counter(str(e) for e in failures.values() if not isinstance(e, NotApplicable))
    row = _row(law.name, name, errors.kinetic, errors)
    row.update(
        cost_s=cost,
        refused=sum((refused_before + refused).values()),
        failed=sum(failed.values()),
        reason=_reasons(refused_before + refused + failed),
    )
    frame = _frame(law.name, name, impacts, velocities, failures, errors)
    return row, frame


def _row(law: str, name: str, kinetic: np.ndarray, errors: heldout.Errors) -> dict[str, Any]:
    """The error columns of a table row from the per-impact errors."""
    return {
        "law": law,
        "coefficients": name,
        **heldout.summary(kinetic),
        "normal_error": float(np.median(errors.normal)) if len(errors.normal) else math.nan,
        "tangential_error": (
            float(np.median(errors.tangential)) if len(errors.tangential) else math.nan
        ),
        "refused": 0,
        "failed": 0,
        "reason": "",
    }


def _reasons(counts: Counter[str]) -> str:
    """The reasons of refusals and failures, most frequent first, each with its count."""
    return "; ".join(f"{reason} ({count})" for reason, count in counts.most_common())


def _frame(
    law: str,
    name: str,
    impacts: Sequence[MeasuredImpact],
    velocities: np.ndarray,
    failures: Mapping[int, LawbenchError],
    errors: heldout.Errors,
) -> pd.DataFrame:
    """One row per judged impact: its status, errors, and predicted and measured velocities."""
    status = [
        "ok"
        if k not in failures
        else ("refused" if isinstance(failures[k], NotApplicable) else "failed")
        for k in range(len(impacts))
    ]
    values = {key: np.full(len(impacts), np.nan) for key in ("error", "normal", "tangential")}
    ok = np.array([s == "ok" for s in status], dtype=bool)
    values["error"][ok], values["normal"][ok] = errors.kinetic, errors.normal
    values["tangential"][ok] = errors.tangential
    return pd.DataFrame(
        {
            "law": law,
            "coefficients": name,
            "index": [impact.index for impact in impacts],
            "status": status,
            "error": values["error"],
            "normal_error": values["normal"],
            "tangential_error": values["tangential"],
            "predicted": [v.tolist() for v in velocities],
            "measured": [impact.v_after.tolist() for impact in impacts],
        }
    )


def _study_baseline(name: str, basis: Any, halves: _Halves) -> tuple[dict[str, Any], pd.DataFrame]:
    """A baseline fitted on the training impacts and judged on the test impacts."""
    started = time.perf_counter()
    theta = heldout.fit_baseline(basis, halves.train)
    began = time.perf_counter()
    velocities = heldout.predict_baseline(basis, theta, halves.test)
    cost = (time.perf_counter() - began) / len(halves.test)
    errors = heldout.errors(halves.test, velocities)
    row = _row(name, FITTED, errors.kinetic, errors)
    row.update(
        cost_s=cost,
        fitted_on=halves.label("train", len(halves.train)),
        judged_on=halves.label("test", len(halves.test)),
        wall_s=time.perf_counter() - started,
    )
    return row, _frame(name, FITTED, halves.test, velocities, {}, errors)
