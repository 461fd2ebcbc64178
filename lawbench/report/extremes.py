"""The cells of the stability grid and their verdicts.

A cell is one law on one scene pushed to an extreme: a stiffness ratio, the striking ball's
mass over the others', a grazing approach, a long chain, a large friction, or a contact given
twice, each crossed with e = 0 and e = 1. Cells on a scene's own parameters are runner jobs;
the grazing and duplicated-contact problems are built here from a scene's problem:

- grazing: the pre-impact velocity changed along ``M^-1 Wn`` only, so that every gap rate is
  scaled by one factor and the fastest approach becomes ``speed``; the motion the contacts do
  not see (orthogonal in the kinetic metric: momentum of a free chain, slip of a sphere) stays;
- duplicated: contact 0 given twice (its normal and tangential columns and its parameters).

Verdicts: 'time-out' (no answer within the budget), 'NaN' (a non-finite number, caught by the
law or found in the answer), 'clear error' (a `LawbenchError`), 'unexpected error' (any other
exception), 'conservation broken' (momentum or energy error above the tolerance), 'check
failed' (finite and conserving, but a normal impulse is tensile, a contact approaches after
the impact, or a tangential impulse leaves its cone), or 'ok' (finite and correct).
Momentum error: the larger of the impulse-momentum residual ``|M (v+ - v-) - W P|`` and the
change of the conserved momentum (where the scene conserves it), over the largest momentum.
Energy error: ``|dT| / T-`` when every contact is elastic and frictionless (e = 1, mu = 0),
else the energy created ``max(dT, 0) / T-``. Tolerance: 1e-9, or 1000 times the law's numeric
accuracy knob when it has one (an integrated law is as accurate as its tolerance).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lawbench.case import Case
from lawbench.errors import InvalidProblem, LawbenchError
from lawbench.law import Law
from lawbench.problem import ImpactProblem
from lawbench.report.config import Config
from lawbench.report.runs import TIME_OUT_CLASS, Context, Job, array

TOLERANCE = 1e-9
CATEGORIES = (
    "ok",
    "check failed",
    "conservation broken",
    "clear error",
    "NaN",
    "time-out",
    "unexpected error",
)
UNACCEPTABLE = ("NaN", "time-out", "unexpected error")


@dataclass
class Cell:
    """One law on one scene at one extreme."""

    law: str
    axis: str
    case: str
    value: float
    e: float | None
    job: Job | None = None
    problem: ImpactProblem | None = None
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def row(self) -> str:
        """The label of the figure row this cell is drawn in."""
        e = "" if self.e is None else f", e={self.e:g}"
        return f"{self.axis} ({self.case}{e})"

    def reproducer(self) -> str:
        """How to solve this cell again."""
        sets = " ".join(f"--set {k}={_cli(v)}" for k, v in self.params.items())
        command = f"`lawbench solve {self.law} {self.case} {sets}`".replace(" `", "`")
        if self.axis == "grazing speed":
            return (
                f"{command} with the velocity made grazing: "
                f"`lawbench.report.extremes.grazing(problem, {self.value:g})`"
            )
        if self.axis == "duplicated contact":
            return f"{command} with `lawbench.report.extremes.duplicated(problem)`"
        return command


def _cli(value: Any) -> str:
    if isinstance(value, list):
        return ",".join(f"{x:g}" for x in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def grazing(problem: ImpactProblem, speed: float) -> ImpactProblem:
    """``problem`` with its gap rates scaled so that the fastest approach is ``speed``."""
    un = problem.un
    fastest = float(-un.min())
    if fastest <= 0:
        raise InvalidProblem("no contact approaches: nothing to make grazing")
    change, *_ = np.linalg.lstsq(problem.delassus, (speed / fastest - 1.0) * un, rcond=None)
    v = problem.v + problem.solve_mass(problem.Wn @ change)
    return dataclasses.replace(problem, v=v)


def duplicated(problem: ImpactProblem) -> ImpactProblem:
    """``problem`` with contact 0 given a second time (a redundant constraint)."""
    Wt = problem.Wt
    if Wt is not None:
        blocks = Wt.reshape(problem.n, problem.m, problem.d)
        Wt = np.concatenate([blocks, blocks[:, :1]], axis=1).reshape(problem.n, -1)
    return dataclasses.replace(
        problem,
        Wn=np.column_stack([problem.Wn, problem.Wn[:, 0]]),
        Wt=Wt,
        contacts=[*problem.contacts, problem.contacts[0]],
        gaps=np.append(problem.gaps, problem.gaps[0]),
    )


def param(case: Case, name: str, value: float) -> Any:
    """``value`` in the form ``case``'s parameter ``name`` takes, or None when it cannot."""
    spec = next((s for s in case.params if s.name == name), None)
    if spec is None:
        return None
    value = [value] if spec.kind == "floats" else value
    try:
        spec.coerce(value)
    except InvalidProblem:
        return None
    return value


def _restitutions(case: Case, config: Config) -> list[tuple[float | None, dict[str, Any]]]:
    """Each configured e in the scene's form; one cell at its default when it has no e."""
    forms = [(e, param(case, "e", e)) for e in config.restitutions]
    found = [(e, {"e": form}) for e, form in forms if form is not None]
    return found or [(None, {})]


def plan(ctx: Context) -> tuple[list[Cell], list[str]]:
    """Every cell of the grid, and notes on the scenes it could not use."""
    config, cells, notes = ctx.config, [], []

    def scene(name: str) -> Case | None:
        case = ctx.case(name)
        if case is None:
            notes.append(f"scene `{name}` is not registered")
        return case

    for name in config.stiffness_cases:
        if case := scene(name):
            ratios = config.stiffness_ratios
            cells += _job_cells(ctx, case, "stiffness ratio", "stiffness_ratio", ratios)
    three, chain = scene("three_ball_chain"), scene("ball_chain")
    for law in ctx.laws:
        if law.tags.several_contacts and three:
            cells += _mass_cells(law, three, config, lambda r: {"masses": [r, 1.0, 1.0]})
        elif chain:
            cells += _mass_cells(law, chain, config, lambda r: {"n": 2, "masses": [r, 1.0]})
    if chain:
        cells += _job_cells(ctx, chain, "chain length", "n", config.chain_lengths)
    for case in ctx.cases:
        if case.requires.friction and any(s.name == "mu" for s in case.params):
            cells += _job_cells(ctx, case, "friction", "mu", config.frictions)
    for axis, names, values in (
        ("grazing speed", config.grazing_cases, config.grazing_speeds),
        ("duplicated contact", config.redundant_cases, (2.0,)),
    ):
        for name in names:
            if not (case := scene(name)):
                continue
            try:
                cells += _problem_cells(ctx, case, axis, values)
            except LawbenchError as exc:
                notes.append(f"no {axis} cells on `{name}`: {exc}")
    return cells, sorted(set(notes))


def _job_cells(
    ctx: Context, case: Case, axis: str, name: str, values: tuple[float, ...]
) -> list[Cell]:
    cells = []
    for law in ctx.laws:
        if not law.tags.covers(case.requires):
            continue
        for value in values:
            form = param(case, name, value)
            if form is None:
                continue
            for e, extra in _restitutions(case, ctx.config):
                params = {name: form, **extra}
                job = Job(law.name, case.name, params)
                cells.append(Cell(law.name, axis, case.name, float(value), e, job, None, params))
    return cells


def _mass_cells(law: Law, case: Case, config: Config, masses: Any) -> list[Cell]:
    cells = []
    for ratio in config.mass_ratios:
        for e, extra in _restitutions(case, config):
            params = {**masses(ratio), **extra}
            job = Job(law.name, case.name, params)
            cells.append(Cell(law.name, "mass ratio", case.name, ratio, e, job, None, params))
    return cells


def _problem_cells(ctx: Context, case: Case, axis: str, values: tuple[float, ...]) -> list[Cell]:
    cells = []
    for e, extra in _restitutions(case, ctx.config):
        base = case.build(**extra)
        for value in values:
            problem = grazing(base, value) if axis == "grazing speed" else duplicated(base)
            for law in ctx.laws:
                if law.tags.covers(case.requires):
                    cells.append(Cell(law.name, axis, case.name, value, e, None, problem, extra))
    return cells


def _tolerance(law: Law, options: dict[str, Any]) -> float:
    knob = law.tags.accuracy_knob
    value = law.option_values(options).get(knob) if knob else None
    if isinstance(value, float):
        return max(TOLERANCE, 1e3 * value)
    return TOLERANCE


LAWBENCH_ERRORS = {LawbenchError.__name__} | {
    kind.__name__ for kind in LawbenchError.__subclasses__()
}


def verdict(
    cell: Cell, record: dict[str, Any], problem: ImpactProblem, axes: Any, law: Law, budget: float
) -> dict[str, Any]:
    """The verdict of a cell from its record, with its momentum and energy errors."""
    error_class = record.get("error_class") or ""
    message = str(record.get("error_message") or "")
    result = {"momentum_error": np.nan, "energy_error": np.nan, "detail": message}
    if error_class == TIME_OUT_CLASS or (record.get("wall_time_s") or 0.0) > budget:
        return {**result, "verdict": "time-out", "detail": message or "over the budget"}
    if error_class:
        if "non-finite" in message or "nan" in message.lower().split():
            kind = "NaN"
        else:
            kind = "clear error" if error_class in LAWBENCH_ERRORS else "unexpected error"
        return {**result, "verdict": kind, "detail": f"{error_class}: {message}"}
    v_plus, Pn, Pt = (array(record, key) for key in ("v_plus", "Pn", "Pt"))
    if not all(np.isfinite(x).all() for x in (v_plus, Pn, Pt)):
        return {**result, "verdict": "NaN", "detail": "non-finite answer"}
    tolerance = _tolerance(law, cell.job.options if cell.job else {})
    momentum, energy = _errors(problem, axes, v_plus, Pn, Pt)
    result.update(momentum_error=momentum, energy_error=energy, detail=record.get("warnings", ""))
    if momentum > tolerance or energy > tolerance:
        created = " (energy created)" if record.get("dT", 0.0) > 0 else ""
        text = f"momentum error {momentum:.2g}, energy error {energy:.2g}{created}"
        return {**result, "verdict": "conservation broken", "detail": text}
    failed = _failed_checks(problem, v_plus, Pn, Pt, tolerance)
    if failed:
        return {**result, "verdict": "check failed", "detail": ", ".join(failed)}
    return {**result, "verdict": "ok"}


def _errors(
    problem: ImpactProblem, axes: Any, v_plus: np.ndarray, Pn: np.ndarray, Pt: np.ndarray
) -> tuple[float, float]:
    M, v = problem.M, problem.v
    change = M @ (v_plus - v)
    impulse = problem.Wn @ Pn + (problem.Wt @ Pt if Pt.size else 0.0)
    scale = max(float(np.abs(M @ v).max()), float(np.abs(M @ v_plus).max()), 1e-300)
    momentum = float(np.abs(change - impulse).max())
    if axes is not None:
        momentum = max(momentum, float(np.abs(axes @ change).max()))
    T_minus = float(v @ M @ v) / 2
    dT = float(v_plus @ M @ v_plus) / 2 - T_minus
    elastic = bool((problem.restitution("newton") == 1.0).all() and not problem.mu.any())
    energy = (abs(dT) if elastic else max(dT, 0.0)) / T_minus
    return momentum / scale, energy


def _failed_checks(
    problem: ImpactProblem, v_plus: np.ndarray, Pn: np.ndarray, Pt: np.ndarray, tolerance: float
) -> list[str]:
    failed = []
    impulse = max(float(np.abs(Pn).max()), 1e-300)
    if Pn.min() < -tolerance * impulse:
        failed.append(
            f"impulse sign (Pn = {Pn.min():.3g}, {Pn.min() / impulse:.2g} of the largest)"
        )
    speed = max(float(np.abs(problem.v).max()), float(np.abs(v_plus).max()))
    rounding = 1e-12 * speed * float(np.abs(problem.Wn).sum(axis=0).max())
    un_plus = problem.Wn.T @ v_plus
    if un_plus.min() < -(tolerance * float(np.abs(problem.un).max()) + rounding):
        failed.append(f"admissible (un+ = {un_plus.min():.3g} after the impact)")
    if Pt.size and problem.d:
        tangential = np.linalg.norm(Pt.reshape(problem.m, problem.d), axis=1)
        excess = float((tangential - problem.mu * Pn).max())
        if excess > tolerance * impulse:
            failed.append(
                f"friction cone (|Pt| - mu Pn = {excess / impulse:.2g} of the largest Pn)"
            )
    return failed
