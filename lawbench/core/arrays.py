"""Arrays an impact problem holds: dense or scipy.sparse, checked finite, kept read-only.

scipy.sparse is imported only by problems given sparse matrices: a small problem never loads it.
"""

from __future__ import annotations

import math
import sys
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem


def all_finite(array: np.ndarray) -> bool:
    """Whether every entry of ``array`` is finite."""
    return bool(np.isfinite(array).all())


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


def checked_matrix(name: str, value: object, shape: tuple[int, ...]) -> np.ndarray:
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
    return read_only_finite(name, array)


def _non_finite(value: float) -> str:
    """What a non-finite number is, in words (a message never shows a NaN of its own)."""
    return "is not a number" if math.isnan(value) else f"is {'-' if value < 0 else ''}infinite"


def read_only_finite(name: str, array: np.ndarray) -> np.ndarray:
    """Make ``array`` (the problem's own copy) read-only, or raise naming a non-finite entry."""
    if not all_finite(array):
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        raise InvalidProblem(f"{name}{list(index)} {_non_finite(array[index])}: must be finite")
    array.setflags(write=False)
    return array


def checked_sparse_matrix(name: str, value: object, shape: tuple[int, int]) -> Any:
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
