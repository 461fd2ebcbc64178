"""FCLIB files (the frictional-contact problem library of Siconos and others) as impact problems.

FCLIB stores 3D (or 2D) frictional contact problems in HDF5 (Acary, Brémond, Koziara, Pérignon,
"FCLIB: a collection of discrete 3D frictional contact problems", 2014; the library's
``fclib.h``). Per contact the local coordinates are (normal, tangent 1[, tangent 2]); ``mu``
has one entry per contact; ``spacedim`` is 3 (or 2).

- Local form ``/fclib_local``: a positive semidefinite Delassus matrix ``W`` and a vector
  ``q``; find ``u = W r + q`` and ``r`` in the Coulomb cones with De Saxce's complementarity
  ``C*_mu ∋ u + (mu |u_T|, 0, 0) ⊥ r ∈ C_mu``.
- Global form ``/fclib_global``: ``M v = H r + f``, ``u = H.T v + w`` and the same cone
  complementarity (``G``, ``b``: equality constraints, not read here).

The global form is exactly an impact with ``e = 0`` resolved by Moreau's law with Coulomb
cones: `read_fclib` maps it to an `ImpactProblem` with ``M``, ``W = H`` (normal columns
``Wn``, tangential ``Wt``) and the pre-impact velocity ``v- = M^-1 f``. A global form that is
no impact, its ``M`` not symmetric (LMGC90 writes such iteration matrices) or with an offset
``w``, is read in contact space as Siconos reformulates it, ``W = H.T M^-1 H`` and
``q = H.T M^-1 f + w``, the reason in the problem's name. The local form has no generalized
coordinates: it is read as the `ContactProblem` it is, ``W`` and ``q`` as given (an asymmetric
``W`` is kept, and its asymmetry reported by the solve; ``q`` need not lie in the range of
``W``). The file is read once (`read_fclib_file`): its problem comes with the facts of the
reading (`lawbench.files.facts.FileFacts`), among them the file's own ``W`` and ``q``, on which
an answer of a global problem has its FC3D error, the measure of the field's comparisons; a
contact-space solve reports it itself.

Matrices are read in any of FCLIB's sparse layouts (``nz = -1`` compressed columns, ``-2``
compressed rows, ``>= 0`` triplets: row ``i[k]``, column ``p[k]``), their index arrays checked
against the matrix's shape before scipy sees them, and written as compressed columns. HDF5
needs h5py.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from lawbench.core.contact import ContactProblem
from lawbench.core.errors import InvalidProblem, LawbenchError, LossyExport, NotApplicable
from lawbench.core.metric import as_array
from lawbench.core.problem import ImpactProblem
from lawbench.files.facts import LAYOUTS, ContactSpace, FileFacts, ProblemFile
from lawbench.files.hdf5 import require_h5py
from lawbench.files.paths import MAX_BYTES, input_file, output_file, replaced

FORMS = ("local", "global")
# The largest matrix of a global form held dense (entries, 8 MB of doubles); larger ones are
# held sparse, as a local form's W always is.
DENSE_ENTRIES = 1_000_000
# The relative asymmetry of M beyond which a global form is no impact problem: the impact
# problem's own bound on its mass matrix.
MASS_SYMMETRY = 1e-12
# FCLIB files are HDF5: an extension that names another encoding would mislead every reader.
SUFFIXES = (".h5", ".hdf5")
# FCLIB's forms that are not frictional impacts, by their HDF5 group: recognised, and refused.
OTHER_FORMS = {"fclib_global_rolling": "the global problem with rolling friction"}
# The most entries one dataset may hold to be read: the doubles of the largest file read,
# uncompressed. A compressed or never written dataset can claim far more than its file holds.
MAX_ENTRIES = MAX_BYTES // 8


def fclib_form(path: str | Path) -> str | None:
    """The FCLIB form ``path`` holds ('local', 'global' or another of FCLIB's), or None."""
    try:
        with require_h5py().File(path, "r") as handle:
            return form_of(handle)
    except (OSError, RuntimeError, KeyError):  # not HDF5, or a damaged one
        return None


def form_of(handle: Any) -> str | None:
    """The FCLIB form an open HDF5 file holds ('local', 'global' or another), or None."""
    for group in [f"fclib_{form}" for form in FORMS] + list(OTHER_FORMS):
        if group in handle:
            return group.removeprefix("fclib_")
    return None


def _read_matrix(
    group: Any, where: str, shape: tuple[int, int], why: str
) -> tuple[scipy.sparse.csr_matrix, str]:
    """A sparse matrix in any of FCLIB's layouts, and that layout (one of `LAYOUTS`).

    The shape the matrix claims must be ``shape``, which the problem's vectors fix (``why``
    says how), before anything of its size is allocated: a file may claim a billion rows it
    holds no entry of. Index arrays are checked against the shape before scipy sees them.

    Triplets (``nz >= 0``) hold the row of entry k in ``i[k]`` and its column in ``p[k]``:
    CSparse's triplets, which Siconos and LMGC90 write (the field comments of ``fclib.h`` name
    them the other way round; in the files of theirs read here ``i`` stays within the rows and
    ``p`` within the columns). Repeated entries are summed.
    """
    group = _group(group, where)
    m, n, nz = (_number(group, key, where) for key in ("m", "n", "nz"))
    if (m, n) != shape:
        raise InvalidProblem(f"{where} is {m} x {n} where {why} need {shape[0]} x {shape[1]}")
    p, i, x = (_dataset(group, key, where) for key in ("p", "i", "x"))
    for key, index in (("p", p), ("i", i)):
        if not np.issubdtype(index.dtype, np.integer):
            raise InvalidProblem(f"{where}/{key} holds {index.dtype}, not integers")
    if not (np.issubdtype(x.dtype, np.floating) or np.issubdtype(x.dtype, np.integer)):
        raise InvalidProblem(f"{where}/x holds {x.dtype}, not numbers")
    if nz >= 0:
        if min(p.size, i.size, x.size) < nz:
            raise InvalidProblem(
                f"{where}: nz = {nz} triplets, but p, i and x hold {p.size}, {i.size} and "
                f"{x.size} entries"
            )
        rows, columns = i[:nz], p[:nz]
        _within(rows, m, f"{where}/i (rows)")
        _within(columns, n, f"{where}/p (columns)")
        return scipy.sparse.coo_matrix((x[:nz], (rows, columns)), shape=(m, n)).tocsr(), LAYOUTS[0]
    if nz not in (-1, -2):
        raise InvalidProblem(f"{where}/nz = {nz}: not an FCLIB sparse layout (-2, -1 or >= 0)")
    major, minor, layout = (n, m, "columns") if nz == -1 else (m, n, "rows")
    if p.size != major + 1:
        raise InvalidProblem(
            f"{where}/p has {p.size} entries; compressed {layout} of a {m} x {n} matrix need "
            f"{major + 1}"
        )
    if p[0] != 0 or (np.diff(p) < 0).any() or p[-1] > min(i.size, x.size):
        raise InvalidProblem(
            f"{where}/p must start at 0, never decrease and end within i and x "
            f"({i.size} and {x.size} entries); it runs from {p[0]} to {p[-1]}"
        )
    _within(i[: p[-1]], minor, f"{where}/i")
    arrays = (x[: p[-1]], i[: p[-1]], p)
    matrix = scipy.sparse.csc_matrix if nz == -1 else scipy.sparse.csr_matrix
    return scipy.sparse.csr_matrix(matrix(arrays, shape=(m, n))), LAYOUTS[-nz]


def _group(node: Any, where: str) -> Any:
    """``node`` once it is known to be an HDF5 group (``where`` names it)."""
    if not isinstance(node, require_h5py().Group):
        raise InvalidProblem(f"{where} is a dataset, not a group")
    return node


def _dataset(group: Any, key: str, where: str) -> np.ndarray:
    """The numbers of dataset ``group[key]``, flat, read once known to be a bounded dataset.

    Raises
    ------
    InvalidProblem
        Naming ``where/key``: missing, a group, more than `MAX_ENTRIES` entries, or entries
        that are not real numbers (text, compound records, an empty dataspace).
    """
    if key not in group:
        raise InvalidProblem(f"{where}/{key} is missing")
    node = group[key]
    if not isinstance(node, require_h5py().Dataset):
        raise InvalidProblem(f"{where}/{key} is a group, not a dataset")
    if (node.size or 0) > MAX_ENTRIES:
        raise InvalidProblem(
            f"{where}/{key} claims {node.size} entries, more than the {MAX_ENTRIES} read at most"
        )
    data = np.asarray(node[()]).ravel()
    if data.dtype.kind not in "iuf":
        raise InvalidProblem(f"{where}/{key} holds {data.dtype}, not numbers")
    return data


def _number(group: Any, key: str, where: str) -> int:
    """The one integer dataset ``group[key]`` holds (a size, a count, a dimension)."""
    data = _dataset(group, key, where)
    if data.size != 1:
        raise InvalidProblem(f"{where}/{key} holds {data.size} entries, not one integer")
    value = data[0]
    if data.dtype.kind == "f" and not (np.isfinite(value) and value == int(value)):
        raise InvalidProblem(f"{where}/{key} = {value!r}: not an integer")
    return int(value)


def _within(index: np.ndarray, bound: int, where: str) -> None:
    """Refuse an index array with an entry outside ``0 .. bound - 1``."""
    outside = (index < 0) | (index >= bound)
    if outside.any():
        k = int(np.flatnonzero(outside)[0])
        raise InvalidProblem(f"{where}[{k}] = {int(index[k])} lies outside 0..{bound - 1}")


def _write_matrix(group: Any, matrix: np.ndarray) -> None:
    """Write ``matrix`` in triplets (``nz`` entries, rows in ``i``, columns in ``p``).

    Siconos' global reader copies ``nz`` indices whatever the storage, so a compressed matrix
    (``nz = -1``) crashes it; triplets are read by every reader of the format.
    """
    coo = scipy.sparse.coo_matrix(matrix)
    for key, value in (
        ("nzmax", coo.nnz),
        ("m", coo.shape[0]),
        ("n", coo.shape[1]),
        ("nz", coo.nnz),
    ):
        group.create_dataset(key, data=np.array([value], dtype=np.int32))
    group.create_dataset("p", data=coo.col.astype(np.int32))
    group.create_dataset("i", data=coo.row.astype(np.int32))
    group.create_dataset("x", data=coo.data.astype(float))


def _vector(group: Any, key: str, where: str, size: int | None = None) -> np.ndarray:
    """The dataset ``group[key]`` as floats; of ``size`` entries when given."""
    data = _dataset(group, key, where).astype(float)
    if size is not None and data.size != size:
        raise InvalidProblem(
            f"{where}/{key} holds {data.size} entries; the problem's other fields need {size}"
        )
    return data


def _split(W: Any, dim: int, mu: np.ndarray) -> dict[str, Any]:
    """Normal and tangential columns from FCLIB's per-contact (n, t1[, t2]) order.

    ``W`` has ``dim`` columns per entry of ``mu``, as `read_open` checked.
    """
    first = np.arange(mu.size)[:, None] * dim
    return {"Wn": W[:, first[:, 0]], "Wt": W[:, (first + np.arange(1, dim)).ravel()]}


def _local_order(problem: ImpactProblem) -> np.ndarray:
    """The columns of ``[Wn, Wt]`` in FCLIB's per-contact order (n, t1, t2)."""
    m, d = problem.m, problem.d
    return np.array(
        [column for j in range(m) for column in (j, *(m + j * d + k for k in range(d)))]
    )


def read_fclib(path: str | Path) -> ImpactProblem | ContactProblem:
    """The problem of an FCLIB file (`read_fclib_file`), without what its reading learned."""
    return read_fclib_file(path).problem


def read_fclib_file(path: str | Path) -> ProblemFile:
    """Read an FCLIB file: the global form as an impact, the local form as given.

    The global form is an `ImpactProblem` with ``e = 0`` (or, when its ``M`` is not symmetric
    or it has an offset ``w``, the `ContactProblem` ``W = H.T M^-1 H``, ``q = H.T M^-1 f + w``);
    the local form a `ContactProblem` with ``W`` and ``q`` as the file holds them. The facts
    name the form, each matrix's layout, the reformulation applied, and give the file's own
    ``W`` and ``q`` (for the FC3D error of an answer, W's asymmetry and rank).

    Raises
    ------
    InvalidProblem
        For a file that is not FCLIB, a missing field, a form this mapping cannot represent
        (equality constraints, a mixed local problem), a singular ``M``, or a bad field of the
        resulting problem; the message names the field.
    NotApplicable
        For FCLIB's rolling-friction form: no impact law here has rolling resistance.
    """
    where = str(input_file(path, "FCLIB file"))
    try:
        handle = require_h5py().File(path, "r")
    except OSError as exc:
        raise InvalidProblem(f"{where}: cannot be read as HDF5 ({exc})") from None
    with handle:
        read = read_open(handle, where)
    return read.interpret()


@dataclass(frozen=True)
class FclibRead:
    """The arrays of an FCLIB file's problem, read; `interpret` makes its problem and facts."""

    form: str
    where: str
    dim: int
    mu: np.ndarray
    arrays: dict[str, Any]
    storage: tuple[tuple[str, str], ...]

    def interpret(self) -> ProblemFile:
        """The problem the arrays define, with the facts of the file (`read_fclib_file`)."""
        where, dim, mu = self.where, self.dim, self.mu
        if self.form == "local":
            W, q = self.arrays["W"], self.arrays["q"]
            space = ContactSpace(W, q, mu, dim)
            return ProblemFile(
                ContactProblem(W, q, mu, dim, name=where),
                FileFacts("local", self.storage, contact_space=lambda: space),
            )
        M, H, f, w = (self.arrays[key] for key in ("M", "H", "f", "w"))

        @functools.cache
        def contact_space() -> ContactSpace:
            # Siconos' reformulation of the global form: W = H.T M^-1 H, q = H.T M^-1 f + w.
            W = H.T @ _solve(M, as_array(H), where)
            return ContactSpace(W, H.T @ _solve(M, f, where) + w, mu, dim)

        reason = _no_impact(M, w)
        facts = FileFacts("global", self.storage, reason, contact_space)
        if reason:
            space = contact_space()
            name = f"{where} (in contact space: {reason})"
            return ProblemFile(ContactProblem(space.W, space.q, mu, dim, name=name), facts)
        try:
            problem = ImpactProblem.from_arrays(
                M, v=_solve(M, f, where), **_split(H, dim, mu), e=0.0, mu=mu
            )
        except InvalidProblem as exc:
            raise InvalidProblem(f"{where}: {exc}") from None
        return ProblemFile(problem, facts)


def read_open(handle: Any, where: str) -> FclibRead:
    """Read the FCLIB problem of the open HDF5 file ``handle`` (named ``where`` in messages).

    Raises
    ------
    InvalidProblem, NotApplicable
        As `read_fclib_file`, for what the file holds (its interpretation raises the rest).
    """
    try:
        root, form, where, dim = _root(handle, where)
        at = f"{where}/vectors"
        vectors = _group(root["vectors"], at)
        mu = _vector(vectors, "mu", at)
        size = mu.size * dim  # the contacts' local coordinates
        local = f"{mu.size} contacts of dimension {dim}"
        if form == "local":
            if "V" in root or "R" in root:
                raise InvalidProblem(f"{where}/V, R: mixed problems are not an impact problem")
            q = _vector(vectors, "q", at, size)
            W, layout = _read_matrix(_member(root, "W", where), f"{where}/W", (size, size), local)
            return FclibRead(form, where, dim, mu, {"W": W, "q": q}, (("W", layout),))
        if "G" in root:
            raise InvalidProblem(f"{where}/G: equality constraints are not an impact problem")
        f = _vector(vectors, "f", at)
        if not f.size:
            raise InvalidProblem(f"{at}/f holds no entry: a global form needs coordinates")
        n, coordinates = f.size, f"the {f.size} entries of f"
        M, of_M = _read_matrix(_member(root, "M", where), f"{where}/M", (n, n), coordinates)
        H, of_H = _read_matrix(
            _member(root, "H", where), f"{where}/H", (n, size), f"{coordinates} and {local}"
        )
        arrays = {"M": _held(M), "H": _held(H), "f": f, "w": _vector(vectors, "w", at, size)}
        return FclibRead(form, where, dim, mu, arrays, (("M", of_M), ("H", of_H)))
    except LawbenchError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError) as exc:
        # h5py's errors for a damaged structure, met wherever the file is read.
        raise InvalidProblem(f"{where}: a damaged HDF5 file ({exc})") from None


def _root(handle: Any, where: str) -> tuple[Any, str, str, int]:
    """The open file's problem group, its form, its name for messages and its ``spacedim``."""
    if "fclib_global" in handle:
        form = "global"
    elif "fclib_local" in handle:
        form = "local"
    else:
        for group, name in OTHER_FORMS.items():
            if group in handle:
                raise NotApplicable(
                    f"{where}: /{group} is FCLIB's {name}; the impact laws here have "
                    "Coulomb friction only (no rolling resistance)"
                )
        raise InvalidProblem(f"{where}: neither /fclib_local nor /fclib_global")
    where = f"{where}:/fclib_{form}"
    root = _group(handle[f"fclib_{form}"], where)
    dim = _number(root, "spacedim", where) if "spacedim" in root else 3
    if dim not in (2, 3):
        raise InvalidProblem(f"{where}/spacedim = {dim}: must be 2 or 3")
    _member(root, "vectors", where)
    return root, form, where, dim


def _member(group: Any, key: str, where: str) -> Any:
    """``group[key]``, or an `InvalidProblem` naming it when it is missing."""
    if key not in group:
        raise InvalidProblem(f"{where}/{key} is missing")
    return group[key]


def _no_impact(M: Any, w: np.ndarray) -> str:
    """Why a global form is no impact problem (its M not symmetric, an offset w), or ''."""
    asymmetry = abs(M - M.T).max()
    if asymmetry > MASS_SYMMETRY * abs(M).max():
        return f"M is not symmetric, largest |M - M.T| = {asymmetry:.3g}"
    if np.any(w):
        return "w, a constant local velocity, has no impact counterpart"
    return ""


def _solve(M: Any, rhs: np.ndarray, where: str) -> np.ndarray:
    """``M^-1 rhs`` for a dense or sparse ``M``."""
    try:
        if scipy.sparse.issparse(M):
            return scipy.sparse.linalg.splu(scipy.sparse.csc_matrix(M)).solve(rhs)
        return np.linalg.solve(M, rhs)
    except (np.linalg.LinAlgError, RuntimeError):  # RuntimeError: splu's singular pivot
        raise InvalidProblem(f"{where}/M is singular") from None


def _held(matrix: scipy.sparse.csr_matrix) -> Any:
    """A global form's matrix as its impact problem holds it.

    Dense up to `DENSE_ENTRIES` entries, sparse (compressed columns) beyond.
    """
    m, n = matrix.shape
    return matrix.toarray() if m * n <= DENSE_ENTRIES else scipy.sparse.csc_array(matrix)


def write_fclib(problem: ImpactProblem, path: str | Path, form: str = "local") -> Path:
    """Write ``problem`` as an FCLIB file: its contact Delassus matrix (local) or M, H (global).

    The restitution coefficients are not part of FCLIB (its problems are impacts with
    ``e = 0``): a problem with a nonzero one is written as its plastic impact, with a
    `LossyExport` warning naming the contacts. A frictionless problem is written with spatial
    dimension 2 and ``mu = 0``.

    Raises
    ------
    InvalidProblem
        For an unknown form, a path whose extension is not an HDF5 one, or a file that cannot
        be written (`lawbench.files.paths.replaced`: the file is written whole or not at all).
    SolverFailure
        For a disk that runs out of room; the file is left as it was.
    """
    if form not in FORMS:
        raise InvalidProblem(f"FCLIB form {form!r}: must be one of {', '.join(FORMS)}")
    path = output_file(path, "FCLIB file")
    if path.suffix.lower() not in SUFFIXES:
        raise InvalidProblem(
            f"FCLIB file {path}: FCLIB is HDF5, so its extension is {' or '.join(SUFFIXES)}"
        )
    restituted = [j for j, c in enumerate(problem.contacts) if _restitutes(c)]
    if restituted:
        shown = ", ".join(map(str, restituted[:10])) + (", ..." if len(restituted) > 10 else "")
        warnings.warn(
            f"FCLIB holds no restitution: {path} holds the plastic impact (e = 0); the "
            f"restitution coefficients of contacts [{shown}] are left out",
            LossyExport,
            stacklevel=2,
        )
    if problem.Wt is None:
        # Each contact's normal column, then a zero tangent column.
        blank = scipy.sparse.csc_array((problem.n, problem.m))
        interleaved = np.ravel(
            np.column_stack([np.arange(problem.m), problem.m + np.arange(problem.m)])
        )
        W = scipy.sparse.hstack([scipy.sparse.csc_array(problem.Wn), blank]).tocsc()[:, interleaved]
        dim = 2
    else:
        W, dim = problem.W[:, _local_order(problem)], problem.d + 1
    with replaced(path, "FCLIB file") as temporary, require_h5py().File(temporary, "w") as handle:
        root = handle.create_group(f"fclib_{form}")
        root.create_dataset("spacedim", data=np.array([dim], dtype=np.int32))
        vectors = root.create_group("vectors")
        vectors.create_dataset("mu", data=problem.mu)
        if form == "local":
            _write_matrix(root.create_group("W"), W.T @ problem.solve_mass(W))
            vectors.create_dataset("q", data=W.T @ problem.v)
        else:
            _write_matrix(root.create_group("M"), problem.M)
            _write_matrix(root.create_group("H"), W)
            vectors.create_dataset("f", data=problem.M @ problem.v)
            vectors.create_dataset("w", data=np.zeros(W.shape[1]))
    return path


def _restitutes(contact: Any) -> bool:
    """Whether a contact has a nonzero normal or tangential restitution coefficient."""
    given = (contact.e, contact.e_newton, contact.e_poisson, contact.e_energy, contact.e_t)
    return any(value for value in given if value is not None)
