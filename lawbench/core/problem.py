"""The impact problem every law consumes: linear algebra at a frozen configuration.

Sign conventions, used everywhere in lawbench: the gap rate of contact j is
``un[j] = Wn[:, j] @ v``; ``un < 0`` approaches and ``un > 0`` separates. Normal impulses
``Pn >= 0`` push the bodies apart, and ``v_plus = v + M^-1 (Wn @ Pn + Wt @ Pt)``.

This module holds the problem's fields and their checks; its checked arrays, the mass matrix's
factor, the Delassus matrices and the units a problem is solved in are `lawbench.core.metric`'s.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import operator
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.geometry import Geometry
from lawbench.core.metric import (
    SMALL,
    KineticMetric,
    all_finite,
    cached,
    checked_gaps,
    checked_matrix,
    checked_range,
    closed_gaps,
    in_units,
    is_diagonal,
    is_sparse,
    kinetic_energy,
    read_only_finite,
    solving_units,
)
from lawbench.core.sparse import checked_sparse_matrix

# The kinds of restitution coefficient and the contact field that overrides ``e`` for each:
# Newton's kinematic, Poisson's kinetic, Stronge's energetic coefficient.
RESTITUTION_FIELDS = {"kinematic": "e_newton", "kinetic": "e_poisson", "energetic": "e_energy"}
# Mindlin's ratio of the normal to the tangential stiffness of a contact between identical
# elastic bodies of Poisson's ratio 0.3, (2 - nu) / (2 (1 - nu)) = 17/14: the contacts'
# tangential_stiffness_ratio when none is given (Jia 2013 rounds it to 1.2).
MINDLIN_RATIO = (2 - 0.3) / (2 * (1 - 0.3))
# A closed contact separates when its gap rate exceeds this fraction of the largest rate.
SEPARATING = 1e-12
# The checked fields of a contact, in the order they are checked: name, lowest and highest
# value (None: unbounded), and whether zero is refused (a stiffness, exponent or ratio).
CONTACT_RANGES = (
    ("e", 0.0, 1.0, False),
    ("e_newton", 0.0, 1.0, False),
    ("e_poisson", 0.0, 1.0, False),
    ("e_energy", 0.0, 1.0, False),
    ("e_t", -1.0, 1.0, False),
    ("mu", 0.0, None, False),
    ("damping", 0.0, None, False),
    ("stiffness", 0.0, None, True),
    ("exponent", 0.0, None, True),
    ("tangential_stiffness_ratio", 0.0, None, True),
)
# Up to this many distinct contacts are checked one by one; more, as one table of numbers.
CHECKED_ONE_BY_ONE = 8


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
        """Raise `InvalidProblem` naming ``label.field`` for the first bad field."""
        for name, low, high, positive in CONTACT_RANGES:
            value = getattr(self, name)
            if value is None:
                if name in _UNSET_ALLOWED:
                    continue
                raise InvalidProblem(f"{label}.{name} = None: must be a number")
            checked_range(f"{label}.{name}", value, low, high)
            if positive and value == 0.0:
                raise InvalidProblem(f"{label}.{name} = 0: must be > 0")

    def restitution(self, kind: str) -> float:
        """Return the coefficient of ``kind`` ('kinematic', 'kinetic' or 'energetic')."""
        if kind not in RESTITUTION_FIELDS:
            raise ValueError(f"unknown restitution kind {kind!r}")
        override = getattr(self, RESTITUTION_FIELDS[kind])
        return self.e if override is None else override


CONTACT_FIELDS = frozenset(f.name for f in dataclasses.fields(Contact))
# The fields that may be None (unset): the overrides of e and Jia's ratio.
_UNSET_ALLOWED = frozenset(f.name for f in dataclasses.fields(Contact) if f.default is None)
# One coefficient for every contact, and what a coefficient may be.
_SCALAR = (int, float, str)
_NUMBER = (int, float, np.number)
_CHECKED_FIELDS = operator.attrgetter(*(name for name, *_ in CONTACT_RANGES))
_LOWS = np.array([low for _, low, _, _ in CONTACT_RANGES])
_HIGHS = np.array([math.inf if high is None else high for _, _, high, _ in CONTACT_RANGES])
_POSITIVE = np.array([positive for *_, positive in CONTACT_RANGES])
_MAY_BE_UNSET = np.array([name in _UNSET_ALLOWED for name, *_ in CONTACT_RANGES])


def _check_contacts(contacts: tuple[Contact, ...]) -> Contact | None:
    """Check every distinct contact object once; return the one object when all are one.

    Raises `InvalidProblem` naming ``contacts[j].field`` (j the first index of the object).
    """
    # Read from the last contact to the first, each object keeps the first index it is at.
    first = dict(zip(map(id, reversed(contacts)), range(len(contacts) - 1, -1, -1), strict=True))
    indices = sorted(first.values())
    for j in indices:
        if not isinstance(contacts[j], Contact):
            raise InvalidProblem(f"contacts[{j}] is {type(contacts[j]).__name__}, not Contact")
    if len(indices) > CHECKED_ONE_BY_ONE:
        indices = _rows_out_of_range([contacts[j] for j in indices], indices)
    for j in indices:
        if not _in_range(contacts[j]):
            contacts[j].validate(f"contacts[{j}]")
    return contacts[0] if len(first) == 1 else None


@functools.lru_cache(maxsize=256)
def _in_range(contact: Contact) -> bool:
    """Whether every field of ``contact`` is in its range, decided once per distinct contact.

    A contact is immutable, so the problems that share its coefficients share the verdict; the
    one out of range is checked again under its label for the message.
    """
    try:
        contact.validate("contact")
    except InvalidProblem:
        return False
    return True


def _rows_out_of_range(contacts: list[Contact], indices: list[int]) -> list[int]:
    """The indices of the contacts whose fields, read as one table, leave their ranges.

    A field that is not a number leaves every index to the checks one by one.
    """
    table = np.array(list(map(_CHECKED_FIELDS, contacts)), dtype=object)
    missing = np.equal(table, None)
    try:
        values = np.where(missing, 1.0, table).astype(float)
    except (TypeError, ValueError, OverflowError):
        return indices
    inside = (
        np.isfinite(values)
        & (values >= _LOWS)
        & (values <= _HIGHS)
        & ~(_POSITIVE & (values == 0.0))
    )
    bad = ~np.where(missing, _MAY_BE_UNSET, inside).all(axis=1)
    return [indices[row] for row in np.flatnonzero(bad)]


def forget_shared_contacts() -> None:
    """Build shared contacts anew: a law forced a write into one it was given (`Law._answer`)."""
    _shared_contact.cache_clear()
    _in_range.cache_clear()


@functools.lru_cache(maxsize=256, typed=True)
def _shared_contact(**coefficients: Any) -> Contact:
    """The one contact of coefficients every contact shares (typed: 1 and 1.0 are two)."""
    return Contact(**coefficients)


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
    geometry : Geometry or None
        What the scene looks like, for the engine laws that build it (`lawbench.core.geometry`);
        None when the scene declares none. The other laws and the checks never read it.

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
    momentum : array (n,)
        Generalized momentum before the impact, ``M @ v``.
    T_minus : float
        Kinetic energy before the impact, ``v @ M @ v / 2`` (finite: checked).
    metric : KineticMetric
        M checked symmetric positive definite, with what applies ``M^-1``
        (`lawbench.core.metric`).

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
    geometry: Geometry | None = field(default=None, repr=False)
    # Found while the fields are checked, and stored then by `__init__`.
    n: int = field(init=False, repr=False)
    m: int = field(init=False, repr=False)
    d: int = field(init=False, repr=False)
    sparse: bool = field(init=False, repr=False)
    momentum: np.ndarray = field(init=False, repr=False)
    T_minus: float = field(init=False, repr=False)
    metric: KineticMetric = field(init=False, repr=False)

    def __init__(
        self,
        M: Any,
        Wn: Any,
        v: Any,
        contacts: Sequence[Contact],
        Wt: Any = None,
        bodies: Mapping[str, Sequence[int]] | None = None,
        gaps: Any = None,
        geometry: Geometry | None = None,
    ) -> None:
        # Every field is checked here and the problem keeps its own read-only copies, written
        # once into the instance (the dataclass is frozen).
        try:
            v = np.array(v, dtype=float, ndmin=1)
        except (TypeError, ValueError, OverflowError) as exc:
            raise InvalidProblem(f"v: not an array of numbers ({exc})") from None
        n = v.shape[0] if v.ndim == 1 else -1
        if n < 1:
            raise InvalidProblem(f"v has shape {v.shape}, expected (n,) with n >= 1")
        contacts = tuple(contacts)
        m = len(contacts)
        if m < 1:
            raise InvalidProblem("contacts is empty: an impact needs at least one contact")
        one_contact = _check_contacts(contacts)
        sparse = n > SMALL and any(is_sparse(a) for a in (M, Wn, Wt))
        matrix = checked_sparse_matrix if sparse else checked_matrix
        state = self.__dict__
        state.update(
            n=n,
            m=m,
            sparse=sparse,
            v=read_only_finite("v", v),
            M=matrix("M", M, (n, n)),
            Wn=matrix("Wn", Wn, (n, m)),
            contacts=contacts,
            Wt=None,
            d=0,
            _restitutions={},
            _one_contact=one_contact,
        )
        if Wt is None:
            state["frictional"] = False
        else:
            d = np.shape(Wt)[1] // m if np.ndim(Wt) == 2 else 0
            if d not in (1, 2):
                raise InvalidProblem(f"Wt has shape {np.shape(Wt)}, expected ({n}, {m}*d)")
            state.update(Wt=matrix("Wt", Wt, (n, m * d)), d=d)
        if gaps is None:
            state.update(gaps=closed_gaps(m), closed_count=m)
        else:
            state["gaps"] = checked_gaps(gaps, m)
        state["bodies"] = _bodies(bodies, n)
        if geometry is not None and not isinstance(geometry, Geometry):
            raise InvalidProblem(f"geometry is {type(geometry).__name__}, not Geometry")
        state["geometry"] = geometry
        state["metric"] = KineticMetric(self.M)
        # Where M^-1 or v is extreme, the Delassus matrix, the energy and the gap rates
        # overflow: each is refused by name, not with a warning.
        with np.errstate(over="ignore", invalid="ignore"):
            self._check_normals()
            momentum = self.M.dot(self.v)
            T_minus = float(self.v.dot(momentum)) / 2.0
            rates = {"M v": momentum, "v M v / 2": T_minus, "Wn.T v": self.un, "Wt.T v": self.ut}
        for name, value in rates.items():
            if not all_finite(np.asarray(value)):
                raise InvalidProblem(f"{name} is beyond double precision (it overflows)")
        momentum.setflags(write=False)
        state.update(momentum=momentum, T_minus=T_minus)

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
            shape = np.shape(Wn)
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
            # One set of coefficients: one (immutable) contact serves, checked once.
            contacts = (_shared_contact(**shared),) * m
        return cls(M, Wn, v, contacts, Wt, bodies, gaps)

    def _check_normals(self) -> None:
        """Refuse a contact that no motion can push along its normal (`KineticMetric`)."""
        if self.n <= SMALL or self.sparse:
            # The Delassus matrix costs little more than its diagonal here (a small or a sparse
            # one), and every rigid law needs it: its diagonal serves (where M^-1 overflows,
            # infinite entries, refused there).
            normal = self.delassus.diagonal()
        else:
            normal = self.metric.compliances(self.Wn)
        self.metric.refuse_singular_normals(self.Wn, self.W, normal)

    @cached
    def frictional(self) -> bool:
        """Whether some contact has a tangential Jacobian and a positive mu."""
        return self.Wt is not None and bool((self.mu > 0).any())

    @cached
    def closed(self) -> np.ndarray:
        """Boolean mask of the contacts with zero gap, the ones an impact involves."""
        closed = self.gaps <= 0.0
        closed.setflags(write=False)
        return closed

    @cached
    def closed_count(self) -> int:
        """Number of closed contacts."""
        return self.m - int(np.count_nonzero(self.gaps))

    @cached
    def separating(self) -> tuple[int, ...]:
        """Closed contacts whose gap rate is positive before the impact (they separate)."""
        if not self.un.max() > 0.0:
            return ()
        scale = float(np.abs(self.un).max())
        separating = self.closed & (self.un > SEPARATING * scale)
        return tuple(int(j) for j in np.flatnonzero(separating))

    def kinetic_energy(self, v: np.ndarray) -> float:
        """Kinetic energy ``v @ M @ v / 2`` of a velocity ``v`` (inf when it overflows)."""
        return kinetic_energy(self.M, v)

    def dense(self) -> ImpactProblem:
        """The same problem with numpy arrays in place of sparse ones (itself when dense)."""
        if not self.sparse:
            return self
        Wt = None if self.Wt is None else self.Wt.toarray()
        return dataclasses.replace(self, M=self.M.toarray(), Wn=self.Wn.toarray(), Wt=Wt)

    def solve_mass(self, rhs: Any) -> Any:
        """Return ``M^-1 @ rhs``; a sparse ``rhs`` gives a sparse answer.

        Through the reciprocal diagonal of a diagonal M, the inverse of a small one, or M's
        Cholesky or sparse LU factor (`lawbench.core.metric.KineticMetric`).
        """
        return self.metric.solve(rhs)

    @cached
    def delassus(self) -> Any:
        """Normal Delassus matrix ``G = Wn.T M^-1 Wn`` (m, m): gap-rate change per impulse.

        Sparse for a sparse problem.
        """
        return self.metric.delassus(self.Wn)

    @cached
    def decoupled(self) -> bool:
        """Whether the Delassus matrix is diagonal: no contact's impulse moves another's gap."""
        return is_diagonal(self.delassus)

    @cached
    def un(self) -> np.ndarray:
        """Pre-impact normal gap rates ``Wn.T @ v``."""
        un = self.Wn.T.dot(self.v)
        un.setflags(write=False)
        return un

    @cached
    def W(self) -> Any:
        """Contact Jacobian ``[Wn, Wt]`` (n, m + m*d): normal columns, then tangential."""
        if self.Wt is None:
            return self.Wn
        if self.sparse:
            import scipy.sparse

            return scipy.sparse.hstack([self.Wn, self.Wt], format="csc")
        return np.hstack([self.Wn, self.Wt])

    @cached
    def contact_delassus(self) -> Any:
        """Delassus matrix of normal and tangential directions ``W.T M^-1 W``.

        Blocks: ``[[Gnn, Gnt], [Gtn, Gtt]]`` with the m normal rows first, then the m*d
        tangential rows (contact j's tangential rows are ``m + j*d ... m + j*d + d - 1``).
        Sparse for a sparse problem; an entry of ``Wt`` that overflows is refused by name.
        """
        return self.metric.contact_delassus(self.W, self.Wt, self.m)

    @cached
    def ut(self) -> np.ndarray:
        """Pre-impact tangential slip velocities ``Wt.T @ v`` (m*d,); empty without Wt."""
        return np.zeros(0) if self.Wt is None else self.Wt.T @ self.v

    @cached
    def mu(self) -> np.ndarray:
        """Friction coefficients, one per contact."""
        return self._per_contact(operator.attrgetter("mu"))

    def restitution(self, kind: str) -> np.ndarray:
        """Per-contact restitution coefficients of ``kind`` (a key of `RESTITUTION_FIELDS`)."""
        coefficients = self._restitutions.get(kind)
        if coefficients is None:
            coefficients = self._per_contact(operator.methodcaller("restitution", kind))
            self._restitutions[kind] = coefficients
        return coefficients

    def _per_contact(self, read: Any) -> np.ndarray:
        """A read-only array of ``read(contact)`` over the contacts, read once when one serves."""
        one = self._one_contact
        if one is not None:
            values = np.full(self.m, float(read(one)))
        else:
            values = np.array([read(c) for c in self.contacts], dtype=float)
        values.setflags(write=False)
        return values

    @cached
    def units(self) -> tuple[float, float, float]:
        """The units of mass, velocity and time a scale-free law solves this problem in.

        Powers of two near the heaviest diagonal entry of M and the fastest component of v
        (`lawbench.core.metric.solving_units`): rescaling by them rounds nothing, and masses of
        1e-308 kg or speeds of 1e-300 m/s come near 1, where the laws' linear algebra and
        integrators neither under- nor overflow.

        Raises
        ------
        InvalidProblem
            When the impulse or energy unit these give, ``mass velocity`` or
            ``mass velocity^2``, is not a positive double: an answer could not be scaled back.
        """
        return solving_units(self.M, self.v, self.contacts)

    def in_units(self, mass: float, velocity: float, time: float) -> ImpactProblem:
        """The problem with masses, velocities and times in units ``mass``, ``velocity``, ``time``.

        See `lawbench.core.metric.in_units`.
        """
        return in_units(self, mass, velocity, time)

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


def _bodies(bodies: Mapping[str, Sequence[int]] | None, n: int) -> dict[str, tuple[int, ...]]:
    """Body names and the indices of their coordinates, checked to lie in [0, n)."""
    if bodies is None:
        return {}
    if not isinstance(bodies, Mapping):
        raise TypeError(
            f"bodies must be a mapping of names to indices, not {type(bodies).__name__}"
        )
    checked: dict[str, tuple[int, ...]] = {}
    for name, indices in bodies.items():
        try:
            checked[str(name)] = tuple(map(int, indices))
        except (TypeError, ValueError):
            raise InvalidProblem(f"bodies[{str(name)!r}] = {indices!r}: not indices") from None
    every = [i for idx in checked.values() for i in idx]
    if every and (min(every) < 0 or max(every) >= n):
        name, idx = next((k, i) for k, i in checked.items() if i and (min(i) < 0 or max(i) >= n))
        raise InvalidProblem(f"bodies[{name!r}] = {idx}: indices must lie in [0, {n})")
    return checked
