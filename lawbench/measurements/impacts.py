"""Measured impacts and the sets that hold them, with their sources and a fixed split.

A `MeasuredImpact` is the `ImpactProblem` at the configuration where an impact was observed
(mass matrix, contact Jacobians, generalized velocity before), with the generalized velocity
measured after it. Its contacts carry the placeholders ``e = 0`` and ``mu = 0``: a law's fit
sets the coefficients it has. It carries ``problem`` and ``facts``, so the one way into a
solve (`lawbench.core.trial.make_trial`) takes it as it is.

A `MeasurementSet` is loaded on first use: importing a set's module registers it without
reading its data file.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.problem import ImpactProblem
from lawbench.core.registry import Registry

# Where the built-in sets keep their converted files, one folder per set.
DATA = Path(__file__).resolve().parent / "data"
# The seed of every shipped train/test split: drawn once by the conversion, stored with the data.
SPLIT_SEED = 20260101


@dataclass(frozen=True, eq=False)
class MeasuredImpact:
    """One observed impact: the problem before it and the velocity measured after it.

    Parameters
    ----------
    problem : ImpactProblem
        The impact at the measured configuration: M, Wn, Wt and the velocity before.
    v_after : array (n,)
        The generalized velocity measured after the impact, in the coordinates of ``problem``.
    sigma : array (n,) or None
        Standard uncertainty of ``v_after`` where the source gives one, else None.
    set_name : str
        The set the impact belongs to.
    index : int
        Its index in the source (a bounce's or a toss's number, a digitized point's rank).
    facts : mapping
        What was learned while making the impact (fit residuals, flags, the incidence angle).
    """

    problem: ImpactProblem
    v_after: np.ndarray
    sigma: np.ndarray | None = None
    set_name: str = ""
    index: int = 0
    facts: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        v_after = np.array(self.v_after, dtype=float, ndmin=1)
        if v_after.shape != (self.problem.n,) or not np.isfinite(v_after).all():
            raise InvalidProblem(
                f"v_after has shape {v_after.shape} or a non-finite entry: expected "
                f"{self.problem.n} finite numbers"
            )
        v_after.setflags(write=False)
        object.__setattr__(self, "v_after", v_after)
        if self.sigma is not None:
            sigma = np.array(self.sigma, dtype=float, ndmin=1)
            if sigma.shape != (self.problem.n,) or not (sigma >= 0).all():
                raise InvalidProblem(f"sigma has shape {sigma.shape} or a negative entry")
            object.__setattr__(self, "sigma", sigma)

    @property
    def dv(self) -> np.ndarray:
        """The measured change of generalized velocity, ``v_after - v``."""
        return self.v_after - self.problem.v


@dataclass(frozen=True)
class Source:
    """Where a set's numbers come from.

    Parameters
    ----------
    paper : str
        The publication(s) that report the measurements.
    repository : str
        The public repository the raw file was read from.
    commit : str
        The commit of that repository.
    path : str
        The raw file's path (or paths) in the repository.
    licence : str
        The repository's licence, as it states it.
    """

    paper: str
    repository: str
    commit: str
    path: str
    licence: str


@dataclass(frozen=True)
class Processing:
    """How the shipped impacts were made from the raw file.

    Parameters
    ----------
    method : str
        What made the impacts (the conversion and its rules).
    kept : int
        Impacts kept.
    dropped : mapping of str to int
        Each reason for dropping a candidate, with its count.
    corrected : str
        What was corrected in the raw numbers and why; empty when nothing was.
    """

    method: str
    kept: int
    dropped: Mapping[str, int]
    corrected: str = ""


class MeasurementSet:
    """A named set of measured impacts: source, processing, impacts and a fixed split.

    Parameters
    ----------
    name : str
        The set's registered name.
    summary : str
        One line: what was measured.
    source : Source
        Paper, repository, commit, path and licence of the raw numbers.
    load : callable
        Returns ``(impacts, train, processing)`` on first use: the impacts in source order,
        the boolean training mask stored with the data, and the processing record.
    facts : mapping
        Constants of the experiment (mass, sizes, sampling rate, published fits).
    """

    def __init__(
        self,
        name: str,
        summary: str,
        source: Source,
        load: Callable[[], tuple[Sequence[MeasuredImpact], np.ndarray, Processing]],
        facts: Mapping[str, Any] | None = None,
    ) -> None:
        self.name = name
        self.summary = summary
        self.source = source
        self.facts = dict(facts or {})
        self._load = load

    @functools.cached_property
    def _loaded(self) -> tuple[tuple[MeasuredImpact, ...], np.ndarray, Processing]:
        impacts, train, processing = self._load()
        train = np.asarray(train, dtype=bool)
        if train.shape != (len(impacts),):
            raise InvalidProblem(f"{self.name}: the split has {train.shape}, not one per impact")
        train.setflags(write=False)
        return tuple(impacts), train, processing

    @property
    def impacts(self) -> tuple[MeasuredImpact, ...]:
        """The set's impacts, in source order."""
        return self._loaded[0]

    @property
    def processing(self) -> Processing:
        """What made the impacts, what was kept and dropped, and why."""
        return self._loaded[2]

    @property
    def train(self) -> tuple[MeasuredImpact, ...]:
        """The impacts a law's free coefficients are fitted on."""
        return tuple(i for i, t in zip(self.impacts, self._loaded[1], strict=True) if t)

    @property
    def test(self) -> tuple[MeasuredImpact, ...]:
        """The impacts a fitted law is measured on."""
        return tuple(i for i, t in zip(self.impacts, self._loaded[1], strict=True) if not t)

    def __len__(self) -> int:
        return len(self.impacts)

    def __repr__(self) -> str:
        return f"<measurement set {self.name}: {self.summary}>"


# The registry scans this package, whose `sets` module imports the built-in sets, and the
# entry-point group of the same name, ``lawbench.measurements``, for plugins.
MEASUREMENTS: Registry[MeasurementSet] = Registry(
    "measurement set", "lawbench.measurements", MeasurementSet
)


def training_mask(count: int, seed: int = SPLIT_SEED) -> np.ndarray:
    """A boolean mask choosing ``count // 2`` of ``count`` impacts for training.

    Drawn once by a conversion and stored with the data, so the split never depends on the
    random generator of the machine that reads it.
    """
    chosen = np.random.default_rng(seed).permutation(count)[: count // 2]
    mask = np.zeros(count, dtype=bool)
    mask[chosen] = True
    return mask


def read_data(name: str) -> dict[str, np.ndarray]:
    """The arrays of the built-in set ``name`` (its ``data/<name>/<name>.npz``)."""
    with np.load(DATA / name / f"{name}.npz", allow_pickle=False) as data:
        return {key: data[key] for key in data.files}


def processing_from(data: Mapping[str, np.ndarray]) -> Processing:
    """The processing record a conversion stored as JSON in a data file's ``processing``."""
    record = json.loads(str(data["processing"]))
    return Processing(record["method"], record["kept"], record["dropped"], record["corrected"])


def processing_array(processing: Processing) -> np.ndarray:
    """A processing record as the JSON string array a data file stores."""
    record = {
        "method": processing.method,
        "kept": processing.kept,
        "dropped": dict(processing.dropped),
        "corrected": processing.corrected,
    }
    return np.array(json.dumps(record, sort_keys=True))


def planar_problem(
    M: np.ndarray, normal: np.ndarray, tangent: np.ndarray, v: np.ndarray
) -> ImpactProblem:
    """The one-contact planar problem with rows ``normal`` and ``tangent`` of the contact.

    The contact's coefficients are the placeholders ``e = 0``, ``mu = 0`` a fit replaces.
    """
    return ImpactProblem.from_arrays(M, normal[:, None], v, tangent[:, None], e=0.0, mu=0.0)
