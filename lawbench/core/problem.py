"""The impact problem every law consumes: linear algebra at a frozen configuration.

Sign conventions, used everywhere in lawbench: the gap rate of contact j is
``un[j] = Wn[:, j] @ v``; ``un < 0`` approaches and ``un > 0`` separates. Normal impulses
``Pn >= 0`` push the bodies apart, and ``v_plus = v + M^-1 (Wn @ Pn + Wt @ Pt)``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import operator
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Generic, NoReturn, TypeVar, overload

import numpy as np

from lawbench.core.errors import InvalidProblem

# The kinds of restitution coefficient and the contact field that overrides ``e`` for each:
# Newton's kinematic, Poisson's kinetic, Stronge's energetic coefficient.
RESTITUTION_FIELDS = {"kinematic": "e_newton", "kinetic": "e_poisson", "energetic": "e_energy"}
# Mindlin's ratio of the normal to the tangential stiffness of a contact between identical
# elastic bodies of Poisson's ratio 0.3, (2 - nu) / (2 (1 - nu)) = 17/14: the contacts'
# tangential_stiffness_ratio when none is given (Jia 2013 rounds it to 1.2).
MINDLIN_RATIO = (2 - 0.3) / (2 * (1 - 0.3))
# Up to this many coordinates the inverse of M is kept: a product is cheaper than a solve.
SMALL = 64
# A matrix with at most this share of non-zero entries is multiplied as a sparse one.
SPARSE_SHARE = 0.05
# A closed contact separates when its gap rate exceeds this fraction of the largest rate.
SEPARATING = 1e-12


_T = TypeVar("_T")


class cached_property(Generic[_T]):  # noqa: N801 (named as the functools one it replaces)
    """A computed attribute, stored in the instance on first use.

    `functools.cached_property` without the lock it takes on every first use before Python
    3.12: a problem is immutable, so two threads that both compute a value get the same one.
    """

    def __init__(self, function: Callable[[Any], _T]) -> None:
        self.function = function
        self.name = function.__name__
        self.__doc__ = function.__doc__

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, instance: None, owner: type | None = None) -> cached_property[_T]: ...

    @overload
    def __get__(self, instance: object, owner: type | None = None) -> _T: ...

    def __get__(self, instance: object | None, owner: type | None = None) -> Any:
        if instance is None:
            return self
        value = self.function(instance)
        instance.__dict__[self.name] = value
        return value


@np.errstate(over="ignore", invalid="ignore")
def kinetic_energy(M: np.ndarray, v: np.ndarray) -> float:
    """Return ``v @ M @ v / 2`` (inf, without a warning, when it overflows)."""
    return float(v.dot(M.dot(v))) / 2.0


# Up to this many entries an array is reduced as Python floats: cheaper than a numpy reduction
# (about 1 us each), and overflow and NaN propagate there without a warning.
REDUCED_IN_PYTHON = 64


def all_finite(array: np.ndarray) -> bool:
    """Whether every entry of ``array`` is finite.

    An infinite or NaN entry makes the sum non-finite, so a finite sum settles it in one
    reduction; only a non-finite sum (which overflow can also give) is looked at entry by entry.
    """
    total = sum(array.ravel().tolist()) if array.size <= REDUCED_IN_PYTHON else array.sum()
    return math.isfinite(total) or bool(np.isfinite(array).all())


def smallest(array: np.ndarray) -> float:
    """The smallest entry of a non-empty array of finite numbers."""
    return min(array.tolist()) if array.size <= REDUCED_IN_PYTHON else float(array.min())


def largest(array: np.ndarray) -> float:
    """The largest entry of a non-empty array of finite numbers."""
    return max(array.tolist()) if array.size <= REDUCED_IN_PYTHON else float(array.max())


# Columns of M^-1 W solved at once through a sparse factor of M: bounds the dense block.
SOLVE_BLOCK = 256

# A problem whose heaviest mass entry and fastest velocity component lie within this factor of
# 1 (about 1e-9 to 1e9) is solved in its own units; beyond, in units near them
# (`ImpactProblem.units`).
UNIT_BAND = 2.0**30


def binary_scale(size: float) -> float:
    """The power of two nearest ``size`` (1 for zero or a non-finite size).

    Multiplying by it is exact (no digit is rounded) wherever no number under- or overflows.
    """
    if not math.isfinite(size) or size <= 0.0:
        return 1.0
    return math.ldexp(1.0, round(math.log2(size)))


def is_sparse(value: object) -> bool:
    """Whether ``value`` is a scipy.sparse matrix or array.

    Without scipy.sparse imported no value can be one, so small problems never import it.
    """
    if isinstance(value, np.ndarray):
        return False
    module = sys.modules.get("scipy.sparse")
    return module is not None and bool(module.issparse(value))


def as_array(value: Any) -> np.ndarray:
    """``value`` as a numpy array: a scipy.sparse one densified, any other as it is."""
    return value.toarray() if is_sparse(value) else value


def _check_range(label: str, value: float, low: float, high: float | None = None) -> None:
    """Raise `InvalidProblem` unless ``low <= value <= high`` (``high`` None: unbounded)."""
    if not math.isfinite(value):
        raise InvalidProblem(f"{label} = {value}: must be a finite number")
    if value < low or (high is not None and value > high):
        bounds = f"in [{low:g}, {high:g}]" if high is not None else f">= {low:g}"
        raise InvalidProblem(f"{label} = {value:g}: must be {bounds}")


@dataclass(frozen=True)
class Contact:
    """Parameters of one contact.

    Parameters
    ----------
    e : float
        Restitution coefficient, read by each law as its own kind: kinematic for Newton and
        Moreau, kinetic for Poisson, energetic (Stronge) for Darboux-Keller and the energetic
        multiple-impact law. In [0, 1].
    e_newton, e_poisson, e_energy : float or None
        Overrides of ``e`` for one kind of coefficient.
    e_t : float
        Tangential restitution coefficient (Brach), in [-1, 1].
    mu : float
        Coulomb friction coefficient; 0 means frictionless.
    stiffness : float
        Contact stiffness (N/m^exponent); compliant models use it, rigid laws only its ratios.
    exponent : float
        Force-indentation exponent: 1 linear, 1.5 Hertz.
    damping : float
        Damping coefficient of compliant models.
    tangential_stiffness_ratio : float or None
        Jia's ratio eta0^2 = k0 / k' of the normal (compression) to the tangential stiffness;
        None for Mindlin's (`MINDLIN_RATIO`).
    """

    e: float = 1.0
    e_newton: float | None = None
    e_poisson: float | None = None
    e_energy: float | None = None
    e_t: float = 0.0
    mu: float = 0.0
    stiffness: float = 1.0
    exponent: float = 1.5
    damping: float = 0.0
    tangential_stiffness_ratio: float | None = None

    @property
    def tangential_ratio(self) -> float:
        """``tangential_stiffness_ratio``, or Mindlin's when it is None."""
        ratio = self.tangential_stiffness_ratio
        return MINDLIN_RATIO if ratio is None else ratio

    def validate(self, label: str) -> None:
        """Raise `InvalidProblem` naming ``label.field`` for the first bad field.

        A contact is immutable: once it has passed, it is not checked again.
        """
        if "_valid" in self.__dict__:
            return
        for name in ("e", "e_newton", "e_poisson", "e_energy"):
            value = getattr(self, name)
            if value is not None:
                _check_range(f"{label}.{name}", value, 0.0, 1.0)
        _check_range(f"{label}.e_t", self.e_t, -1.0, 1.0)
        _check_range(f"{label}.mu", self.mu, 0.0)
        _check_range(f"{label}.damping", self.damping, 0.0)
        for name in ("stiffness", "exponent", "tangential_stiffness_ratio"):
            value = getattr(self, name)
            if value is None:
                continue
            _check_range(f"{label}.{name}", value, 0.0)
            if value == 0.0:
                raise InvalidProblem(f"{label}.{name} = 0: must be > 0")
        object.__setattr__(self, "_valid", True)

    def restitution(self, kind: str) -> float:
        """Return the coefficient of ``kind`` ('kinematic', 'kinetic' or 'energetic')."""
        if kind not in RESTITUTION_FIELDS:
            raise ValueError(f"unknown restitution kind {kind!r}")
        override = getattr(self, RESTITUTION_FIELDS[kind])
        return self.e if override is None else override


CONTACT_FIELDS = frozenset(f.name for f in dataclasses.fields(Contact))
# One coefficient for every contact, and what a coefficient may be.
_SCALAR = (int, float, str)
_NUMBER = (int, float, np.number)


@functools.lru_cache(maxsize=256, typed=True)
def _shared_contact(**coefficients: Any) -> Contact:
    """The one contact of coefficients every contact shares: built (and checked) once.

    Typed: 1 and 1.0, equal as keys, build their own contact.
    """
    return Contact(**coefficients)


@functools.lru_cache(maxsize=64)
def _no_gaps(m: int) -> np.ndarray:
    """The gaps of m closed contacts: zeros, read-only, one array shared by every such problem."""
    gaps = np.zeros(m)
    gaps.setflags(write=False)
    return gaps


def _cho_solve(cholesky: tuple[np.ndarray, bool], rhs: np.ndarray) -> np.ndarray:
    """``M^-1 rhs`` from M's lower Cholesky factor.

    numpy's solves for a small M (no scipy.linalg to import), scipy's triangular ones beyond.
    """
    factor = cholesky[0]
    if factor.shape[0] <= SMALL:
        return np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
    import scipy.linalg

    return scipy.linalg.cho_solve(cholesky, rhs, check_finite=False)


def _matrix(name: str, value: object, shape: tuple[int, ...]) -> np.ndarray:
    """Return ``value`` as a read-only float array of ``shape``, or raise `InvalidProblem`."""
    if is_sparse(value):
        value = value.toarray()
    try:
        if np.iscomplexobj(value):
            raise InvalidProblem(f"{name}: complex numbers; a problem holds real ones")
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, InvalidProblem):
            raise
        raise InvalidProblem(f"{name}: not an array of numbers ({exc})") from None
    if array.shape != shape:
        raise InvalidProblem(f"{name} has shape {array.shape}, expected {shape}")
    return _read_only_finite(name, array)


def _non_finite(value: float) -> str:
    """What a non-finite number is, in words (a message never shows a NaN of its own)."""
    return "is not a number" if math.isnan(value) else f"is {'-' if value < 0 else ''}infinite"


def _read_only_finite(name: str, array: np.ndarray) -> np.ndarray:
    """Make ``array`` (the problem's own copy) read-only, or raise naming a non-finite entry."""
    if not all_finite(array):
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        raise InvalidProblem(f"{name}{list(index)} {_non_finite(array[index])}: must be finite")
    array.setflags(write=False)
    return array


def _sparse_matrix(name: str, value: object, shape: tuple[int, int]) -> Any:
    """Return ``value`` as a read-only CSC array of ``shape``, or raise `InvalidProblem`.

    The checks cost O(nnz): only the stored entries are read.
    """
    import scipy.sparse

    try:
        matrix = scipy.sparse.csc_array(value, dtype=float, copy=True)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{name}: not a matrix of numbers ({exc})") from None
    if matrix.shape != shape:
        raise InvalidProblem(f"{name} has shape {matrix.shape}, expected {shape}")
    matrix.sum_duplicates()
    bad = np.flatnonzero(~np.isfinite(matrix.data))
    if bad.size:
        k = int(bad[0])
        column = int(np.searchsorted(matrix.indptr, k, side="right")) - 1
        raise InvalidProblem(
            f"{name}{[int(matrix.indices[k]), column]} {_non_finite(matrix.data[k])}: must be "
            "finite"
        )
    matrix.eliminate_zeros()
    for part in (matrix.data, matrix.indices, matrix.indptr):
        part.setflags(write=False)
    return matrix


def _sparse_factor(M: Any) -> Any:
    """Sparse LU factor of a symmetric M with symmetric ordering and no pivoting, or None.

    Without pivoting the factor is ``P M P.T = L D L.T`` written as ``L U``: M is positive
    definite exactly when every pivot, the diagonal of U, is positive.
    """
    import scipy.sparse.linalg

    try:
        factor = scipy.sparse.linalg.splu(
            M,
            permc_spec="MMD_AT_PLUS_A",
            diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )
    except RuntimeError:  # an exactly singular pivot
        return None
    if not np.array_equal(factor.perm_r, factor.perm_c) or (factor.U.diagonal() <= 0).any():
        return None
    return factor


def has_off_diagonal(M: Any) -> bool:
    """Whether M (dense or sparse) has a non-zero entry off its diagonal."""
    if isinstance(M, np.ndarray):
        return np.count_nonzero(M) != np.count_nonzero(M.diagonal())
    coo = M.tocoo()
    return bool(np.any(coo.data[coo.row != coo.col]))


@dataclass(frozen=True, eq=False, init=False)
class ImpactProblem:
    """An impact at a frozen configuration, validated when built.

    ``M``, ``Wn`` and ``Wt`` may be scipy.sparse matrices. Beyond ``SMALL`` coordinates the
    problem then keeps all three as CSC arrays (`sparse`), checks them in O(nnz) and solves
    with M through its reciprocal diagonal or one sparse LU factor; a smaller one is densified.

    Parameters
    ----------
    M : array or scipy.sparse matrix (n, n)
        Symmetric positive definite mass matrix in generalized coordinates.
    Wn : array or scipy.sparse matrix (n, m)
        Normal Jacobian: ``un = Wn.T @ v`` is the gap rate of the m contacts.
    v : array (n,)
        Pre-impact generalized velocity.
    contacts : sequence of Contact
        One entry per contact.
    Wt : array or scipy.sparse matrix (n, m*d), or None
        Tangential Jacobian, d = 1 (planar) or 2 (spatial); None without friction.
    bodies : mapping of str to sequence of int
        Body name -> indices of its generalized coordinates (for energy shares).
    gaps : array (m,) or None
        Initial gaps; None means zero (a simultaneous impact). A contact with a positive gap is
        open: the rigid laws leave it alone at this instant.

    Attributes
    ----------
    n, m : int
        Numbers of generalized coordinates and of contacts.
    d : int
        Tangential directions per contact: 0 without friction, 1 planar, 2 spatial.
    sparse : bool
        Whether M, Wn and Wt are scipy.sparse CSC arrays (a large problem given sparse). Then
        `delassus`, `W` and `contact_delassus` are sparse too; `dense` gives the problem with
        arrays.
    T_minus : float
        Kinetic energy before the impact, ``v @ M @ v / 2`` (finite: checked).

    Raises
    ------
    InvalidProblem
        When a shape disagrees, M is not symmetric positive definite, a number is not finite,
        or a contact parameter is out of range; the message names the field and value.
    """

    M: np.ndarray
    Wn: np.ndarray
    v: np.ndarray
    contacts: Sequence[Contact]
    Wt: np.ndarray | None = None
    bodies: Mapping[str, Sequence[int]] = field(default_factory=dict)
    gaps: np.ndarray | None = None
    # Found while the fields are checked and stored then by `__init__`: reading one is a
    # dictionary look-up (a property's call costs more than a small impact's arithmetic).
    n: int = field(init=False, repr=False)
    m: int = field(init=False, repr=False)
    d: int = field(init=False, repr=False)
    sparse: bool = field(init=False, repr=False)
    T_minus: float = field(init=False, repr=False)

    def __init__(
        self,
        M: Any,
        Wn: Any,
        v: Any,
        contacts: Sequence[Contact],
        Wt: Any = None,
        bodies: Mapping[str, Sequence[int]] | None = None,
        gaps: Any = None,
    ) -> None:
        # Every field is checked here and the problem keeps its own read-only copies, written
        # once into the instance (the dataclass is frozen).
        try:
            v = np.array(v, dtype=float, ndmin=1)
        except (TypeError, ValueError) as exc:
            raise InvalidProblem(f"v: not an array of numbers ({exc})") from None
        n = v.shape[0] if v.ndim == 1 else -1
        if n < 1:
            raise InvalidProblem(f"v has shape {v.shape}, expected (n,) with n >= 1")
        contacts = tuple(contacts)
        m = len(contacts)
        if m < 1:
            raise InvalidProblem("contacts is empty: an impact needs at least one contact")
        repeated = 0
        for j, contact in enumerate(contacts):
            if j and contact is contacts[j - 1]:
                repeated += 1
                continue
            if not isinstance(contact, Contact):
                raise InvalidProblem(f"contacts[{j}] is {type(contact).__name__}, not Contact")
            if "_valid" not in contact.__dict__:
                contact.validate(f"contacts[{j}]")
        sparse = n > SMALL and any(is_sparse(a) for a in (M, Wn, Wt))
        matrix = _sparse_matrix if sparse else _matrix
        state = self.__dict__
        state.update(
            n=n,
            m=m,
            sparse=sparse,
            v=_read_only_finite("v", v),
            M=matrix("M", M, (n, n)),
            Wn=matrix("Wn", Wn, (n, m)),
            contacts=contacts,
            Wt=None,
            _restitutions={},
            # One contact object for every contact: its coefficients are every contact's.
            _one_contact=contacts[0] if repeated == m - 1 else None,
        )
        if Wt is None:
            state.update(frictional=False, d=0)
        else:
            d = np.shape(Wt)[1] // m if np.ndim(Wt) == 2 else 0
            if d not in (1, 2):
                raise InvalidProblem(f"Wt has shape {np.shape(Wt)}, expected ({n}, {m}*d)")
            state.update(Wt=matrix("Wt", Wt, (n, m * d)), d=d)
        if gaps is None:
            gaps = _no_gaps(m)
            state["closed_count"] = m
        else:
            gaps = _matrix("gaps", gaps, (m,))
            if (gaps < 0).any():
                j = int(np.argmax(gaps < 0))
                raise InvalidProblem(f"gaps[{j}] = {gaps[j]:g}: must be >= 0")
        state["gaps"] = gaps
        checked: dict[str, tuple[int, ...]] = {}
        if bodies is not None and not isinstance(bodies, Mapping):
            raise TypeError(
                f"bodies must be a mapping of names to indices, not {type(bodies).__name__}"
            )
        for name, indices in (bodies or {}).items():
            try:
                idx = tuple(int(i) for i in indices)
            except (TypeError, ValueError):
                raise InvalidProblem(f"bodies[{str(name)!r}] = {indices!r}: not indices") from None
            if any(i < 0 or i >= n for i in idx):
                raise InvalidProblem(f"bodies[{str(name)!r}] = {idx}: indices must lie in [0, {n})")
            checked[str(name)] = idx
        state["bodies"] = checked
        self._check_normals(self._factor_mass())
        T_minus = self.kinetic_energy(self.v)
        if not math.isfinite(T_minus):
            raise InvalidProblem(f"v and M give a kinetic energy that overflows ({T_minus})")
        state["T_minus"] = T_minus

    @classmethod
    def from_arrays(
        cls,
        M: object,
        Wn: object,
        v: object,
        Wt: object | None = None,
        *,
        gaps: object | None = None,
        bodies: Mapping[str, Sequence[int]] | None = None,
        **coefficients: object,
    ) -> ImpactProblem:
        """Build a problem from arrays and per-contact coefficients.

        Parameters
        ----------
        M, Wn, v, Wt, gaps, bodies
            As in the class.
        **coefficients
            Fields of `Contact` (``e``, ``mu``, ``stiffness``, ...): one value for every
            contact, or a sequence with one value per column of ``Wn``.

        Raises
        ------
        InvalidProblem
            For an unknown coefficient, a sequence of the wrong length, or any bad field.
        """
        try:
            shape = Wn.shape if type(Wn) is np.ndarray else np.shape(Wn)
        except ValueError as exc:  # a ragged nesting of lists
            raise InvalidProblem(f"Wn: not an array of numbers ({exc})") from None
        m = shape[1] if len(shape) == 2 else 0
        shared: dict[str, object] = {}
        per_contact: dict[str, list[object]] = {}
        for name, value in coefficients.items():
            if name not in CONTACT_FIELDS:
                known = ", ".join(sorted(CONTACT_FIELDS))
                raise InvalidProblem(f"unknown contact coefficient {name!r}; known: {known}")
            one = isinstance(value, _SCALAR) or not isinstance(value, Sequence | np.ndarray)
            if not one and len(value) != m:
                raise InvalidProblem(
                    f"{name} has {len(value)} values, expected 1 or {m} (one per contact)"
                )
            # A shared value is checked once, as contact 0's.
            values = ([value] if m else []) if one else list(value)
            for j, entry in enumerate(values):
                if entry is not None and not isinstance(entry, _NUMBER):
                    raise InvalidProblem(f"contacts[{j}].{name} = {entry!r}: not a number")
            if one:
                shared[name] = value
            else:
                per_contact[name] = values
        if per_contact:
            contacts = [
                Contact(**shared, **{name: values[j] for name, values in per_contact.items()})
                for j in range(m)
            ]
        else:
            # One set of coefficients: one (immutable) contact serves, validated once.
            contacts = (_shared_contact(**shared),) * m
        return cls(M, Wn, v, contacts, Wt, bodies, gaps)

    def _factor_mass(self) -> float:
        """Check that M is symmetric positive definite and keep what `solve_mass` uses.

        A diagonal M (points, decoupled coordinates) is inverted exactly by its reciprocal
        diagonal; any other by its Cholesky factor, or its sparse LU factor when sparse.
        Returns the largest diagonal entry of M^-1 (a lower bound of it when sparse).
        """
        diagonal = self.M.diagonal()
        # A positive definite M has no zero on its diagonal: with n non-zero entries it is
        # diagonal, and with fewer, or a zero on the diagonal, the test below refuses it.
        stored = self.M.count_nonzero() if self.sparse else np.count_nonzero(self.M)
        if stored <= self.n:
            lightest = smallest(diagonal)
            if not lightest > 0:
                raise InvalidProblem("M is not positive definite")
            if math.isinf(1.0 / lightest):
                self._too_close_to_singular()
            reciprocal = 1.0 / diagonal
            reciprocal.setflags(write=False)
            object.__setattr__(self, "_inverse_diagonal", reciprocal)
            if diagonal.size <= REDUCED_IN_PYTHON:
                object.__setattr__(self, "_masses", diagonal.tolist())
            # Rounded division is monotone: the largest reciprocal is that of the smallest mass.
            return 1.0 / lightest
        asymmetry = abs(self.M - self.M.T).max()
        if asymmetry > 1e-12 * abs(self.M).max():
            raise InvalidProblem(f"M is not symmetric (largest |M - M.T| = {asymmetry:.3g})")
        if self.sparse:
            factor = _sparse_factor(self.M)
            if factor is None:
                raise InvalidProblem("M is not positive definite")
            object.__setattr__(self, "_sparse_factor", factor)
            # (M^-1)_ii >= 1 / M_ii (Cauchy-Schwarz): a bound without the inverse, enough for
            # a test at rounding level.
            return float((1.0 / diagonal).max())
        try:
            object.__setattr__(self, "_cholesky", (np.linalg.cholesky(self.M), True))
        except np.linalg.LinAlgError:
            raise InvalidProblem("M is not positive definite") from None
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            inverse = _cho_solve(self._cholesky, np.eye(self.n))
        if not all_finite(inverse):
            self._too_close_to_singular()
        if self.n <= SMALL:
            inverse.setflags(write=False)
            object.__setattr__(self, "_inverse", inverse)
        return float(inverse.diagonal().max())

    def _too_close_to_singular(self) -> NoReturn:
        diagonal = np.diag(self.M)
        raise InvalidProblem(
            f"M is too close to singular: its inverse overflows (smallest diagonal entry "
            f"M[{int(np.argmin(diagonal))}, {int(np.argmin(diagonal))}] = {diagonal.min():.3g})"
        )

    def _check_normals(self, inverse_mass: float) -> None:
        """Refuse a contact that no motion can push along its normal (a singular configuration).

        Its normal Delassus entry is then rounding noise (for example a pendulum hanging
        straight down onto the floor), and every law's impulse would be meaningless.
        ``inverse_mass`` is the largest diagonal entry of M^-1, within a factor n of its largest
        eigenvalue: scale enough for a test at rounding level.
        """
        if self.sparse:
            normal = (self.Wn * self._mass_solved(self.Wn)).sum(axis=0)
            columns = (self.W * self.W).sum(axis=0)
        elif self.n <= SMALL:
            # The Delassus matrix is cheap here and every law needs it: its diagonal serves
            # (where M^-1 overflows, infinite entries, refused below).
            with np.errstate(over="ignore"):
                normal, columns = self.delassus.diagonal(), None
        else:
            normal, columns = np.einsum("ij,ij->j", self.Wn, self.solve_mass(self.Wn)), None
        # The squared Frobenius norm of W bounds its largest squared column: one product
        # settles the usual case.
        W = self.Wn if self.Wt is None else self.W
        total = float(columns.sum()) if columns is not None else float(np.vdot(W, W))
        if smallest(normal) > 1e-12 * inverse_mass * total:
            return
        if columns is None:
            columns = np.einsum("ij,ij->j", W, W)
        # Each contact against the inverse masses of the coordinates its normal moves: a light
        # body elsewhere (masses 1e-20 and 1 kg) makes no contact singular.
        geometry = 1e-12 * float(columns.max())
        for j in range(self.m):
            if not normal[j] / self._inverse_mass_on(j, inverse_mass) > geometry:
                raise InvalidProblem(
                    f"contacts[{j}]: no motion moves it along its normal (Wn[:, {j}] M^-1 "
                    f"Wn[:, {j}] = {normal[j]:.3g}): a singular configuration"
                )

    def _inverse_mass_on(self, j: int, inverse_mass: float) -> float:
        """The largest diagonal entry of M^-1 over the coordinates contact j's normal moves.

        ``inverse_mass`` (the largest over all) where M^-1's diagonal is not at hand.
        """
        diagonal = self.__dict__.get("_inverse_diagonal")
        if diagonal is None and "_inverse" in self.__dict__:
            diagonal = self._inverse.diagonal()
        column = self.Wn[:, [j]].toarray().ravel() if self.sparse else self.Wn[:, j]
        if diagonal is None or not column.any():
            return inverse_mass
        return float(diagonal[column != 0].max())

    @cached_property
    def frictional(self) -> bool:
        """Whether some contact has a tangential Jacobian and a positive mu."""
        return self.Wt is not None and any(c.mu > 0 for c in self.contacts)

    @cached_property
    def closed(self) -> np.ndarray:
        """Boolean mask of the contacts with zero gap, the ones an impact involves."""
        closed = self.gaps <= 0.0
        closed.setflags(write=False)
        return closed

    @cached_property
    def closed_count(self) -> int:
        """Number of closed contacts."""
        return self.m - int(np.count_nonzero(self.gaps))

    @cached_property
    def separating(self) -> tuple[int, ...]:
        """Closed contacts whose gap rate is positive before the impact (they separate)."""
        if largest(self.un) <= 0.0:
            return ()
        scale = float(np.abs(self.un).max())
        separating = self.closed & (self.un > SEPARATING * (scale or 1.0))
        return tuple(int(j) for j in np.flatnonzero(separating))

    def kinetic_energy(self, v: np.ndarray) -> float:
        """Kinetic energy ``v @ M @ v / 2`` of a velocity ``v`` (inf when it overflows).

        A small diagonal M's in Python floats, from its diagonal: cheaper than numpy's calls.
        """
        masses = self.__dict__.get("_masses")
        if masses is None:
            return kinetic_energy(self.M, v)
        velocities = v.tolist()
        # x (m x), the products of numpy's v @ (M v).
        return sum(map(operator.mul, velocities, map(operator.mul, masses, velocities))) / 2.0

    def dense(self) -> ImpactProblem:
        """The same problem with numpy arrays in place of sparse ones (itself when dense)."""
        if not self.sparse:
            return self
        Wt = None if self.Wt is None else self.Wt.toarray()
        return dataclasses.replace(self, M=self.M.toarray(), Wn=self.Wn.toarray(), Wt=Wt)

    def solve_mass(self, rhs: Any) -> Any:
        """Return ``M^-1 @ rhs``.

        The cached inverse of a small M, the reciprocal diagonal, or M's (sparse LU or
        Cholesky) factor; a sparse ``rhs`` gives a sparse answer.
        """
        reciprocal = self.__dict__.get("_inverse_diagonal")
        if reciprocal is not None and not is_sparse(rhs):
            return reciprocal * rhs if np.ndim(rhs) == 1 else reciprocal[:, None] * rhs
        if is_sparse(rhs):
            return self._mass_solved(rhs)
        inverse = self.__dict__.get("_inverse")
        if inverse is not None:
            return inverse.dot(rhs)
        factor = self.__dict__.get("_sparse_factor")
        if factor is not None:
            return factor.solve(np.asarray(rhs, dtype=float))
        return _cho_solve(self._cholesky, rhs)

    def _mass_solved(self, W: Any) -> Any:
        """``M^-1 W`` of a sparse ``W`` as a CSC array, in O(nnz) for a diagonal M.

        Through M's sparse factor ``SOLVE_BLOCK`` columns at a time, keeping non-zero entries.
        """
        import scipy.sparse

        reciprocal = self.__dict__.get("_inverse_diagonal")
        if reciprocal is not None:
            return scipy.sparse.csc_array(W.multiply(reciprocal[:, None]))
        if not self.sparse:
            return scipy.sparse.csc_array(self.solve_mass(W.toarray()))
        blocks = [
            scipy.sparse.csc_array(self.solve_mass(W[:, k : k + SOLVE_BLOCK].toarray()))
            for k in range(0, W.shape[1], SOLVE_BLOCK)
        ]
        return scipy.sparse.hstack(blocks, format="csc")

    def _sparse_delassus(self, W: Any) -> Any:
        """``W.T M^-1 W`` of a sparse ``W``, symmetrized, as a CSC array."""
        G = W.T @ self._mass_solved(W)
        return ((G + G.T) / 2).tocsc()

    @cached_property
    def delassus(self) -> Any:
        """Normal Delassus matrix ``G = Wn.T M^-1 Wn`` (m, m): gap-rate change per impulse.

        Sparse for a sparse problem.
        """
        if self.sparse:
            return self._sparse_delassus(self.Wn)
        if self.n > SMALL and np.count_nonzero(self.Wn) <= SPARSE_SHARE * self.Wn.size:
            # Chains and columns: each contact moves two bodies, so G is banded; the sparse
            # product costs O(nnz) instead of O(n m^2).
            import scipy.sparse

            G = self._sparse_delassus(scipy.sparse.csc_array(self.Wn)).toarray()
        elif "_inverse_diagonal" in self.__dict__:
            # S.T S with S = M^-1/2 Wn: symmetric as computed (one product, no symmetrizing).
            scaled = self.Wn * np.sqrt(self._inverse_diagonal)[:, None]
            G = scaled.T.dot(scaled)
        else:
            G = self.Wn.T.dot(self.solve_mass(self.Wn))
            G = (G + G.T) / 2
        G.setflags(write=False)
        return G

    @cached_property
    def un(self) -> np.ndarray:
        """Pre-impact normal gap rates ``Wn.T @ v``."""
        un = self.Wn.T.dot(self.v)
        un.setflags(write=False)
        return un

    @cached_property
    def W(self) -> Any:
        """Contact Jacobian ``[Wn, Wt]`` (n, m + m*d): normal columns, then tangential."""
        if self.Wt is None:
            return self.Wn
        if self.sparse:
            import scipy.sparse

            return scipy.sparse.hstack([self.Wn, self.Wt], format="csc")
        return np.hstack([self.Wn, self.Wt])

    @cached_property
    def contact_delassus(self) -> Any:
        """Delassus matrix of normal and tangential directions ``W.T M^-1 W``.

        Blocks: ``[[Gnn, Gnt], [Gtn, Gtt]]`` with the m normal rows first, then the m*d
        tangential rows (contact j's tangential rows are ``m + j*d ... m + j*d + d - 1``).
        Sparse for a sparse problem.
        """
        if self.sparse:
            return self._sparse_delassus(self.W)
        G = self.W.T @ self.solve_mass(self.W)
        G = (G + G.T) / 2
        G.setflags(write=False)
        return G

    @cached_property
    def ut(self) -> np.ndarray:
        """Pre-impact tangential slip velocities ``Wt.T @ v`` (m*d,); empty without Wt."""
        return np.zeros(0) if self.Wt is None else self.Wt.T @ self.v

    @cached_property
    def mu(self) -> np.ndarray:
        """Friction coefficients, one per contact."""
        mu = np.array([c.mu for c in self.contacts])
        mu.setflags(write=False)
        return mu

    def restitution(self, kind: str) -> np.ndarray:
        """Per-contact restitution coefficients of ``kind`` (a key of `RESTITUTION_FIELDS`)."""
        coefficients = self._restitutions.get(kind)
        if coefficients is None:
            one = self._one_contact
            if one is not None:
                coefficients = np.array([one.restitution(kind)] * self.m)
            else:
                coefficients = np.array([c.restitution(kind) for c in self.contacts])
            coefficients.setflags(write=False)
            self._restitutions[kind] = coefficients
        return coefficients

    @cached_property
    def units(self) -> tuple[float, float, float]:
        """The units of mass, velocity and time a scale-free law solves this problem in.

        Powers of two (`binary_scale`) near the heaviest diagonal entry of M and the fastest
        component of v, or 1 for a scale within `UNIT_BAND` of 1; when one of them is not 1,
        the time unit brings the stiffest contact's stiffness near 1 (the time of its
        compression), else it is 1 too. Rescaling by them rounds nothing, and masses of
        1e-308 kg or speeds of 1e-300 m/s come near 1, where the laws' linear algebra and
        integrators neither under- nor overflow.

        Raises
        ------
        InvalidProblem
            When the impulse or energy unit these give, ``mass velocity`` or
            ``mass velocity^2``, is not a positive double: an answer could not be scaled back.
        """
        mass = largest(np.abs(self.M.diagonal()))
        speed = largest(np.abs(self.v))
        mass_unit, velocity_unit = (
            1.0 if 1.0 / UNIT_BAND <= size <= UNIT_BAND else binary_scale(size)
            for size in (mass, speed)
        )
        energy = mass_unit * velocity_unit * velocity_unit
        if not (mass_unit * velocity_unit > 0.0 and 0.0 < energy < math.inf):
            raise InvalidProblem(
                f"M (largest diagonal entry {mass:.3g}) and v (largest |v| {speed:.3g}) give "
                f"impulses and energies beyond double precision (energy scale "
                f"{mass * speed**2:.3g})"
            )
        if mass_unit == velocity_unit == 1.0:
            return 1.0, 1.0, 1.0
        # Compression time of a spring K d^p loaded by the unit mass at the unit speed:
        # (m / (K v^(p - 1)))^(1 / (p + 1)), in base-2 logarithms to stay clear of overflow.
        mass_log, velocity_log = math.log2(mass_unit), math.log2(velocity_unit)
        time_log = min(
            (mass_log - math.log2(c.stiffness) - (c.exponent - 1.0) * velocity_log)
            / (c.exponent + 1.0)
            for c in set(self.contacts)
        )
        return mass_unit, velocity_unit, math.ldexp(1.0, round(time_log))

    def in_units(self, mass: float, velocity: float, time: float) -> ImpactProblem:
        """The problem with masses, velocities and times in units ``mass``, ``velocity``, ``time``.

        Lengths are then in units of ``velocity time``: M and v are divided by their units,
        gaps by the length unit, and a stiffness (N/m^exponent = kg m^(1 - exponent) s^-2) is
        multiplied by ``length^(exponent - 1) time^2 / mass``. A damping's unit depends on the
        compliant model that reads it, so it is kept as given: the laws that read it solve in
        the problem's own units (`lawbench.core.law.Law.scale_free`).

        Raises
        ------
        InvalidProblem
            When a number rescaled leaves double precision, naming it and the units.
        """
        length = velocity * time
        length_log, time_log = math.log2(length), math.log2(time)
        contacts, rescaled = [], {}
        for contact in self.contacts:
            if contact not in rescaled:
                factor_log = (
                    (contact.exponent - 1.0) * length_log + 2.0 * time_log - math.log2(mass)
                )
                stiffness = 2.0 ** (math.log2(contact.stiffness) + factor_log)
                rescaled[contact] = dataclasses.replace(contact, stiffness=stiffness)
            contacts.append(rescaled[contact])
        try:
            return ImpactProblem(
                self.M / mass,
                self.Wn,
                self.v / velocity,
                contacts,
                self.Wt,
                self.bodies,
                self.gaps / length if self.gaps.any() else None,
            )
        except (InvalidProblem, OverflowError) as exc:
            raise InvalidProblem(
                f"in units of {mass:g} kg, {velocity:g} m/s and {time:g} s the problem cannot "
                f"be solved: {exc}"
            ) from None

    def select_contacts(self, mask: np.ndarray) -> ImpactProblem:
        """Return the problem restricted to the contacts where ``mask`` is true."""
        mask = np.asarray(mask, dtype=bool)
        Wt = None
        if self.Wt is not None:
            columns = np.flatnonzero(mask)[:, None] * self.d + np.arange(self.d)
            Wt = self.Wt[:, columns.ravel()]
        return dataclasses.replace(
            self,
            Wn=self.Wn[:, mask],
            Wt=Wt,
            contacts=[c for c, keep in zip(self.contacts, mask, strict=True) if keep],
            gaps=self.gaps[mask],
        )
