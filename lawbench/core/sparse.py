"""The sparse mass and Jacobian matrices of a large problem, checked.

Read only by problems given scipy.sparse matrices, which import scipy.sparse themselves; a
dense problem never loads it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.metric import is_sparse, non_finite


def checked_sparse_matrix(name: str, value: object, shape: tuple[int, int]) -> Any:
    """Return ``value`` as a read-only CSC array of ``shape``, or raise `InvalidProblem`.

    The checks cost O(nnz): only the stored entries are read, and a sparse ``value``'s shape
    before anything of its size is made (it may claim a billion columns).
    """
    import scipy.sparse

    if is_sparse(value) and value.shape != shape:
        raise InvalidProblem(f"{name} has shape {value.shape}, expected {shape}")
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
            f"{name}{[int(matrix.indices[k]), column]} {non_finite(matrix.data[k])}: must be finite"
        )
    matrix.eliminate_zeros()
    for part in (matrix.data, matrix.indices, matrix.indptr):
        part.setflags(write=False)
    return matrix
