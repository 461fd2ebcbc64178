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
    transforms = ["grazing=1e-08", "duplicated"]   # lawbench.core.transforms, one per row

A parameter or option takes a list of values, one value, ``{range = [start, stop, count]}`` (evenly
spaced), ``{logrange = [start_exponent, stop_exponent, count]}`` (powers of ten), or ``{random =
[low, high, count], log = false, size = 1}`` (uniform samples, drawn from the spec's seed and the
grid, parameter and draw position, so the same spec always gives the same values; ``size`` > 1 draws
vectors). A generator's bounds are finite, a ``random`` one's ``low <= high`` (both positive with
``log = true``), its count at most `MAX_CELLS` and its ``size`` at most `MAX_SIZE`; a grid holds
at most `MAX_CELLS` rows. Rows are the Cartesian product in the order written: cases, then laws,
then parameters, then options, then transforms. A malformed generator raises `InvalidProblem` as
the grid is read; every row is checked before any work: an unknown name, a value out of range,
options of a law that has no cell in their grid or a check named twice raise `InvalidProblem`.
A row is a `lawbench.studies.study.Job`; `RunSpec.plan` gives the executor's plan
(`lawbench.studies.runner.run`). `RunSpec.count` counts the rows from the grid's sizes and
`RunSpec.sample` builds a few of them alone, so a grid of millions of rows is sized and timed before
it is built.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from lawbench.checks import CHECKS, SINGLE_SOLVE
from lawbench.core.case import CASES
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS
from lawbench.core.transforms import parse
from lawbench.files.paths import input_file
from lawbench.studies.study import Job, Plan

if TYPE_CHECKING:
    from lawbench.core.case import Case
    from lawbench.core.law import Law


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
            data = tomllib.loads(input_file(path, "spec").read_bytes().decode("utf-8"))
        except OSError as exc:
            raise InvalidProblem(f"spec {path}: cannot be read ({exc.strerror})") from None
        except UnicodeDecodeError as exc:
            raise InvalidProblem(
                f"spec {path}: TOML is UTF-8 text ({exc.reason} at byte {exc.start})"
            ) from None
        except tomllib.TOMLDecodeError as exc:
            raise InvalidProblem(f"spec {path}: malformed TOML ({exc})") from None
        except RecursionError:
            raise InvalidProblem(f"spec {path}: nested deeper than a run file ever is") from None
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
        for number, name in enumerate(checks):
            if name not in CHECKS:
                raise InvalidProblem(f"spec: unknown check {name!r}; known: {', '.join(CHECKS)}")
            if name in checks[:number]:
                raise InvalidProblem(f"spec: key 'checks' names the check {name!r} twice")
        sizes = _typed(data.get("continuity_sizes", [1e-2, 1e-4, 1e-6]), list, "continuity_sizes")
        # Relative perturbations of the gaps and velocities: positive and finite, or no probe.
        if not all(
            isinstance(x, int | float) and not isinstance(x, bool) and 0 < x < math.inf
            for x in sizes
        ):
            raise InvalidProblem(
                f"spec: key 'continuity_sizes' holds positive finite numbers, got {sizes!r}"
            )
        seed = data.get("seed", 0)
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            raise InvalidProblem(f"spec: key 'seed' must be an integer >= 0, got {seed!r}")
        return cls(grids, seed, checks, tuple(float(x) for x in sizes))

    def rows(self) -> list[Job]:
        """Every row, in order, each checked against its law and case (`count` first)."""
        self.count()
        return [job for block in self._blocks() for job in block.rows()]

    def count(self) -> int:
        """The number of rows, from each grid's sizes, without building a row.

        Per grid, the sum over its cases and laws of parameter sets x option sets x transforms,
        where a generator's grid points are counted, not drawn: a grid of millions of rows is
        counted as fast as one of ten.

        Raises
        ------
        InvalidProblem
            For a grid of more than `MAX_CELLS` rows, with its count.
        """
        total = sum(block.size for block in self._blocks())
        if total > MAX_CELLS:
            raise InvalidProblem(
                f"spec: a grid of {total} cells, more than the {MAX_CELLS} a run holds"
            )
        return total

    def sample(self, count: int) -> list[Job]:
        """``count`` rows spread evenly over the grid (all of them when there are fewer).

        Each row is built alone, from its position: the rows around it are not built.
        """
        total, blocks = self.count(), list(self._blocks())
        wanted = sorted({k * total // count for k in range(count)}) if total else []
        jobs, start = [], 0
        for block in blocks:
            jobs += [block.row(k - start) for k in wanted if start <= k < start + block.size]
            start += block.size
        return jobs

    def _blocks(self) -> Iterator[_Block]:
        for number, grid in enumerate(self.grids):
            yield from _blocks(grid, self.seed, number)

    def describe(self) -> str:
        """The grid as it was read, in one line: names, and each parameter's grid points.

        A generator's grid points are shown as the rows draw them; only those shown are
        computed.
        """
        parts = []
        for number, grid in enumerate(self.grids):
            text = [f"laws {_listed(grid.get('laws', ['*']))}"]
            text.append(f"cases {_listed(grid.get('cases', ['*']))}")
            entries = [
                (name, ("param", name), spec) for name, spec in grid.get("params", {}).items()
            ]
            entries += [
                (f"{law}.{name}", ("option", law, name), spec)
                for law, options in grid.get("options", {}).items()
                for name, spec in options.items()
            ]
            for name, where, spec in entries:
                points = grid_points(spec, self.seed, (number, *where))
                few = points if len(points) <= SHOWN else [*points[: SHOWN - 1], "...", points[-1]]
                shown = " | ".join(_shown(p) for p in few)
                plural = "s" if len(points) != 1 else ""
                text.append(f"{name} = {shown} ({len(points)} grid point{plural})")
            if grid.get("examples"):
                text.append("each case's examples")
            if grid.get("transforms"):
                text.append(f"transforms {_listed([t or 'none' for t in grid['transforms']])}")
            parts.append(f"grid {number}: " + "; ".join(text))
        return " / ".join(parts)

    def plan(self, sample: int | None = None) -> Plan:
        """The executor's plan: every row (or a `sample` of them), the checks, their settings.

        A plan has no measures.
        """
        settings = {"continuity_sizes": list(self.continuity_sizes)}
        jobs = self.rows() if sample is None else self.sample(sample)
        return Plan("", jobs, tuple(self.checks), settings)


# Grid points of one parameter the echoed grid shows before it elides the middle ones.
SHOWN = 6
# Rows of a grid at most (a count above it is a typo: a billion cells take days on a cluster);
# the grid points of one generator are bounded by it too.
MAX_CELLS = 10**9
# Entries of a random vector at most: the longest per-contact vector, a chain of 100000 balls.
MAX_SIZE = 100_000
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
    params = _typed(grid.get("params", {}), dict, f"{where}.params")
    _typed(grid.get("examples", False), bool, f"{where}.examples")
    entries = [((number, "param", name), spec) for name, spec in params.items()]
    for law, options in _typed(grid.get("options", {}), dict, f"{where}.options").items():
        _typed(options, dict, f"{where}.options.{law}", "a table of option = values")
        entries += [((number, "option", law, name), spec) for name, spec in options.items()]
    for key, spec in entries:
        grid_points(spec, 0, key)  # a generator checks its bounds, count and size


def _names(grid: Mapping[str, Any], key: str, registry: Any) -> list[str]:
    names = _strings(grid.get(key, ["*"]), key)
    if names == ["*"]:
        return registry.names()
    for name in names:
        registry.get(name)
    return list(names)


@dataclass(frozen=True)
class _Block:
    """The rows of one law on one case of a grid: parameter sets x option sets x transforms."""

    number: int
    law: Law
    case: Case
    law_name: str
    case_name: str
    parameter_sets: Sequence[Mapping[str, Any]]
    option_sets: Sequence[Mapping[str, Any]]
    transforms: Sequence[str]

    @property
    def size(self) -> int:
        """The number of rows, counted without building them."""
        return _size(self.parameter_sets) * _size(self.option_sets) * len(self.transforms)

    def rows(self) -> Iterator[Job]:
        """Every row, in order, each checked against its law and case."""
        for params in self.parameter_sets:
            for options in self.option_sets:
                self._check(params, options)
                for transform in self.transforms:
                    yield self._job(params, options, transform)

    def row(self, index: int) -> Job:
        """Row ``index`` (in the order of `rows`), built alone and checked."""
        rest, transform = divmod(index, len(self.transforms))
        params, options = divmod(rest, len(self.option_sets))
        chosen = self.parameter_sets[params], self.option_sets[options]
        self._check(*chosen)
        return self._job(*chosen, self.transforms[transform])

    def _job(self, params: Mapping[str, Any], options: Mapping[str, Any], transform: str) -> Job:
        return Job(self.law_name, self.case_name, dict(params), dict(options), transform)

    def _check(self, params: Mapping[str, Any], options: Mapping[str, Any]) -> None:
        try:
            self.case.parameters(**params)
            self.law.option_values(dict(options))
        except InvalidProblem as exc:
            raise InvalidProblem(
                f"spec grid {self.number}, {self.law_name} on {self.case_name}: {exc}"
            ) from None


def _blocks(grid: Mapping[str, Any], seed: int, number: int) -> Iterator[_Block]:
    """The blocks of a grid, one per case and law in row order; no row is built."""
    every_law = grid.get("laws", ["*"]) in (["*"], "*")
    laws, cases = _names(grid, "laws", LAWS), _names(grid, "cases", CASES)
    param_points = Product(
        {
            name: grid_points(spec, seed, (number, "param", name))
            for name, spec in dict(grid.get("params", {})).items()
        }
    )
    option_grids = dict(grid.get("options", {}))
    pairs = [
        (case_name, law_name)
        for case_name in cases
        for law_name in laws
        if not every_law or LAWS.get(law_name).tags.covers(CASES.get(case_name).requires)
    ]
    for law in option_grids:
        if LAWS.get(law) and law not in {law_name for _, law_name in pairs}:
            raise InvalidProblem(f"spec grid[{number}].options.{law}: {law!r} has no cell here")
    transforms = _strings(grid.get("transforms", [""]), f"grid[{number}].transforms")
    for spelling in filter(None, transforms):
        parse(spelling)
    for case_name, law_name in pairs:
        case, law = CASES.get(case_name), LAWS.get(law_name)
        option_points = Product(
            {
                name: grid_points(spec, seed, (number, "option", law_name, name))
                for name, spec in dict(option_grids.get(law_name, {})).items()
            }
        )
        examples = [dict(p) for p in case.examples.values()]
        parameter_sets = examples if grid.get("examples", False) else param_points
        yield _Block(
            number, law, case, law_name, case_name, parameter_sets, option_points, transforms
        )


def _size(points: Sequence[Any]) -> int:
    """The length of ``points``, a `Product` of any size counted without `len`'s limit."""
    return points.size if isinstance(points, Product) else len(points)


def _listed(names: Any) -> str:
    return ",".join(names) if isinstance(names, list) else str(names)


def _shown(value: Any) -> str:
    if isinstance(value, list):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return f"{value:g}" if isinstance(value, float) else str(value)


def parse_values(name: str, text: str, flag: str = "--param") -> list[Any]:
    """The grid points of a command-line value: ``0,0.5,1`` is three, ``[0.9,0.8]`` one vector.

    Commas outside brackets separate grid points; a bracketed list is one per-contact vector
    (``[0.9,0.8],[1,1]`` is two), never nested. A point is a number where it reads as one, else
    a word.

    Raises
    ------
    InvalidProblem
        For an empty value, unbalanced or nested brackets or a malformed vector, naming
        ``flag`` and ``name``.
    """
    items, depth, current = [], 0, ""
    for char in text:
        depth += (char == "[") - (char == "]")
        if depth > 1:
            raise InvalidProblem(
                f"{flag} {name}={_quoted(text)}: nested brackets; a grid point is a number, a "
                "word or one [vector] of numbers"
            )
        if depth < 0:
            break
        if char == "," and depth == 0:
            items.append(current.strip())
            current = ""
        else:
            current += char
    items.append(current.strip())
    if depth != 0:
        raise InvalidProblem(f"{flag} {name}={_quoted(text)}: unbalanced brackets")
    if not all(items):
        raise InvalidProblem(f"{flag} {name}={_quoted(text)}: an empty value")
    return [_point(name, item, flag) for item in items]


# Characters of a typed value quoted in a message; a longer one is cut in the middle.
QUOTED = 60


def _quoted(text: str) -> str:
    """``text`` as a message quotes it: at most `QUOTED` characters, the middle elided."""
    if len(text) <= QUOTED:
        return text
    half = QUOTED // 2
    return f"{text[:half]}...{text[-half:]} ({len(text)} characters)"


def _point(name: str, item: str, flag: str) -> Any:
    try:
        value = json.loads(item)
    except (json.JSONDecodeError, RecursionError):  # braces nest: a word, or a bad vector
        if item.startswith("["):
            raise InvalidProblem(f"{flag} {name}: malformed vector {_quoted(item)}") from None
        return item
    if isinstance(value, list) and not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in value
    ):
        raise InvalidProblem(f"{flag} {name}: a vector holds numbers, got {_quoted(item)}")
    return value if isinstance(value, int | float | list) else item


class Product(Sequence[dict[str, Any]]):
    """The Cartesian product of named grid points, in ``itertools.product`` order.

    The last name varies fastest. Its length and any one entry come without the others.
    """

    def __init__(self, axes: Mapping[str, Sequence[Any]]) -> None:
        self.axes = dict(axes)

    @property
    def size(self) -> int:
        """The number of entries, however many (`len` refuses more than ``sys.maxsize``)."""
        return math.prod(len(points) for points in self.axes.values())

    def __len__(self) -> int:
        return self.size

    @overload
    def __getitem__(self, index: int) -> dict[str, Any]: ...
    @overload
    def __getitem__(self, index: slice) -> list[dict[str, Any]]: ...
    def __getitem__(self, index: int | slice) -> dict[str, Any] | list[dict[str, Any]]:
        if isinstance(index, slice):
            return [self[k] for k in range(*index.indices(len(self)))]
        index = _position(index, len(self))
        chosen = {}
        for name, points in reversed(self.axes.items()):
            index, k = divmod(index, len(points))
            chosen[name] = points[k]
        return {name: chosen[name] for name in self.axes}

    def __iter__(self) -> Iterator[dict[str, Any]]:
        names = list(self.axes)
        for combination in itertools.product(*self.axes.values()):
            yield dict(zip(names, combination, strict=True))


class Generated(Sequence[Any]):
    """The grid points of a generator (``range``, ``logrange``, ``random``), drawn on demand.

    Its length is the generator's count; an entry is computed alone (a random draw from the
    generator's stream advanced to it), equal to the same entry of the whole list.

    Raises
    ------
    InvalidProblem
        For an unknown generator or a malformed one, naming its key and what is wrong: bounds
        that are not finite, a count outside [0, `MAX_CELLS`], a size outside [1, `MAX_SIZE`],
        a random draw with ``low > high``, or with ``log = true`` and ``low <= 0``.
    """

    KINDS = ("range", "logrange", "random")

    def __init__(self, spec: Mapping[str, Any], seed: int, where: tuple) -> None:
        self.kind = next((kind for kind in self.KINDS if kind in spec), None)
        if self.kind is None:
            raise InvalidProblem(f"spec {_key(where)}: unknown value generator {dict(spec)}")
        known = (self.kind, "log", "size") if self.kind == "random" else (self.kind,)
        unknown = sorted(set(spec) - set(known))
        if unknown:
            raise InvalidProblem(
                f"spec {_key(where)}: unknown key {unknown[0]!r} in value generator "
                f"{dict(spec)}; known: {', '.join(known)}"
            )
        if not isinstance(spec.get("log", False), bool):
            raise InvalidProblem(
                f"spec {_key(where)}.log: must be true or false, got {spec['log']!r}"
            )
        try:
            start, stop, count = spec[self.kind]
            self.start, self.stop = float(start), float(stop)
            self.count, self.width = _whole(count, "count"), _whole(spec.get("size", 1), "size")
        except (TypeError, ValueError, OverflowError) as exc:
            raise InvalidProblem(
                f"spec {_key(where)}: bad value generator {dict(spec)} ({exc})"
            ) from None
        self.log = spec.get("log", False)
        problem = self._problem()
        if problem:
            raise InvalidProblem(
                f"spec {_key(where)}: bad value generator {dict(spec)} ({problem})"
            )
        digest = hashlib.sha1("/".join(str(part) for part in where).encode()).digest()
        self.seed = [seed, int.from_bytes(digest[:8], "little")]

    def _problem(self) -> str:
        """What is wrong with this generator's bounds, count or size ('' when nothing is)."""
        low, high = self.start, self.stop
        if not (math.isfinite(low) and math.isfinite(high)):
            return f"its bounds {low:g} and {high:g} must be finite"
        if not 0 <= self.count <= MAX_CELLS:
            return f"a count of {self.count}, outside 0..{MAX_CELLS}"
        if not 1 <= self.width <= MAX_SIZE:
            return f"a size of {self.width}, outside 1..{MAX_SIZE}"
        if self.kind != "random":
            return ""
        if low > high:
            return f"low {low:g} is above high {high:g}"
        if self.log and low <= 0:
            return f"log = true draws between positive bounds, not from {low:g}"
        if not math.isfinite(high - low):
            return f"the span {low:g} to {high:g} exceeds floating point"
        return ""

    def __len__(self) -> int:
        return self.count

    @overload
    def __getitem__(self, index: int) -> Any: ...
    @overload
    def __getitem__(self, index: slice) -> list[Any]: ...
    def __getitem__(self, index: int | slice) -> Any:
        if isinstance(index, slice):
            return [self[k] for k in range(*index.indices(len(self)))]
        index = _position(index, self.count)
        if self.kind == "random":
            return self._draws(index, 1)[0]
        # np.linspace's entry index: start + index * step, the last one exactly stop.
        if index == self.count - 1 and index > 0:
            point = self.stop
        else:
            point = index * ((self.stop - self.start) / max(1, self.count - 1)) + self.start
        return float(np.power(10.0, point)) if self.kind == "logrange" else point

    def __iter__(self) -> Iterator[Any]:
        if self.kind == "range":
            return iter(np.linspace(self.start, self.stop, self.count).tolist())
        if self.kind == "logrange":
            return iter(np.logspace(self.start, self.stop, self.count).tolist())
        return iter(self._draws(0, self.count))

    def _draws(self, first: int, count: int) -> list[Any]:
        """Draws ``first`` to ``first + count - 1`` of the generator's seeded stream."""
        rng = np.random.default_rng(self.seed)
        # A uniform draw takes one 64-bit output of PCG64: skip those of the draws before.
        rng.bit_generator.advance(first * self.width)
        if self.log:
            low, high = np.log10(self.start), np.log10(self.stop)
            draws = 10 ** rng.uniform(low, high, (count, self.width))
        else:
            draws = rng.uniform(self.start, self.stop, (count, self.width))
        return [row[0] if self.width == 1 else row for row in draws.tolist()]


def _whole(value: Any, what: str) -> int:
    """``value`` as an int, or a ValueError for a number with a fraction (a count of 2.5)."""
    if isinstance(value, bool) or int(value) != value:
        raise ValueError(f"the {what} {value!r} is not a whole number")
    return int(value)


def _position(index: int, length: int) -> int:
    """``index`` as a position in a sequence of ``length`` (negative from the end)."""
    position = index + length if index < 0 else index
    if not 0 <= position < length:
        raise IndexError(f"grid point {index} of {length}")
    return position


def grid_points(spec: Any, seed: int, where: tuple) -> Sequence[Any]:
    """The grid points a grid entry stands for (see the module docstring), not yet drawn."""
    if isinstance(spec, list):
        return spec
    if not isinstance(spec, Mapping):
        return [spec]
    return Generated(spec, seed, where)


def values(spec: Any, seed: int, where: tuple) -> list[Any]:
    """The values a grid entry stands for (see the module docstring)."""
    return list(grid_points(spec, seed, where))


def _key(where: tuple) -> str:
    """The TOML key of a grid entry: ``(0, 'param', 'e')`` is ``grid[0].params.e``."""
    number, kind, *names = where
    return f"grid[{number}].{kind}s." + ".".join(str(n) for n in names)
