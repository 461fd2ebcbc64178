"""A problem read from a file, with what reading the file learned of it.

Reading a file decides its form (FCLIB's local or global form, or lawbench's own format), the
layout of each matrix on disk, and, for FCLIB, the contact-space data ``W``, ``q`` the file
defines (``W = H.T M^-1 H``, ``q = H.T M^-1 f + w`` for a global form). Whoever needs these
(the FC3D error of an answer on the file's own data, W's asymmetry or rank) takes them from the
`ProblemFile` the read returned, never by opening the file again.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from lawbench.core.contact import ContactProblem
from lawbench.core.mechanics import fc3d_error
from lawbench.core.metric import as_array
from lawbench.core.outcome import Outcome
from lawbench.core.problem import ImpactProblem

# The layouts of a matrix in a file: FCLIB's three sparse ones (``nz >= 0``, ``-1``, ``-2``;
# lawbench's CSR triplets are compressed rows) and a dense array.
LAYOUTS = ("triplets", "compressed columns", "compressed rows", "dense")


@dataclass(frozen=True)
class ContactSpace:
    """The frictional contact problem ``u = W r + q`` a file defines, in FCLIB's local order.

    ``W`` as the file's data give it (a global form's ``H.T M^-1 H``, entries as computed);
    ``mu`` one coefficient per contact; ``dim`` the normal and tangents of each contact.
    """

    W: Any
    q: np.ndarray
    mu: np.ndarray
    dim: int


@dataclass(frozen=True, eq=False)
class FileFacts:
    """What reading a problem file learned of it, beyond the problem it holds.

    Parameters
    ----------
    form : str
        ``'local'`` or ``'global'`` (FCLIB's forms), or ``'lawbench'`` (lawbench's format).
    storage : tuple of (str, str)
        Each matrix read, with its layout in the file (one of `LAYOUTS`).
    reformulation : str
        ``''`` when the problem is the file's as written; else the reformulation applied and
        why (a global form that is no impact, read in contact space as Siconos does).
    contact_space : callable or None
        The file's `ContactSpace`, computed on first call (a global form's ``M^-1 H`` costs a
        factorization no impact solve needs); None for lawbench's format, which holds the
        impact exactly as it is solved.
    """

    form: str
    storage: tuple[tuple[str, str], ...] = ()
    reformulation: str = ""
    contact_space: Callable[[], ContactSpace] | None = None

    @property
    def asymmetry(self) -> float | None:
        """``max |W - W.T| / max |W|`` of the file's ``W``: zero for a mechanical system's."""
        if self.contact_space is None:
            return None
        W = self.contact_space().W
        largest = float(abs(W).max()) if W.size else 0.0
        return float(abs(W - W.T).max()) / largest if largest else 0.0

    @functools.cached_property
    def rank(self) -> int | None:
        """The rank of the file's ``W``: below its size when contacts are redundant."""
        if self.contact_space is None:
            return None
        return int(np.linalg.matrix_rank(as_array(self.contact_space().W)))

    def diagnostics(self, outcome: Outcome) -> dict[str, float]:
        """How an impact's ``outcome`` answers the file's own problem.

        For a global FCLIB form read as an impact, ``fc3d_error``: Acary, Brémond and Huber's
        measure (`lawbench.core.mechanics.fc3d_error`) on the file's ``W`` and ``q``, ``r``
        the outcome's impulses in FCLIB's local order. Nothing for lawbench's format, which
        holds the problem exactly as it is solved, nor for a problem read in contact space,
        whose solution carries that error itself.
        """
        if self.form != "global" or self.reformulation or self.contact_space is None:
            return {}
        space = self.contact_space()
        m = space.mu.size
        r = np.zeros((m, space.dim))
        r[:, 0] = outcome.Pn
        if outcome.Pt.size:
            r[:, 1:] = outcome.Pt.reshape(m, space.dim - 1)
        return {"fc3d_error": fc3d_error(space.W, space.q, space.mu, r.ravel())}


@dataclass(frozen=True)
class ProblemFile:
    """A problem read from a file, and the `FileFacts` its reading learned."""

    problem: ImpactProblem | ContactProblem
    facts: FileFacts
