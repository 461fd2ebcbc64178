"""Many impact problems of one shape, stacked, and their outcomes.

A `ProblemBatch` holds B problems with the same numbers of coordinates and contacts as stacked
arrays, validated once for the whole batch with the same rules as `ImpactProblem`. A law solves it
with `Law.resolve_batch`: a law with a vectorized path (closed forms and active-set enumeration on
the Delassus matrices, `lawbench.numerics.solvers.enumerate_lcp`) solves every problem in a few
numpy calls; the others are solved one by one. Either way the answer equals the one-by-one path to
rounding.

Sign conventions as everywhere: ``un = Wn.T @ v``, ``ut = Wt.T @ v``, ``Pn >= 0`` pushes apart,
``v_plus = v + M^-1 (Wn Pn + Wt Pt)``. Batches are simultaneous (zero gaps), frictionless or
with a tangential Jacobian of d = 1 (planar) or 2 (spatial) directions per contact and a
Coulomb ``mu`` per problem and contact: the measured impacts a fitted law solves thousands of
times.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.metric import UNIT_BAND, all_finite
from lawbench.core.problem import CONTACT_RANGES, RESTITUTION_FIELDS, Contact, ImpactProblem

if TYPE_CHECKING:
    import pandas as pd

_OVERFLOW = "M is too close to singular (its inverse overflows)"
# Contact fields a batch carries per problem and contact, with their allowed ranges (those of
# `ImpactProblem`'s contacts).
COEFFICIENTS = {
    name: (low, np.inf if high is None else high)
    for name, low, high, _ in CONTACT_RANGES
    if name in ("e", *RESTITUTION_FIELDS.values(), "e_t", "mu")
}
# The coefficients only a batch with a tangential Jacobian carries.
FRICTION_COEFFICIENTS = ("e_t", "mu")


def _numbers(name: str, value: object) -> np.ndarray:
    """``value`` as a float array; `InvalidProblem` naming ``name`` when it holds no numbers."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{name}: not an array of numbers ({exc})") from None


def _stack(name: str, value: object, shape: tuple[int, ...], batch: int | None) -> np.ndarray:
    """``value`` as a float array (B, *shape); one array of ``shape`` serves every problem."""
    array = _numbers(name, value)
    # Before broadcasting: one array that serves every problem is checked once.
    finite = all_finite(array)
    if array.shape == shape and batch is not None:
        array = np.broadcast_to(array, (batch, *shape))
    if array.ndim != len(shape) + 1 or array.shape[1:] != shape:
        raise InvalidProblem(f"{name} has shape {array.shape}, expected (B, {shape}) or {shape}")
    if not finite:
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        raise InvalidProblem(f"{name}{list(index)} = {array[index]}: must be finite")
    return array


def _coefficients(given: object, batch: int, m: int) -> dict[str, np.ndarray]:
    """The batch's coefficients (B, m), checked in their ranges; ``e`` is 1 where not given."""
    if not isinstance(given, Mapping):
        raise TypeError(
            "coefficients must be a mapping of coefficient names to values, not "
            f"{type(given).__name__}"
        )
    coefficients = {}
    for name, value in given.items():
        if name not in COEFFICIENTS:
            raise InvalidProblem(
                f"unknown batch coefficient {name!r}; known: {', '.join(COEFFICIENTS)}"
            )
        array = np.broadcast_to(_numbers(f"coefficients[{name!r}]", value), (batch, m))
        low, high = COEFFICIENTS[name]
        # NaN fails every comparison; an unbounded range still refuses infinity.
        largest = array.max()
        if not (array.min() >= low and largest <= high and largest < np.inf):
            inside = (array >= low) & (array <= high) & (array < np.inf)
            k, j = (int(i) for i in np.argwhere(~inside)[0])
            value = array[k, j]
            bounds = f"in [{low:g}, {high:g}]" if high < np.inf else f">= {low:g}"
            must = f"must be {bounds}" if np.isfinite(value) else "must be a finite number"
            raise InvalidProblem(f"problem {k}: contacts[{j}].{name} = {value}: {must}")
        coefficients[name] = array
    coefficients.setdefault("e", np.ones((batch, m)))
    return coefficients


@dataclass(frozen=True, eq=False)
class ProblemBatch:
    """B simultaneous impact problems of one shape, validated once.

    Parameters
    ----------
    M : array (B, n, n) or (n, n)
        Mass matrices (one serves every problem).
    Wn : array (B, n, m) or (n, m)
        Normal Jacobians.
    v : array (B, n)
        Pre-impact velocities; B is the number of rows.
    coefficients : mapping of str to array (B, m)
        Contact coefficients per problem and contact, in the ranges of `Contact`: restitution
        (``e``, ``e_newton``, ``e_poisson``, ``e_energy``, in [0, 1]), and with a tangential
        Jacobian Brach's ``e_t`` (in [-1, 1]) and Coulomb's ``mu`` (>= 0); those not given are
        the defaults of `Contact`.
    Wt : array (B, n, m*d) or (n, m*d), optional
        Tangential Jacobians, d = 1 (planar) or 2 (spatial) directions per contact; None
        without friction.

    Raises
    ------
    InvalidProblem
        Naming the field, the problem and the value, like `ImpactProblem`.
    """

    M: np.ndarray
    Wn: np.ndarray
    v: np.ndarray
    coefficients: dict[str, np.ndarray] = field(default_factory=dict)
    Wt: np.ndarray | None = None

    def __post_init__(self) -> None:
        v = _numbers("v", self.v)
        if v.ndim != 2 or v.shape[0] < 1 or v.shape[1] < 1:
            raise InvalidProblem(f"v has shape {v.shape}, expected (B, n) with B, n >= 1")
        batch, n = v.shape
        m = np.shape(self.Wn)[-1] if np.ndim(self.Wn) >= 2 else 0
        if m < 1:
            raise InvalidProblem(f"Wn has shape {np.shape(self.Wn)}, expected (B, n, m)")
        set_ = object.__setattr__
        set_(self, "v", _stack("v", v, (n,), None))
        set_(self, "M", _stack("M", self.M, (n, n), batch))
        set_(self, "Wn", _stack("Wn", self.Wn, (n, m), batch))
        stacked = ("M", "Wn")
        if self.Wt is not None:
            columns = np.shape(self.Wt)[-1] if np.ndim(self.Wt) >= 2 else 0
            if columns not in (m, 2 * m):
                raise InvalidProblem(
                    f"Wt has shape {np.shape(self.Wt)}, expected (B, {n}, {m}*d) with d = 1 or 2"
                )
            set_(self, "Wt", _stack("Wt", self.Wt, (n, columns), batch))
            stacked += ("Wt",)
        for name in (f for f in stacked if getattr(self, f).shape[0] != batch):
            raise InvalidProblem(f"{name} holds {getattr(self, name).shape[0]} problems, v {batch}")
        coefficients = _coefficients(self.coefficients, batch, m)
        for name in FRICTION_COEFFICIENTS:
            if self.Wt is not None:
                coefficients.setdefault(name, np.zeros((batch, m)))
            elif name in coefficients:
                raise InvalidProblem(f"coefficient {name!r} without a tangential Jacobian Wt")
        set_(self, "coefficients", coefficients)
        self._check_normals(self._factor_mass())

    def _check_normals(self, smallest: np.ndarray) -> None:
        """Refuse a contact no motion moves along its normal, by `ImpactProblem`'s criterion.

        A normal Delassus entry at rounding level against the largest inverse mass (1 over
        ``smallest``, each M's smallest eigenvalue) times the largest squared column of the
        whole Jacobian ``[Wn, Wt]`` flags a problem; a flagged one is judged as an
        `ImpactProblem`, whose test reads entries and columns beyond double precision (a
        Delassus entry that overflows, squares of 1e160) by their scale.
        """
        with np.errstate(over="ignore", invalid="ignore"):
            diagonal = np.einsum("kjj->kj", self.delassus)
            columns = np.einsum("kij,kij->kj", self.Wn, self.Wn).max(axis=1)
            if self.Wt is not None:
                tangential = np.einsum("kij,kij->kj", self.Wt, self.Wt).max(axis=1)
                columns = np.maximum(columns, tangential)
            floor = 1e-12 * columns / smallest
            flagged = ~(diagonal > floor[:, None]).all(axis=1)
        for k in np.flatnonzero(flagged):
            try:
                self.problem(int(k))
            except InvalidProblem as exc:
                raise InvalidProblem(f"problem {k}: {exc}") from None

    def _factor_mass(self) -> np.ndarray:
        """Check every M and keep its inverse; return the smallest eigenvalue of each.

        Diagonal mass matrices (particles, chains) are inverted entry by entry, exactly.
        """
        masses = np.einsum("kii->ki", self.M)
        if np.count_nonzero(self.M) == np.count_nonzero(masses):
            smallest = masses.min(axis=1)
            self._refuse("M is not positive definite", ~(smallest > 0))
            with np.errstate(all="ignore"):
                reciprocal = 1.0 / masses
            object.__setattr__(self, "_inverse_diagonal", reciprocal)
            if not all_finite(reciprocal):
                self._refuse(_OVERFLOW, ~np.isfinite(reciprocal).all(axis=1))
            return smallest
        asymmetry = np.abs(self.M - np.swapaxes(self.M, 1, 2)).max(axis=(1, 2))
        asymmetric = asymmetry > 1e-12 * np.abs(self.M).max(axis=(1, 2))
        for k in np.flatnonzero(asymmetric)[:1]:
            raise InvalidProblem(f"problem {k}: M is not symmetric ({asymmetry[k]:.3g})")
        smallest = np.linalg.eigvalsh(self.M)[:, 0]
        self._refuse("M is not positive definite", ~(smallest > 0))
        with np.errstate(all="ignore"):
            inverse = np.linalg.inv(self.M)
        object.__setattr__(self, "_inverse", inverse)
        self._refuse(_OVERFLOW, ~np.isfinite(inverse).all(axis=(1, 2)))
        return smallest

    @staticmethod
    def _refuse(reason: str, bad: np.ndarray) -> None:
        """Raise `InvalidProblem` for the first problem where ``bad`` holds."""
        for k in np.flatnonzero(bad)[:1]:
            raise InvalidProblem(f"problem {k}: {reason}")

    @classmethod
    def from_problems(cls, problems: Sequence[ImpactProblem]) -> ProblemBatch:
        """Stack problems of one shape (n, m and d alike, zero gaps), checked as a batch.

        An override of ``e`` that some contacts give and others do not is carried as the
        coefficient of its kind at every contact (`Contact.restitution`).
        """
        if not problems:
            raise InvalidProblem("an empty batch: give at least one problem")
        for k, problem in enumerate(problems):
            if not isinstance(problem, ImpactProblem):
                raise TypeError(f"problems[{k}] is {type(problem).__name__}, not ImpactProblem")
        first = problems[0]
        for k, problem in enumerate(problems):
            if (problem.n, problem.m, problem.d) != (first.n, first.m, first.d):
                raise InvalidProblem(
                    f"problem {k} has (n, m, d) = ({problem.n}, {problem.m}, {problem.d}), "
                    f"problem 0 has ({first.n}, {first.m}, {first.d}): a batch holds problems "
                    "of one shape"
                )
            if problem.gaps.any():
                raise InvalidProblem(f"problem {k} has gaps: a batch is simultaneous")
        contacts = [p.contacts for p in problems]
        coefficients = {
            name: np.array([[c.restitution(kind) for c in row] for row in contacts])
            for kind, name in RESTITUTION_FIELDS.items()
            if any(getattr(c, name) is not None for row in contacts for c in row)
        }
        names = ("e", *FRICTION_COEFFICIENTS) if first.Wt is not None else ("e",)
        for name in names:
            coefficients[name] = np.array([[getattr(c, name) for c in row] for row in contacts])
        Wt = None if first.Wt is None else np.stack([p.Wt for p in problems])
        return cls(
            np.stack([p.M for p in problems]),
            np.stack([p.Wn for p in problems]),
            np.stack([p.v for p in problems]),
            coefficients,
            Wt,
        )

    def __len__(self) -> int:
        return self.v.shape[0]

    @property
    def n(self) -> int:
        """Number of generalized coordinates."""
        return self.v.shape[1]

    @property
    def m(self) -> int:
        """Number of contacts."""
        return self.Wn.shape[2]

    def solve_mass(self, rhs: np.ndarray) -> np.ndarray:
        """``M^-1 @ rhs`` for every problem (``rhs`` of shape (B, n) or (B, n, k))."""
        reciprocal = self.__dict__.get("_inverse_diagonal")
        if reciprocal is not None:
            return reciprocal * rhs if rhs.ndim == 2 else reciprocal[:, :, None] * rhs
        if rhs.ndim == 2:
            return np.einsum("kij,kj->ki", self._inverse, rhs)
        return self._inverse @ rhs

    @property
    def d(self) -> int:
        """Tangential directions per contact: 0 without ``Wt``, 1 planar, 2 spatial."""
        return 0 if self.Wt is None else self.Wt.shape[2] // self.m

    @cached_property
    def mu(self) -> np.ndarray:
        """Coulomb coefficients (B, m); zeros without a tangential Jacobian."""
        return self.coefficients.get("mu", np.zeros((len(self.v), self.m)))

    @cached_property
    def frictional(self) -> bool:
        """Whether some problem has a tangential Jacobian and a positive mu.

        With `d` and `closed_count`, what a law's `Tags.refusal` reads of a problem: a law's
        tags judge a batch as they judge each of its problems.
        """
        return self.Wt is not None and bool((self.mu > 0).any())

    @property
    def closed_count(self) -> int:
        """Closed contacts of every problem: all of them (a batch has no gaps)."""
        return self.m

    def _symmetric_product(self, W: np.ndarray) -> np.ndarray:
        """``W.T M^-1 W`` for every problem, symmetrized, (B, k, k) for ``W`` (B, n, k)."""
        reciprocal = self.__dict__.get("_inverse_diagonal")
        if reciprocal is not None:
            # One pass over the entries instead of a stack of small matrix products.
            G = np.einsum("kij,ki,kil->kjl", W, reciprocal, W)
        else:
            G = np.swapaxes(W, 1, 2) @ self.solve_mass(W)
        return (G + np.swapaxes(G, 1, 2)) / 2

    @cached_property
    def delassus(self) -> np.ndarray:
        """Normal Delassus matrices ``Wn.T M^-1 Wn``, (B, m, m)."""
        return self._symmetric_product(self.Wn)

    @cached_property
    def W(self) -> np.ndarray:
        """Contact Jacobians ``[Wn, Wt]`` (B, n, m + m*d): normal columns, then tangential."""
        return self.Wn if self.Wt is None else np.concatenate([self.Wn, self.Wt], axis=2)

    @cached_property
    def contact_delassus(self) -> np.ndarray:
        """``W.T M^-1 W`` (B, m + m*d, m + m*d), in `ImpactProblem.contact_delassus`' order."""
        return self.delassus if self.Wt is None else self._symmetric_product(self.W)

    @cached_property
    def in_own_units(self) -> bool:
        """Whether every problem is solved in its own units (`ImpactProblem.units` is 1).

        True when each problem's heaviest mass entry and its fastest speed (if any) lie within
        `UNIT_BAND` of 1; a vectorized path holds then, and the rest go one by one.
        """
        mass = np.abs(np.einsum("kii->ki", self.M)).max(axis=1)
        speed = np.abs(self.v).max(axis=1)
        near = (mass >= 1.0 / UNIT_BAND) & (mass <= UNIT_BAND)
        return bool(
            (near & ((speed == 0.0) | ((speed >= 1.0 / UNIT_BAND) & (speed <= UNIT_BAND)))).all()
        )

    @cached_property
    def un(self) -> np.ndarray:
        """Pre-impact gap rates ``Wn.T @ v``, (B, m)."""
        return np.einsum("knm,kn->km", self.Wn, self.v)

    @cached_property
    def ut(self) -> np.ndarray:
        """Pre-impact slip velocities ``Wt.T @ v``, (B, m*d); (B, 0) without ``Wt``."""
        if self.Wt is None:
            return np.zeros((len(self), 0))
        return np.einsum("knm,kn->km", self.Wt, self.v)

    def restitution(self, kind: str) -> np.ndarray:
        """Per-problem, per-contact coefficients of ``kind`` (the override where given), (B, m)."""
        return self.coefficients.get(RESTITUTION_FIELDS[kind], self.coefficients["e"])

    def kinetic_energy(self, v: np.ndarray) -> np.ndarray:
        """``v @ M @ v / 2`` for every problem."""
        if "_inverse_diagonal" in self.__dict__:
            return 0.5 * np.einsum("kn,kn,kn->k", v, np.einsum("kii->ki", self.M), v)
        return 0.5 * np.einsum("kn,knl,kl->k", v, self.M, v)

    def problem(self, k: int) -> ImpactProblem:
        """Problem ``k`` as an `ImpactProblem` (for the one-by-one path)."""
        fields = {f.name for f in dataclasses.fields(Contact)}
        contacts = [
            Contact(
                **{
                    name: float(self.coefficients[name][k, j])
                    for name in self.coefficients
                    if name in fields
                }
            )
            for j in range(self.m)
        ]
        Wt = None if self.Wt is None else self.Wt[k]
        return ImpactProblem(self.M[k], self.Wn[k], self.v[k], contacts, Wt)


@dataclass(frozen=True, eq=False)
class OutcomeBatch:
    """Outcomes of a batch, stacked: the fields of `lawbench.Outcome` with a batch axis.

    Attributes
    ----------
    v_plus : array (B, n)
    Pn : array (B, m)
    T_minus, T_plus : array (B,)
    diagnostics : dict
        ``formulation`` (the vectorized method, or 'one by one'), ``options``, ``wall_time_s``.
    Pt : array (B, m*d)
        Tangential impulses; (B, 0) without a tangential Jacobian (the default).
    """

    v_plus: np.ndarray
    Pn: np.ndarray
    T_minus: np.ndarray
    T_plus: np.ndarray
    diagnostics: dict[str, Any] = field(default_factory=dict)
    Pt: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.Pt is None:
            object.__setattr__(self, "Pt", np.zeros((len(self.v_plus), 0)))

    @classmethod
    def from_impulses(
        cls, batch: ProblemBatch, Pn: np.ndarray, Pt: np.ndarray | None = None, **diagnostics: Any
    ) -> OutcomeBatch:
        """Apply impulses ``Pn`` (B, m) and ``Pt`` (B, m*d) to every problem of ``batch``.

        ``Pt`` None gives no tangential impulse: (B, m*d) zeros for a batch with ``Wt``.
        """
        impulse = np.einsum("knm,km->kn", batch.Wn, Pn)
        if Pt is None:
            Pt = np.zeros((len(batch), batch.m * batch.d))
        elif batch.d:
            impulse += np.einsum("knm,km->kn", batch.Wt, Pt)
        v_plus = batch.v + batch.solve_mass(impulse)
        return cls(
            v_plus,
            Pn,
            batch.kinetic_energy(batch.v),
            batch.kinetic_energy(v_plus),
            dict(diagnostics),
            Pt,
        )

    @property
    def dT(self) -> np.ndarray:
        """Kinetic energy changes ``T_plus - T_minus`` (positive: energy created)."""
        return self.T_plus - self.T_minus

    def __len__(self) -> int:
        return self.v_plus.shape[0]

    def to_frame(self) -> pd.DataFrame:
        """One row per problem: ``v_plus_i``, ``Pn_j``, ``Pt_j``, ``T_minus``, ``T_plus``, ``dT``.

        ``Pt_j`` is the j-th tangential impulse (contact ``j // d``); none without friction.
        """
        import pandas as pd

        columns = {f"v_plus_{i}": self.v_plus[:, i] for i in range(self.v_plus.shape[1])}
        columns |= {f"Pn_{j}": self.Pn[:, j] for j in range(self.Pn.shape[1])}
        columns |= {f"Pt_{j}": self.Pt[:, j] for j in range(self.Pt.shape[1])}
        columns |= {"T_minus": self.T_minus, "T_plus": self.T_plus, "dT": self.dT}
        return pd.DataFrame(columns)
