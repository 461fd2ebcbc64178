"""Impact problems in files: a documented, versioned format in JSON, NPZ or HDF5.

The format (version 1) holds one `ImpactProblem`:

| key | content |
| --- | --- |
| ``format`` | ``"lawbench-problem"`` |
| ``version`` | ``1`` |
| ``M`` | (n, n) mass matrix |
| ``Wn`` | (n, m) normal Jacobian, ``un = Wn.T @ v`` |
| ``Wt`` | (n, m*d) tangential Jacobian, absent without friction |
| ``v`` | (n,) pre-impact velocity |
| ``gaps`` | (m,) initial gaps |
| ``bodies`` | body name -> indices of its coordinates |
| ``contacts`` | one entry per contact: every field of `lawbench.Contact` (null where unset) |
| ``sparse`` | optional, true or false: whether the matrices are read back as scipy.sparse |

Any other key (array, in NPZ and HDF5) is refused, naming it.

Sign conventions as everywhere in lawbench: ``un < 0`` approaches, ``Pn >= 0`` pushes apart,
``v_plus = v + M^-1 (Wn Pn + Wt Pt)``.

The extension decides the encoding. ``.json`` is readable: matrices are nested lists of numbers
written with Python's shortest round-trip repr, so every float is read back bit for bit.
``.npz`` and ``.h5``/``.hdf5`` hold arrays; a matrix whose entries are mostly zero (sparse
chains) is stored as CSR triplets (``<name>.data``, ``.indices``, ``.indptr``, ``.shape``), so a
large sparse problem stays small on disk. A problem built with scipy.sparse matrices is marked
``sparse`` (true) and read back with them; JSON writes its matrices dense, and reads them back
sparse where a file is marked so by hand. ``bodies`` and ``contacts`` are stored as JSON text in
the array files. HDF5 needs h5py (``pip install 'lawbench[hdf5]'``).
"""

from __future__ import annotations

import json
import zipfile
import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse

from lawbench.core.contact import ContactProblem
from lawbench.core.errors import InvalidProblem, LawbenchError
from lawbench.core.metric import is_sparse
from lawbench.core.problem import Contact, ImpactProblem
from lawbench.files.facts import FileFacts, ProblemFile
from lawbench.files.hdf5 import require_h5py
from lawbench.files.paths import MAX_BYTES, input_file, output_file, replaced

if TYPE_CHECKING:
    from lawbench.files.fclib import FclibRead

FORMAT, VERSION = "lawbench-problem", 1
MATRICES = ("M", "Wn", "Wt", "v", "gaps")
# A matrix is stored as CSR when at most this share of its entries is non-zero.
SPARSE_SHARE = 0.25
# The most entries a matrix stored as CSR in a file not marked sparse may claim, read dense:
# those of a file of MAX_BYTES in doubles.
DENSE_MAX = MAX_BYTES // 8
CONTACT_FIELDS = tuple(Contact.__dataclass_fields__)
# Every key a file in the format may hold; ``sparse`` (true or false) marks a problem read back
# with scipy.sparse matrices.
KEYS = ("format", "version", *MATRICES, "bodies", "contacts", "sparse")
# The arrays of a CSR triplet an NPZ or HDF5 file stores a mostly-zero matrix as.
CSR_PARTS = ("data", "indices", "indptr", "shape")


def to_dict(problem: ImpactProblem) -> dict[str, Any]:
    """The problem as plain data (arrays as numpy arrays)."""
    data: dict[str, Any] = {"format": FORMAT, "version": VERSION}
    for name in MATRICES:
        value = getattr(problem, name)
        if value is not None:
            data[name] = value if is_sparse(value) else np.array(value)
    data["bodies"] = {name: list(idx) for name, idx in problem.bodies.items()}
    data["contacts"] = [{f: getattr(c, f) for f in CONTACT_FIELDS} for c in problem.contacts]
    return data


def from_dict(data: Mapping[str, Any], where: str = "problem") -> ImpactProblem:
    """Build a problem from plain data, checking the format, version and every field.

    Raises
    ------
    InvalidProblem
        Naming ``where`` and the field, or a key the format does not have.
    """
    unknown = sorted(set(data) - set(KEYS), key=str)
    if unknown:
        raise InvalidProblem(f"{where}: unknown key {unknown[0]!r}; known: {', '.join(KEYS)}")
    if data.get("format") != FORMAT:
        raise InvalidProblem(f"{where}: format is {data.get('format')!r}, expected {FORMAT!r}")
    if data.get("version") != VERSION or isinstance(data.get("version"), bool):
        raise InvalidProblem(f"{where}: version {data.get('version')!r} is not supported (1)")
    for name in ("M", "Wn", "v", "contacts"):
        if name not in data:
            raise InvalidProblem(f"{where}: field {name!r} is missing")
    contacts = data["contacts"]
    if not isinstance(contacts, list) or not all(isinstance(c, Mapping) for c in contacts):
        raise InvalidProblem(f"{where}: contacts must be a list of objects")
    parsed = []
    for j, contact in enumerate(contacts):
        unknown = sorted(set(contact) - set(CONTACT_FIELDS))
        if unknown:
            raise InvalidProblem(f"{where}: contacts[{j}].{unknown[0]} is not a contact field")
        for name, value in contact.items():
            if value is not None and (
                isinstance(value, bool) or not isinstance(value, int | float)
            ):
                raise InvalidProblem(f"{where}: contacts[{j}].{name} = {value!r}: not a number")
        parsed.append(Contact(**contact))
    for name in ("M", "Wn", "Wt", "v", "gaps"):
        value = data.get(name)
        if value is None or is_sparse(value):
            continue
        try:
            np.asarray(value, dtype=float)
        except (ValueError, TypeError, OverflowError):  # OverflowError: an integer of 10**400
            raise InvalidProblem(
                f"{where}: field {name!r} holds a value that is not a number"
            ) from None
    bodies = data.get("bodies", {})
    if not isinstance(bodies, Mapping):
        raise InvalidProblem(f"{where}: bodies must map names to index lists")
    matrices = {name: data.get(name) for name in ("M", "Wn", "Wt")}
    if _flag(data.get("sparse", False), where):
        matrices = {name: _compressed(value) for name, value in matrices.items()}
    try:
        return ImpactProblem(
            v=data["v"], contacts=parsed, bodies=bodies, gaps=data.get("gaps"), **matrices
        )
    except InvalidProblem as exc:
        raise InvalidProblem(f"{where}: {exc}") from None


def _compressed(value: Any) -> Any:
    """A matrix of a file marked sparse as CSR; a value of another shape as it is (refused)."""
    if value is None or is_sparse(value) or np.ndim(value) != 2:
        return value
    return scipy.sparse.csr_array(np.asarray(value, dtype=float))


def _flag(value: Any, where: str | Path) -> bool:
    """The ``sparse`` mark: true or false (a boolean array of no dimension in NPZ and HDF5)."""
    if isinstance(value, np.ndarray) and value.shape == () and value.dtype.kind == "b":
        value = bool(value)
    if not isinstance(value, bool | np.bool_):
        raise InvalidProblem(f"{where}: field 'sparse' = {value!r}: must be true or false")
    return bool(value)


def save_problem(problem: ImpactProblem, path: str | Path) -> Path:
    """Write ``problem`` to ``path`` in the encoding its extension names; return the path.

    Raises
    ------
    InvalidProblem
        For an unknown extension, or a file that cannot be written (it is written whole or not
        at all: `lawbench.files.paths.replaced`).
    SolverFailure
        For a disk that runs out of room; the file is left as it was.
    """
    if not isinstance(problem, ImpactProblem):
        raise TypeError(f"problem must be an ImpactProblem, not {type(problem).__name__}")
    path = output_file(path, "problem file")
    writer = _codec(path)[0]
    data = to_dict(problem)
    if writer is _write_json:
        _fits_json(data, path)
    with replaced(path, "problem file") as temporary:
        writer(data, temporary)
    return path


def load_problem(path: str | Path) -> ImpactProblem | ContactProblem:
    """Read a problem written by `save_problem` (or by hand, in the same format).

    An HDF5 file holding an FCLIB problem is read as one (`lawbench.files.fclib`): its global
    form as an `ImpactProblem`, its local form as the `ContactProblem` it is. The problem of
    `read_problem`, without the facts its reading learned.

    Raises
    ------
    InvalidProblem
        For an unknown extension, an unreadable or malformed file, or a bad field; the
        message names the file and the field.
    """
    return read_problem(path).problem


def read_problem(path: str | Path) -> ProblemFile:
    """Read a problem file once: its problem, and what the reading learned of the file.

    The facts (`lawbench.files.facts.FileFacts`) name the file's form (``'lawbench'``, or
    FCLIB's ``'local'`` or ``'global'``), each matrix's layout on disk, the reformulation
    applied to an FCLIB global form that is no impact, and, for FCLIB, the file's own ``W``
    and ``q``: all a caller needs of the file after the read, without opening it again.

    Raises
    ------
    InvalidProblem
        As `load_problem`.
    NotApplicable
        For FCLIB's rolling-friction form: no impact law here has rolling resistance.
    """
    path = input_file(path, "problem file")
    reader = _codec(path)[1]
    try:
        read = reader(path)
    except LawbenchError:
        raise
    except OSError as exc:
        raise InvalidProblem(f"{path}: cannot be read ({exc.strerror or exc})") from None
    except (
        ValueError,
        KeyError,
        TypeError,
        EOFError,
        RuntimeError,
        zipfile.BadZipFile,
        zlib.error,
    ) as exc:
        # A damaged file: RuntimeError is h5py's word for a broken HDF5 structure, zlib's
        # error an NPZ member that does not inflate.
        raise InvalidProblem(f"{path}: not a lawbench problem file ({exc})") from None
    return read.interpret()


@dataclass(frozen=True)
class _Read:
    """The plain data of a file in lawbench's format and the layout of each matrix in it."""

    data: dict[str, Any]
    storage: tuple[tuple[str, str], ...]
    where: Path

    def interpret(self) -> ProblemFile:
        """The problem the data define, checked field by field (`from_dict`)."""
        problem = from_dict(self.data, str(self.where))
        return ProblemFile(problem, FileFacts("lawbench", self.storage))


def _json_default(value: Any) -> Any:
    if is_sparse(value):
        value = value.toarray()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot write {type(value).__name__}")


def _fits_json(data: dict[str, Any], path: Path) -> None:
    """Refuse a problem whose JSON file no reader would take, before its dense copy is made.

    JSON holds matrices dense, each entry at least two characters (``0,``): more than
    `MAX_BYTES` is more than a problem file may hold.
    """
    entries = sum(int(np.prod(value.shape)) for value in data.values() if is_sparse(value))
    if 2 * entries > MAX_BYTES:
        raise InvalidProblem(
            f"{path}: JSON holds matrices dense, {entries:.3g} entries here, more than a problem "
            f"file may hold ({MAX_BYTES} bytes); write .npz or .h5, which keep them sparse"
        )


def _write_json(data: dict[str, Any], path: Path) -> None:
    path.write_text(json.dumps(data, default=_json_default, indent=1, allow_nan=False) + "\n")


def _read_json(path: Path) -> _Read:
    def reject(name: str) -> float:
        raise InvalidProblem(f"{path}: {name} is not a finite number (a problem holds only those)")

    try:
        data = json.loads(path.read_text(), parse_constant=reject)
    except json.JSONDecodeError as exc:
        raise InvalidProblem(f"{path}: malformed JSON ({exc})") from None
    except UnicodeDecodeError as exc:
        raise InvalidProblem(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except RecursionError:
        raise InvalidProblem(f"{path}: JSON nested deeper than a problem ever is") from None
    if not isinstance(data, dict):
        raise InvalidProblem(f"{path}: expected a JSON object")
    return _Read(data, tuple((name, "dense") for name in MATRICES if name in data), path)


def _arrays(data: dict[str, Any]) -> dict[str, np.ndarray]:
    """Flat arrays for NPZ and HDF5: dense, or CSR triplets for mostly-zero matrices.

    ``sparse`` marks a problem given with scipy.sparse matrices, read back as one.
    """
    arrays: dict[str, np.ndarray] = {
        "format": np.array(FORMAT),
        "version": np.array(VERSION),
        "bodies": np.array(json.dumps(data["bodies"])),
        "contacts": np.array(json.dumps(data["contacts"])),
    }
    if is_sparse(data["M"]):
        arrays["sparse"] = np.array(True)
    for name in MATRICES:
        if name not in data:
            continue
        value = data[name]
        if is_sparse(value) or (
            value.ndim == 2
            and value.size > 64
            and np.count_nonzero(value) <= SPARSE_SHARE * value.size
        ):
            csr = scipy.sparse.csr_matrix(value)
            arrays |= {
                f"{name}.data": csr.data,
                f"{name}.indices": csr.indices,
                f"{name}.indptr": csr.indptr,
                f"{name}.shape": np.array(csr.shape),
            }
        else:
            arrays[name] = value
    return arrays


def _from_arrays(get: Callable[[str], Any], names: set[str], where: Path) -> _Read:
    """Plain data from the flat arrays of the NPZ or HDF5 file ``where``."""
    data: dict[str, Any] = {}
    storage: list[tuple[str, str]] = []
    stored = set(KEYS) | {f"{name}.{part}" for name in MATRICES for part in CSR_PARTS}
    unknown = sorted(names - stored)
    if unknown:
        raise InvalidProblem(f"{where}: unknown array {unknown[0]!r}; known: {', '.join(KEYS)}")
    for key in ("format", "version"):
        if key in names:
            value = np.asarray(get(key)).item()
            data[key] = value.decode() if isinstance(value, bytes) else value
    for key in ("bodies", "contacts"):
        if key in names:
            text = np.asarray(get(key)).item()
            data[key] = json.loads(text.decode() if isinstance(text, bytes) else text)
    sparse = "sparse" in names and _flag(np.asarray(get("sparse")), where)
    for name in MATRICES:
        if name in names:
            data[name] = np.asarray(get(name))
            storage.append((name, "dense"))
        elif f"{name}.data" in names:
            shape = _shape(np.asarray(get(f"{name}.shape")), name, where)
            matrix = scipy.sparse.csr_matrix(
                (get(f"{name}.data"), get(f"{name}.indices"), get(f"{name}.indptr")), shape
            )
            # Every index within the shape before anything reads the entries: an index out of
            # range would be read out of bounds by scipy's compiled loops.
            try:
                matrix.check_format(full_check=True)
            except ValueError as exc:
                raise InvalidProblem(
                    f"{where}: field {name!r}: its sparse index arrays are corrupt ({exc})"
                ) from None
            data[name] = matrix if sparse else _dense(matrix, name, where)
            storage.append((name, "compressed rows"))
    return _Read(data, tuple(storage), where)


def _shape(value: np.ndarray, name: str, where: Path) -> tuple[int, int]:
    """The shape a CSR triplet claims: two non-negative integers (of any integer dtype)."""
    if value.shape != (2,) or value.dtype.kind not in "iu" or (value < 0).any():
        raise InvalidProblem(
            f"{where}: field {name!r}: its shape {value.tolist()!r} is not two non-negative "
            "integers"
        )
    return int(value[0]), int(value[1])


def _dense(matrix: scipy.sparse.csr_matrix, name: str, where: Path) -> np.ndarray:
    """``matrix`` as an array, once the shape it claims has at most `DENSE_MAX` entries.

    A few bytes of a file can claim a billion columns: refused before they are allocated.
    """
    rows, columns = matrix.shape
    if rows * columns > DENSE_MAX:
        raise InvalidProblem(
            f"{where}: field {name!r} claims {rows} x {columns} entries, more than the "
            f"{DENSE_MAX} read dense from a file not marked sparse"
        )
    return matrix.toarray()


def _write_npz(data: dict[str, Any], path: Path) -> None:
    with path.open("wb") as handle:
        np.savez_compressed(handle, **_arrays(data))


def _read_npz(path: Path) -> _Read:
    with np.load(path, allow_pickle=False) as archive:
        return _from_arrays(lambda key: archive[key], set(archive.files), path)


def _write_hdf5(data: dict[str, Any], path: Path) -> None:
    with require_h5py().File(path, "w") as handle:
        group = handle.create_group(FORMAT)
        for key, value in _arrays(data).items():
            # Text (the format tag, bodies, contacts) is stored as an HDF5 string.
            group.create_dataset(key, data=value.item() if value.dtype.kind == "U" else value)


def _read_hdf5(path: Path) -> _Read | FclibRead:
    """The arrays of an HDF5 file in lawbench's format or FCLIB's, the file opened once."""
    from lawbench.files.fclib import form_of, read_open

    with require_h5py().File(path, "r") as handle:
        if form_of(handle) is not None:
            return read_open(handle, str(path))
        if FORMAT not in handle:
            raise InvalidProblem(f"{path}: no group {FORMAT!r} (not a lawbench problem file)")
        group = handle[FORMAT]
        return _from_arrays(lambda key: group[key][()], set(group), path)


CODECS: dict[str, tuple[Callable, Callable]] = {
    ".json": (_write_json, _read_json),
    ".npz": (_write_npz, _read_npz),
    ".h5": (_write_hdf5, _read_hdf5),
    ".hdf5": (_write_hdf5, _read_hdf5),
}


def _codec(path: Path) -> tuple[Callable, Callable]:
    try:
        return CODECS[path.suffix.lower()]
    except KeyError:
        known = ", ".join(CODECS)
        raise InvalidProblem(f"{path}: unknown extension {path.suffix!r}; known: {known}") from None


__all__ = ["from_dict", "load_problem", "read_problem", "save_problem", "to_dict"]
