"""Run specifications: grids of laws x cases x parameters x options, expanded deterministically.

A specification is a TOML file (or the same built from the command line)::

    seed = 0                                  # random samples are drawn from this seed
    checks = ["energy_gain", "continuity"]    # optional; default: every single-solve check

    [[grid]]
    laws = ["newton", "moreau"]               # or ["*"]: every law that can treat the case
    cases = ["three_ball_chain"]              # or ["*"]
    params = { e = [0.0, 0.5, 1.0], stiffness_ratio = { logrange = [-3, 3, 7] } }
    options = { moreau = { tol = [1e-6, 1e-10] } }

    [[grid]]
    cases = ["*"]
    examples = true                           # each case's named examples as parameter sets

    [[grid]]
    cases = ["three_ball_chain"]
    transforms = ["grazing=1e-08", "duplicated"]   # lawbench.transforms, one per row

A parameter or option takes a list of values, one value, ``{range = [start, stop, count]}``
(evenly spaced), ``{logrange = [start_exponent, stop_exponent, count]}`` (powers of ten), or
``{random = [low, high, count], log = false, size = 1}`` (uniform samples, drawn from the
spec's seed and the grid, parameter and draw position, so the same spec always gives the same
values; ``size`` > 1 draws vectors). Rows are the Cartesian product in the order written:
cases, then laws, then parameters, then options, then transforms. Every row is checked before
any work: an unknown name or a value out of range raises `InvalidProblem`. A row is a
`lawbench.study.Job`; `RunSpec.plan` gives the executor's plan (`lawbench.runner.run`).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lawbench.case import CASES
from lawbench.checks import CHECKS, SINGLE_SOLVE
from lawbench.errors import InvalidProblem
from lawbench.law import LAWS
from lawbench.study import Job, Plan
from lawbench.transforms import parse


@dataclass(frozen=True)
class RunSpec:
    """A parsed specification: grids, the seed, the checks to run and their settings."""

    grids: Sequence[Mapping[str, Any]]
    seed: int = 0
    checks: Sequence[str] = field(default_factory=lambda: list(SINGLE_SOLVE))
    continuity_sizes: Sequence[float] = (1e-2, 1e-4, 1e-6)

    @classmethod
    def from_toml(cls, path: Path) -> RunSpec:
        """Read a specification file; a malformed one raises `InvalidProblem`."""
        try:
            data = tomllib.loads(Path(path).read_text())
        except OSError as exc:
            raise InvalidProblem(f"spec {path}: cannot be read ({exc.strerror})") from None
        except tomllib.TOMLDecodeError as exc:
            raise InvalidProblem(f"spec {path}: malformed TOML ({exc})") from None
        return cls.from_dict(data)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunSpec:
        """Build a specification from parsed TOML; a bad key or value raises `InvalidProblem`.

        The message names the key (``grid[1].params.e``) and what it should be.
        """
        unknown = set(data) - {"grid", "seed", "checks", "continuity_sizes"}
        if unknown:
            raise InvalidProblem(f"spec: unknown key {sorted(unknown)[0]!r}")
        grids = _typed(data.get("grid", []), list, "grid", "an array of [[grid]] tables")
        if not grids:
            raise InvalidProblem("spec: no [[grid]] table")
        for number, grid in enumerate(grids):
            _check_grid(grid, number)
        checks = _strings(data.get("checks", list(SINGLE_SOLVE)), "checks")
        for name in checks:
            if name not in CHECKS:
                raise InvalidProblem(f"spec: unknown check {name!r}; known: {', '.join(CHECKS)}")
        sizes = _typed(data.get("continuity_sizes", [1e-2, 1e-4, 1e-6]), list, "continuity_sizes")
        if not all(isinstance(x, int | float) and not isinstance(x, bool) for x in sizes):
            raise InvalidProblem(f"spec: key 'continuity_sizes' holds numbers, got {sizes!r}")
        seed = data.get("seed", 0)
        if not isinstance(seed, int) or isinstance(seed, bool):
            raise InvalidProblem(f"spec: key 'seed' must be an integer, got {seed!r}")
        return cls(grids, seed, checks, tuple(float(x) for x in sizes))

    def rows(self) -> list[Job]:
        """Every row, in order, each checked against its law and case."""
        return [
            job
            for number, grid in enumerate(self.grids)
            for job in _expand(grid, self.seed, number)
        ]

    def describe(self) -> str:
        """The grid as it was read, in one line: names, and each parameter's grid points."""
        parts = []
        for number, grid in enumerate(self.grids):
            text = [f"laws {_listed(grid.get('laws', ['*']))}"]
            text.append(f"cases {_listed(grid.get('cases', ['*']))}")
            for kind in ("params", "options"):
                entries = dict(grid.get(kind, {}))
                if kind == "options":  # per law: {law: {option: values}}
                    entries = {f"{law}.{k}": v for law, o in entries.items() for k, v in o.items()}
                for name, spec in entries.items():
                    points = values(spec, self.seed, (number, kind, name))
                    few = (
                        points
                        if len(points) <= SHOWN
                        else [*points[: SHOWN - 1], "...", points[-1]]
                    )
                    shown = " | ".join(_shown(p) for p in few)
                    plural = "s" if len(points) != 1 else ""
                    text.append(f"{name} = {shown} ({len(points)} grid point{plural})")
            if grid.get("examples"):
                text.append("each case's examples")
            if grid.get("transforms"):
                text.append(f"transforms {_listed([t or 'none' for t in grid['transforms']])}")
            parts.append(f"grid {number}: " + "; ".join(text))
        return " / ".join(parts)

    def plan(self) -> Plan:
        """The executor's plan: every row, the checks, their settings; no measures."""
        settings = {"continuity_sizes": list(self.continuity_sizes)}
        return Plan("", self.rows(), tuple(self.checks), settings)


# Grid points of one parameter the echoed grid shows before it elides the middle ones.
SHOWN = 6
GRID_KEYS = {"laws", "cases", "params", "options", "examples", "transforms"}
_KINDS = {list: "an array", dict: "a table", bool: "true or false", str: "a string"}


def _typed(value: Any, kind: type, key: str, what: str | None = None) -> Any:
    if not isinstance(value, kind):
        wanted = what or _KINDS.get(kind, kind.__name__)
        raise InvalidProblem(f"spec: key {key!r} must be {wanted}, got {value!r}")
    return value


def _strings(value: Any, key: str) -> list[str]:
    """A list of names (one name alone stands for a list of one)."""
    names = [value] if isinstance(value, str) else _typed(value, list, key)
    for name in names:
        _typed(name, str, key, "a string or an array of strings")
    return names


def _check_grid(grid: Any, number: int) -> None:
    """The keys and value kinds of ``[[grid]]`` table ``number``."""
    where = f"grid[{number}]"
    _typed(grid, dict, where, "a table")
    unknown = set(grid) - GRID_KEYS
    if unknown:
        raise InvalidProblem(f"spec {where}: unknown key {sorted(unknown)[0]!r}")
    for key in ("laws", "cases", "transforms"):
        if key in grid:
            _strings(grid[key], f"{where}.{key}")
    _typed(grid.get("params", {}), dict, f"{where}.params")
    _typed(grid.get("examples", False), bool, f"{where}.examples")
    for law, options in _typed(grid.get("options", {}), dict, f"{where}.options").items():
        _typed(options, dict, f"{where}.options.{law}", "a table of option = values")


def _names(grid: Mapping[str, Any], key: str, registry: Any) -> list[str]:
    names = grid.get(key, ["*"])
    if isinstance(names, str):
        names = [names]
    if names == ["*"]:
        return registry.names()
    for name in names:
        registry.get(name)
    return list(names)


def _expand(grid: Mapping[str, Any], seed: int, number: int) -> Iterator[Job]:
    every_law = grid.get("laws", ["*"]) in (["*"], "*")
    laws, cases = _names(grid, "laws", LAWS), _names(grid, "cases", CASES)
    param_values = {
        name: values(spec, seed, (number, "param", name))
        for name, spec in dict(grid.get("params", {})).items()
    }
    option_grids = dict(grid.get("options", {}))
    for law in option_grids:
        LAWS.get(law)
    transforms = _strings(grid.get("transforms", [""]), f"grid[{number}].transforms")
    for spelling in filter(None, transforms):
        parse(spelling)
    for case_name in cases:
        case = CASES.get(case_name)
        for law_name in laws:
            law = LAWS.get(law_name)
            if every_law and not law.tags.covers(case.requires):
                continue
            option_values = {
                name: values(spec, seed, (number, "option", law_name, name))
                for name, spec in dict(option_grids.get(law_name, {})).items()
            }
            parameter_sets = (
                [dict(p) for p in case.examples.values()]
                if grid.get("examples", False)
                else list(_product(param_values))
            )
            for params in parameter_sets:
                for options in _product(option_values):
                    try:
                        case.parameters(**params)
                        law.option_values(options)
                    except InvalidProblem as exc:
                        raise InvalidProblem(
                            f"spec grid {number}, {law_name} on {case_name}: {exc}"
                        ) from None
                    for transform in transforms:
                        yield Job(law_name, case_name, params, options, transform)


def _listed(names: Any) -> str:
    return ",".join(names) if isinstance(names, list) else str(names)


def _shown(value: Any) -> str:
    if isinstance(value, list):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return f"{value:g}" if isinstance(value, float) else str(value)


def parse_values(name: str, text: str) -> list[Any]:
    """The grid points of a command-line value: ``0,0.5,1`` is three, ``[0.9,0.8]`` one vector.

    Commas outside brackets separate grid points; a bracketed list is one per-contact vector
    (``[0.9,0.8],[1,1]`` is two). A point is a number where it reads as one, else a word.

    Raises
    ------
    InvalidProblem
        For an empty value, unbalanced brackets or a malformed vector, naming ``name``.
    """
    items, depth, current = [], 0, ""
    for char in text:
        depth += (char == "[") - (char == "]")
        if depth < 0:
            break
        if char == "," and depth == 0:
            items.append(current.strip())
            current = ""
        else:
            current += char
    items.append(current.strip())
    if depth != 0:
        raise InvalidProblem(f"--param {name}={text}: unbalanced brackets")
    if not all(items):
        raise InvalidProblem(f"--param {name}={text}: an empty value")
    return [_point(name, item) for item in items]


def _point(name: str, item: str) -> Any:
    try:
        value = json.loads(item)
    except json.JSONDecodeError:
        if item.startswith("["):
            raise InvalidProblem(f"--param {name}: malformed vector {item}") from None
        return item
    if isinstance(value, list) and not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in value
    ):
        raise InvalidProblem(f"--param {name}: a vector holds numbers, got {item}")
    return value if isinstance(value, int | float | list) else item


def _product(choices: Mapping[str, list[Any]]) -> Iterator[dict[str, Any]]:
    names = list(choices)
    for combination in itertools.product(*(choices[name] for name in names)):
        yield dict(zip(names, combination, strict=True))


def values(spec: Any, seed: int, where: tuple) -> list[Any]:
    """The values a grid entry stands for (see the module docstring)."""
    if isinstance(spec, list):
        return spec
    if not isinstance(spec, Mapping):
        return [spec]
    label = "/".join(str(part) for part in where)
    try:
        if "range" in spec:
            start, stop, count = spec["range"]
            return np.linspace(start, stop, int(count)).tolist()
        if "logrange" in spec:
            start, stop, count = spec["logrange"]
            return np.logspace(start, stop, int(count)).tolist()
        if "random" in spec:
            low, high, count = spec["random"]
            size = int(spec.get("size", 1))
            digest = hashlib.sha1(label.encode()).digest()
            rng = np.random.default_rng([seed, int.from_bytes(digest[:8], "little")])
            if spec.get("log", False):
                draws = 10 ** rng.uniform(np.log10(low), np.log10(high), (int(count), size))
            else:
                draws = rng.uniform(low, high, (int(count), size))
            return [row[0] if size == 1 else row for row in draws.tolist()]
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(
            f"spec {_key(where)}: bad value generator {dict(spec)} ({exc})"
        ) from None
    raise InvalidProblem(f"spec {_key(where)}: unknown value generator {dict(spec)}")


def _key(where: tuple) -> str:
    """The TOML key of a grid entry: ``(0, 'param', 'e')`` is ``grid[0].params.e``."""
    number, kind, *names = where
    return f"grid[{number}].{kind}s." + ".".join(str(n) for n in names)
