"""The matrices of an impact, checked; its kinetic metric; and the units it is solved in.

The arrays a problem holds are dense or scipy.sparse, checked finite and kept read-only;
scipy.sparse is imported only by problems given sparse matrices, so a small problem never loads
it.

An impulse ``P`` along the columns of a Jacobian ``W`` changes the velocity by ``M^-1 W P`` and
the contact velocities ``W.T v`` by ``W.T M^-1 W P``: the Delassus matrix of ``W``, the contact
compliance every rigid law works with. `KineticMetric` checks that M is symmetric positive
definite, keeps the cheapest exact way to apply ``M^-1`` (the reciprocal diagonal of a diagonal
M, the inverse of a small one, a Cholesky or sparse LU factor beyond), and forms these matrices,
dense or sparse.

The units of mass, velocity and time of a solve lie near the impact's own scales: a scale-free
law (`lawbench.core.law.Law.scale_free`) solves a problem in units where its heaviest mass and
fastest speed are near 1, so that masses of 1e-308 kg or speeds of 1e-300 m/s
neither under- nor overflow in its linear algebra and integrators. The units are powers of two:
rescaling by them rounds nothing. `in_units` rescales a problem.

What a problem derives from these on first read it keeps with `cached`.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import sys
from collections.abc import Callable, Iterable
from typing import Any, Generic, NoReturn, TypeVar, overload

import numpy as np

from lawbench.core.errors import InvalidProblem

# Up to this many coordinates the inverse of M is kept: a product is cheaper than a solve.
SMALL = 64
# A matrix with at most this share of non-zero entries is multiplied as a sparse one.
SPARSE_SHARE = 0.05
# Columns of M^-1 W solved at once through a sparse factor of M: bounds the dense block.
SOLVE_BLOCK = 256

_T = TypeVar("_T")


class cached(Generic[_T]):  # noqa: N801 - read like the decorator it replaces
    """A property computed on first read and kept in the instance's ``__dict__``.

    As `functools.cached_property`, without the lock it takes on every first read up to Python
    3.11, which costs as much as the small values a problem keeps (a gap rate, a unit): an
    immutable object's value is the same whichever thread computes it first.
    """

    def __init__(self, function: Callable[[Any], _T]) -> None:
        self.function = function
        self.name = function.__name__
        self.__doc__ = function.__doc__

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, instance: None, owner: type | None = None) -> cached[_T]: ...

    @overload
    def __get__(self, instance: object, owner: type | None = None) -> _T: ...

    def __get__(self, instance: object | None, owner: type | None = None) -> Any:
        if instance is None:
            return self
        value = instance.__dict__[self.name] = self.function(instance)
        return value


def all_finite(array: np.ndarray) -> bool:
    """Whether every entry of ``array`` is finite (it has as many finite entries as entries)."""
    return np.count_nonzero(np.isfinite(array)) == array.size


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


def checked_range(label: str, value: float, low: float, high: float | None = None) -> None:
    """Raise `InvalidProblem` unless ``low <= value <= high`` (``high`` None: unbounded)."""
    try:
        finite = math.isfinite(value)
    except OverflowError:  # an integer beyond the largest double (10**400)
        raise InvalidProblem(
            f"{label}: an integer of {int(value).bit_length()} bits, beyond double precision"
        ) from None
    if not finite:
        raise InvalidProblem(f"{label} = {value}: must be a finite number")
    if value < low or (high is not None and value > high):
        bounds = f"in [{low:g}, {high:g}]" if high is not None else f">= {low:g}"
        raise InvalidProblem(f"{label} = {value:g}: must be {bounds}")


def checked_matrix(name: str, value: object, shape: tuple[int, ...]) -> np.ndarray:
    """Return ``value`` as a read-only float array of ``shape``, or raise `InvalidProblem`.

    A sparse ``value`` is densified once its shape is ``shape``: it may claim a billion columns.
    """
    if is_sparse(value):
        if value.shape != shape:
            raise InvalidProblem(f"{name} has shape {value.shape}, expected {shape}")
        value = value.toarray()
    try:
        if np.iscomplexobj(value):
            raise InvalidProblem(f"{name}: complex numbers; a problem holds real ones")
        array = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:  # OverflowError: an int of 10**400
        if isinstance(exc, InvalidProblem):
            raise
        raise InvalidProblem(f"{name}: not an array of numbers ({exc})") from None
    if array.shape != shape:
        raise InvalidProblem(f"{name} has shape {array.shape}, expected {shape}")
    return read_only_finite(name, array)


def checked_gaps(gaps: Any, m: int) -> np.ndarray:
    """The m initial gaps of a problem, checked finite and non-negative."""
    gaps = checked_matrix("gaps", gaps, (m,))
    if (gaps < 0).any():
        j = int(np.argmax(gaps < 0))
        raise InvalidProblem(f"gaps[{j}] = {gaps[j]:g}: must be >= 0")
    return gaps


@functools.lru_cache(maxsize=64)
def closed_gaps(m: int) -> np.ndarray:
    """The gaps of m closed contacts: zeros, read-only, one array shared by every such problem."""
    gaps = np.zeros(m)
    gaps.setflags(write=False)
    return gaps


def non_finite(value: float) -> str:
    """What a non-finite number is, in words (a message never shows a NaN of its own)."""
    return "is not a number" if math.isnan(value) else f"is {'-' if value < 0 else ''}infinite"


def read_only_finite(name: str, array: np.ndarray) -> np.ndarray:
    """Make ``array`` (the problem's own copy) read-only, or raise naming a non-finite entry."""
    if not all_finite(array):
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        raise InvalidProblem(f"{name}{list(index)} {non_finite(array[index])}: must be finite")
    array.setflags(write=False)
    return array


@np.errstate(over="ignore", invalid="ignore")
def kinetic_energy(M: Any, v: np.ndarray) -> float:
    """Return ``v @ M @ v / 2`` (inf, without a warning, when it overflows)."""
    return float(v.dot(M.dot(v))) / 2.0


def has_off_diagonal(M: Any) -> bool:
    """Whether M (dense or sparse) has a non-zero entry off its diagonal."""
    if isinstance(M, np.ndarray):
        return np.count_nonzero(M) != np.count_nonzero(M.diagonal())
    coo = M.tocoo()
    return bool(np.any(coo.data[coo.row != coo.col]))


def is_diagonal(G: np.ndarray) -> bool:
    """Whether the Delassus matrix (dense or sparse) decouples the contacts."""
    return not has_off_diagonal(G)


def _cho_solve(factor: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``M^-1 rhs`` from M's lower Cholesky factor.

    numpy's solves for a small M (no scipy.linalg to import), scipy's triangular ones beyond.
    """
    if factor.shape[0] <= SMALL:
        return np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
    import scipy.linalg

    return scipy.linalg.cho_solve((factor, True), rhs, check_finite=False)


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


class KineticMetric:
    """A symmetric positive definite mass matrix M, checked, with what applies ``M^-1``.

    Parameters
    ----------
    M : array (n, n) or scipy.sparse CSC array
        The (read-only, finite) mass matrix in generalized coordinates.

    Attributes
    ----------
    M : array or CSC array (n, n)
        The mass matrix.
    sparse : bool
        Whether M is a scipy.sparse array.
    inverse_diagonal : array (n,) or None
        ``1 / diag(M)`` for a diagonal M: then ``M^-1`` is exact and costs O(n).
    inverse : array (n, n) or None
        ``M^-1`` of a small (at most `SMALL` coordinates) non-diagonal M.
    largest_inverse : float
        The largest diagonal entry of ``M^-1`` (a lower bound of it for a sparse,
        non-diagonal M): the scale of the inverse mass, within a factor n of its norm.

    Raises
    ------
    InvalidProblem
        When M is not symmetric positive definite, or so close to singular that its inverse
        overflows.
    """

    def __init__(self, M: Any) -> None:
        self.M = M
        self.n = M.shape[0]
        self.sparse = is_sparse(M)
        self.inverse_diagonal: np.ndarray | None = None
        self.inverse: np.ndarray | None = None
        self._cholesky: np.ndarray | None = None
        self._factor: Any = None
        diagonal = M.diagonal()
        # A positive definite M has no zero on its diagonal: with n non-zero entries it is
        # diagonal, and with fewer, or a zero on the diagonal, the test below refuses it.
        stored = M.count_nonzero() if self.sparse else np.count_nonzero(M)
        if stored <= self.n:
            self.largest_inverse = self._invert_diagonal(diagonal)
            return
        asymmetry = abs(M - M.T).max()
        if asymmetry > 1e-12 * abs(M).max():
            raise InvalidProblem(f"M is not symmetric (largest |M - M.T| = {asymmetry:.3g})")
        if self.sparse:
            self._factor = _sparse_factor(M)
            if self._factor is None:
                raise InvalidProblem("M is not positive definite")
            # (M^-1)_ii >= 1 / M_ii (Cauchy-Schwarz): a bound without the inverse, enough for
            # a test at rounding level.
            self.largest_inverse = float((1.0 / diagonal).max())
            return
        try:
            self._cholesky = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            raise InvalidProblem("M is not positive definite") from None
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            inverse = _cho_solve(self._cholesky, np.eye(self.n))
        if not all_finite(inverse):
            self._too_close_to_singular()
        if self.n <= SMALL:
            inverse.setflags(write=False)
            self.inverse = inverse
        self.largest_inverse = float(inverse.diagonal().max())

    def _invert_diagonal(self, diagonal: np.ndarray) -> float:
        """Keep the reciprocal of a diagonal M and return its largest entry."""
        lightest = float(diagonal.min())
        if not lightest > 0:
            raise InvalidProblem("M is not positive definite")
        if math.isinf(1.0 / lightest):
            self._too_close_to_singular()
        reciprocal = 1.0 / diagonal
        reciprocal.setflags(write=False)
        self.inverse_diagonal = reciprocal
        # Rounded division is monotone: the largest reciprocal is that of the smallest mass.
        return 1.0 / lightest

    def _too_close_to_singular(self) -> NoReturn:
        diagonal = self.M.diagonal()
        lightest = int(np.argmin(diagonal))
        raise InvalidProblem(
            f"M is too close to singular: its inverse overflows (smallest diagonal entry "
            f"M[{lightest}, {lightest}] = {diagonal.min():.3g})"
        )

    def solve(self, rhs: Any) -> Any:
        """Return ``M^-1 @ rhs``; a sparse ``rhs`` gives a sparse answer."""
        if is_sparse(rhs):
            return self.solve_sparse(rhs)
        reciprocal = self.inverse_diagonal
        if reciprocal is not None:
            rhs = np.asarray(rhs)
            return reciprocal * rhs if rhs.ndim == 1 else reciprocal[:, None] * rhs
        if self.inverse is not None:
            return self.inverse.dot(rhs)
        if self._factor is not None:
            return self._factor.solve(np.asarray(rhs, dtype=float))
        return _cho_solve(self._cholesky, rhs)

    def solve_sparse(self, W: Any) -> Any:
        """``M^-1 W`` of a sparse ``W`` as a CSC array, in O(nnz) for a diagonal M.

        Through M's sparse factor ``SOLVE_BLOCK`` columns at a time, keeping non-zero entries.
        """
        import scipy.sparse

        reciprocal = self.inverse_diagonal
        if reciprocal is not None:
            return scipy.sparse.csc_array(W.multiply(reciprocal[:, None]))
        if not self.sparse:
            return scipy.sparse.csc_array(self.solve(W.toarray()))
        blocks = [
            scipy.sparse.csc_array(self.solve(W[:, k : k + SOLVE_BLOCK].toarray()))
            for k in range(0, W.shape[1], SOLVE_BLOCK)
        ]
        return scipy.sparse.hstack(blocks, format="csc")

    def sparse_delassus(self, W: Any) -> Any:
        """``W.T M^-1 W`` of a sparse ``W``, symmetrized, as a CSC array."""
        G = W.T @ self.solve_sparse(W)
        return ((G + G.T) / 2).tocsc()

    def delassus(self, W: Any) -> Any:
        """The Delassus matrix ``W.T M^-1 W`` of a Jacobian ``W``, read-only when dense.

        Sparse for a sparse ``W``. A dense ``W`` with few non-zero entries beyond `SMALL`
        coordinates (chains and columns: each contact moves two bodies, so the matrix is
        banded) is multiplied as a sparse one, in O(nnz) instead of O(n m^2).
        """
        if is_sparse(W):
            return self.sparse_delassus(W)
        if self.n > SMALL and np.count_nonzero(W) <= SPARSE_SHARE * W.size:
            import scipy.sparse

            G = self.sparse_delassus(scipy.sparse.csc_array(W)).toarray()
        elif self.inverse_diagonal is not None:
            # S.T S with S = M^-1/2 W: symmetric as computed (one product, no symmetrizing).
            scaled = W * np.sqrt(self.inverse_diagonal)[:, None]
            G = scaled.T.dot(scaled)
        else:
            return self.symmetric_product(W)
        G.setflags(write=False)
        return G

    def contact_delassus(self, W: Any, Wt: Any, m: int) -> Any:
        """``W.T M^-1 W`` of a whole Jacobian ``W = [Wn, Wt]`` with m normal columns.

        Raises
        ------
        InvalidProblem
            Where a tangential entry overflows, naming the column of ``Wt`` (the normal block
            is the Delassus matrix a problem checks when built).
        """
        with np.errstate(over="ignore", invalid="ignore"):
            G = self.sparse_delassus(W) if is_sparse(W) else self.symmetric_product(W)
        self.refuse_overflow("Wt", Wt, G.diagonal()[m:])
        return G

    def symmetric_product(self, W: np.ndarray) -> np.ndarray:
        """``W.T M^-1 W`` of a dense ``W`` by one solve, symmetrized, read-only."""
        G = W.T.dot(self.solve(W))
        G = (G + G.T) / 2
        G.setflags(write=False)
        return G

    def compliances(self, W: Any) -> np.ndarray:
        """The diagonal of ``W.T M^-1 W`` without the whole matrix."""
        if is_sparse(W):
            return np.asarray(W.multiply(self.solve_sparse(W)).sum(axis=0)).ravel()
        return np.einsum("ij,ij->j", W, self.solve(W))

    def inverse_mass_on(self, column: np.ndarray) -> float:
        """The largest diagonal entry of ``M^-1`` over the coordinates a column moves.

        `largest_inverse` where M^-1's diagonal is not at hand.
        """
        diagonal = self.inverse_diagonal
        if diagonal is None and self.inverse is not None:
            diagonal = self.inverse.diagonal()
        if diagonal is None or not column.any():
            return self.largest_inverse
        return float(diagonal[column != 0].max())

    def refuse_singular_normals(self, Wn: Any, W: Any, normal: np.ndarray) -> None:
        """Refuse a contact that no motion can push along its normal (a singular configuration).

        Its normal Delassus entry ``normal[j]`` is then rounding noise (for example a pendulum
        hanging straight down onto the floor), and every law's impulse would be meaningless.
        The largest diagonal entry of M^-1, within a factor n of its largest eigenvalue, and
        the columns of the whole Jacobian ``W`` give the scale of a test at rounding level.
        It reads ``W`` over a power of two near its largest entry: Jacobians of 1e200 are judged
        by their geometry. An entry that over- or underflows is no singular one: it is refused
        by name where it does so in the mass unit of `solving_units` too.

        Raises
        ------
        InvalidProblem
            Naming the first singular contact, or the first whose entry is beyond double
            precision in the problem's units and in the solving ones.
        """
        sparse = is_sparse(W)
        for j in np.flatnonzero(~np.isfinite(normal)):
            self._refuse_beyond_range_in_units(Wn, int(j), "overflows")
        largest = float(abs(W).max() if sparse else max(W.max(), -W.min())) if W.size else 0.0
        scale = unit_near(largest)
        scaled = W if scale == 1.0 else W / scale
        # The squared Frobenius norm of W bounds its largest squared column: one product
        # settles the usual case.
        frobenius = scaled.multiply(scaled).sum() if sparse else np.vdot(scaled, scaled)
        if normal.min() / scale / scale > 1e-12 * self.largest_inverse * frobenius:
            return
        squares = scaled.multiply(scaled) if sparse else scaled * scaled
        columns = np.asarray(squares.sum(axis=0)).ravel()
        # Each contact against the inverse masses of the coordinates its normal moves: a light
        # body elsewhere (masses 1e-20 and 1 kg) makes no contact singular.
        geometry = 1e-12 * float(columns.max())
        for j in range(Wn.shape[1]):
            column = self._column(Wn, j)
            inverse_mass = self.inverse_mass_on(column)
            if normal[j] / scale / scale / inverse_mass > geometry:
                continue
            # Read again at the scale of W: an entry that underflowed is not a singular one.
            unit = column / scale
            if not float(unit.dot(self.solve(unit))) / inverse_mass > geometry:
                raise InvalidProblem(
                    f"contacts[{j}]: no motion moves it along its normal (Wn[:, {j}] M^-1 "
                    f"Wn[:, {j}] = {normal[j]:.3g}): a singular configuration"
                )
            if normal[j] < np.finfo(float).tiny:
                self._refuse_beyond_range_in_units(Wn, j, "underflows")

    @staticmethod
    def _column(W: Any, k: int) -> np.ndarray:
        """Column ``k`` of a dense or sparse ``W`` as an array."""
        return W[:, [k]].toarray().ravel() if is_sparse(W) else W[:, k]

    def _refuse_beyond_range_in_units(self, Wn: Any, j: int, what: str) -> None:
        """Refuse contact ``j``'s entry that ``what``, unless the solving mass unit reads it."""
        column = self._column(Wn, j)
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            # A power of two: the product rounds nothing that does not leave the range.
            entry = float(column.dot(self.solve(column * mass_unit(self.M))))
        if not np.finfo(float).tiny <= entry < math.inf:
            raise InvalidProblem(self._beyond_range("Wn", j, column, what))

    def refuse_overflow(self, label: str, W: Any, diagonal: np.ndarray) -> None:
        """Refuse a Jacobian ``W`` (the field ``label``) whose Delassus diagonal overflows.

        ``diagonal`` holds the entries ``W[:, k].T M^-1 W[:, k]``; the first that is not finite
        is named, with the scales of ``W`` and ``M^-1`` that made it.
        """
        if all_finite(diagonal):
            return
        k = int(np.flatnonzero(~np.isfinite(diagonal))[0])
        raise InvalidProblem(self._beyond_range(label, k, self._column(W, k), "overflows"))

    def _beyond_range(self, label: str, k: int, column: np.ndarray, what: str) -> str:
        """Why entry ``k`` of the Delassus matrix of ``label`` cannot be read."""
        return (
            f"{label}[:, {k}]: the Delassus matrix {label}.T M^-1 {label} {what} at [{k}, {k}] "
            f"(largest |{label}[:, {k}]| {np.abs(column).max():.3g}, largest entry of M^-1 on "
            f"it {self.inverse_mass_on(column):.3g}): the effective mass is beyond double "
            "precision"
        )


# A problem whose heaviest mass entry and fastest velocity component lie within this factor of
# 1 (about 1e-9 to 1e9) is solved in its own units; beyond, in units near them.
UNIT_BAND = 2.0**30


def binary_scale(size: float) -> float:
    """The power of two nearest ``size`` (1 for zero or a non-finite size), at most 2^1023.

    Multiplying by it is exact (no digit is rounded) wherever no number under- or overflows.
    Sizes beyond 2^1023.5 (1.7e308) round to 2^1024, which no double holds: they take 2^1023.
    """
    if not math.isfinite(size) or size <= 0.0:
        return 1.0
    return math.ldexp(1.0, min(round(math.log2(size)), sys.float_info.max_exp - 1))


def unit_near(size: float) -> float:
    """1 for a ``size`` within `UNIT_BAND` of 1, else the power of two nearest it."""
    return 1.0 if 1.0 / UNIT_BAND <= size <= UNIT_BAND else binary_scale(size)


def mass_unit(M: Any) -> float:
    """The unit of mass a scale-free law solves in: near the heaviest diagonal entry of M."""
    return unit_near(float(M.diagonal().max()))


def solving_units(M: Any, v: np.ndarray, contacts: Iterable[Any]) -> tuple[float, float, float]:
    """The units of mass, velocity and time a scale-free law solves an impact in.

    ``M`` and ``v`` are the impact's mass matrix and velocity, ``contacts`` its contacts (their
    stiffness and exponent are read only where the time unit is not 1).

    Powers of two (`binary_scale`) near the heaviest diagonal entry of M and the fastest
    component of v, or 1 for a scale within `UNIT_BAND` of 1; when one of them is not 1, the
    time unit brings the stiffest contact's stiffness near 1 (the time of its compression),
    else it is 1 too.

    Raises
    ------
    InvalidProblem
        When the impulse or energy unit these give, ``mass velocity`` or ``mass velocity^2``,
        is not a positive double: an answer could not be scaled back.
    """
    # A positive definite M's diagonal entries are positive.
    mass = float(M.diagonal().max())
    speed = float(np.abs(v).max())
    mass_unit, velocity_unit = (unit_near(size) for size in (mass, speed))
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
    springs = {(contact.stiffness, contact.exponent) for contact in contacts}
    time_log = min(
        (mass_log - math.log2(stiffness) - (exponent - 1.0) * velocity_log) / (exponent + 1.0)
        for stiffness, exponent in springs
    )
    return mass_unit, velocity_unit, math.ldexp(1.0, round(time_log))


def stiffness_in_units(
    stiffness: float, exponent: float, mass: float, length: float, time: float
) -> float:
    """A stiffness K d^exponent (N/m^exponent) in units of ``mass``, ``length`` and ``time``.

    N/m^exponent is kg m^(1 - exponent) s^-2: K is multiplied by
    ``length^(exponent - 1) time^2 / mass``, in base-2 logarithms to stay clear of overflow.
    """
    factor_log = (exponent - 1.0) * math.log2(length) + 2.0 * math.log2(time) - math.log2(mass)
    return 2.0 ** (math.log2(stiffness) + factor_log)


def in_units(problem: Any, mass: float, velocity: float, time: float) -> Any:
    """An `ImpactProblem` in units ``mass``, ``velocity`` and ``time`` of mass, velocity, time.

    Typed loosely: the problem's module imports this one.

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
    contacts, rescaled = [], {}
    for contact in problem.contacts:
        if contact not in rescaled:
            stiffness = stiffness_in_units(contact.stiffness, contact.exponent, mass, length, time)
            rescaled[contact] = dataclasses.replace(contact, stiffness=stiffness)
        contacts.append(rescaled[contact])
    gaps = problem.gaps / length if problem.gaps.any() else None
    try:
        return dataclasses.replace(
            problem, M=problem.M / mass, v=problem.v / velocity, contacts=contacts, gaps=gaps
        )
    except (InvalidProblem, OverflowError) as exc:
        raise InvalidProblem(
            f"in units of {mass:g} kg, {velocity:g} m/s and {time:g} s the problem cannot "
            f"be solved: {exc}"
        ) from None
