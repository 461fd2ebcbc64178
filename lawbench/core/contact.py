"""Coulomb's frictional contact problem in contact space: FCLIB's local form, as given.

Find impulses ``r`` and local velocities ``u = W r + q`` with, per contact j, De Saxce and
Feng's (1991) complementarity ``K_j ∋ r_j _|_ uhat_j ∈ K*_j``,
``uhat_j = u_j + (mu_j |u_Tj|, 0[, 0])``, ``K_j = {|r_Tj| <= mu_j r_Nj}`` the Coulomb cone and
``K*_j`` its dual (Acary, Brémond and Huber, "On solving contact problems with Coulomb friction:
formulations and numerical comparisons", 2018, problem (2.4); FCLIB's ``fclib_local``).

It is the impact with ``e = 0`` of `lawbench.core.problem.ImpactProblem` seen only through its
contact Delassus matrix: ``W = Wc.T M^-1 Wc`` and ``q = Wc.T v-``. Here ``W`` and ``q`` are
taken as they are: ``W`` may be asymmetric or singular (its asymmetry is reported, never
removed) and ``q`` need not lie in the range of ``W``. There are no generalized coordinates,
so no velocities, energies or checks in them: the measure of an answer is its FC3D error
(`lawbench.core.mechanics.fc3d_error`). The order is FCLIB's: per contact its normal, then its
tangents; ``dim`` is 3 in space, 2 in the plane.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lawbench.core.errors import InvalidProblem
from lawbench.core.mechanics import fc3d_error


@dataclass(frozen=True, eq=False)
class ContactProblem:
    """``u = W r + q``, ``K ∋ r _|_ uhat ∈ K*`` per contact (module docstring).

    Parameters
    ----------
    W : array or scipy.sparse matrix (m*dim, m*dim)
        The Delassus operator in FCLIB's order; held in compressed rows, entries as given.
    q : array (m*dim,)
        Local velocity without impulses.
    mu : array (m,)
        Friction coefficients, >= 0.
    dim : int
        2 (plane) or 3 (space): the normal and ``dim - 1`` tangents of each contact.
    name : str
        Where the problem comes from, for messages.

    Raises
    ------
    InvalidProblem
        For shapes that disagree, non-finite numbers, a negative ``mu``, or a contact whose
        normal diagonal entry of ``W`` is not positive (its normal impulse would move nothing).
    """

    W: Any
    q: np.ndarray
    mu: np.ndarray
    dim: int = 3
    name: str = "contact problem"

    def __post_init__(self) -> None:
        import scipy.sparse  # here, not at import: a solve of an impact does not need it

        where = self.name
        if self.dim not in (2, 3):
            raise InvalidProblem(f"{where}: dim = {self.dim!r}, must be 2 or 3")
        mu = np.array(self.mu, dtype=float).ravel()
        q = np.array(self.q, dtype=float).ravel()
        size = mu.size * self.dim
        try:
            W = scipy.sparse.csr_array(self.W, dtype=float, copy=True)
        except (TypeError, ValueError) as exc:
            raise InvalidProblem(f"{where}: W is not a numeric matrix ({exc})") from None
        # Stored zeros (a writer that saves a dense block as sparse) change no entry of W and
        # would cost every Gauss-Seidel sweep their time.
        W.sum_duplicates()
        W.eliminate_zeros()
        W.sort_indices()
        if mu.size == 0:
            raise InvalidProblem(f"{where}: mu is empty (no contact)")
        if W.shape != (size, size) or q.size != size:
            raise InvalidProblem(
                f"{where}: W is {W.shape[0]} x {W.shape[1]} and q holds {q.size} entries; "
                f"{mu.size} contacts of dimension {self.dim} need {size} x {size} and {size}"
            )
        for label, values in (("W", W.data), ("q", q), ("mu", mu)):
            if not np.isfinite(values).all():
                raise InvalidProblem(f"{where}: {label} holds a number that is not finite")
        if (mu < 0).any():
            j = int(np.flatnonzero(mu < 0)[0])
            raise InvalidProblem(f"{where}: mu[{j}] = {mu[j]:g}, must be >= 0")
        normal = W.diagonal()[:: self.dim]
        if (normal <= 0).any():
            j = int(np.flatnonzero(normal <= 0)[0])
            raise InvalidProblem(
                f"{where}: W[{j * self.dim}, {j * self.dim}] = {normal[j]:g}: contact {j}'s "
                "normal impulse must change its own normal velocity (a positive diagonal entry)"
            )
        for array in (q, mu, W.data):
            array.setflags(write=False)
        object.__setattr__(self, "W", W)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "mu", mu)
        # Known from the start: every solution reports it, and no solve should pay for it.
        self.asymmetry  # noqa: B018

    @property
    def m(self) -> int:
        """The number of contacts."""
        return self.mu.size

    @functools.cached_property
    def asymmetry(self) -> float:
        """``max |W - W.T| / max |W|``: zero for a Delassus matrix of a mechanical system."""
        largest = float(np.abs(self.W.data).max(initial=0.0))
        if largest == 0.0:
            return 0.0
        return float(abs(self.W - self.W.T).max()) / largest

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """The local velocities ``u = W r + q`` of impulses ``r``."""
        return self.W @ r + self.q

    def error(self, r: np.ndarray) -> float:
        """The FC3D error of impulses ``r`` on this ``W`` and ``q`` (zero exactly at a solution)."""
        return fc3d_error(self.W, self.q, self.mu, r)


@dataclass(frozen=True, eq=False)
class ContactSolution:
    """The answer of a law to a `ContactProblem`.

    Attributes
    ----------
    r : array (m*dim,)
        Impulses, FCLIB's order.
    u : array (m*dim,)
        Local velocities ``W r + q``.
    fc3d_error : float
        The FC3D error of ``r`` on the problem's own ``W`` and ``q``.
    diagnostics : dict
        Formulation, sweeps or steps, solver status, wall time (``wall_time_s``), options,
        and ``W_asymmetry``.
    """

    r: np.ndarray
    u: np.ndarray
    fc3d_error: float
    diagnostics: dict[str, Any] = field(default_factory=dict)
