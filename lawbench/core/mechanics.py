"""Shared mechanics at a frozen configuration: energy shares, kinetic angles, Coulomb cones."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from lawbench.core.metric import SPARSE_SHARE, as_array, kinetic_energy
from lawbench.core.problem import ImpactProblem

if TYPE_CHECKING:
    import scipy.sparse

# Rows beyond which a CSR product beats a dense one on a banded matrix: below, the sparse
# product's dispatch costs more than the arithmetic it saves.
SPARSE_PRODUCTS = 200
EPS = float(np.finfo(float).eps)


def separating_contacts(problem: ImpactProblem) -> list[int]:
    """Closed contacts whose gap rate is positive before the impact (they separate)."""
    return list(problem.separating)


def kinetic_angles(problem: ImpactProblem) -> np.ndarray:
    """Angles (degrees) between the contact constraints in the kinetic metric, (m, m).

    ``cos(theta_ij) = G_ij / sqrt(G_ii G_jj)`` with ``G`` the Delassus matrix (Brogliato 2010,
    eq. 26: two balls on a wall, ``cos(theta_12) = -sqrt(m1 / (m1 + m2))``). Paoli's condition:
    rigid laws with e > 0 are continuous in the initial data only where the angles are right
    angles (orthogonal constraints).
    """
    G = as_array(problem.delassus)
    scale = np.sqrt(np.diag(G))
    cosine = np.clip(G / np.outer(scale, scale), -1.0, 1.0)
    return np.degrees(np.arccos(cosine))


def energy_shares(problem: ImpactProblem, v: np.ndarray) -> dict[str, float]:
    """Share of the kinetic energy at ``v`` carried by each body (``problem.bodies``)."""
    total = kinetic_energy(problem.M, v)
    shares = {}
    for name, indices in problem.bodies.items():
        idx = list(indices)
        own = kinetic_energy(problem.M[np.ix_(idx, idx)], v[idx])
        shares[name] = own / total if total > 0 else 0.0
    return shares


def for_products(A: np.ndarray) -> np.ndarray | scipy.sparse.csr_matrix:
    """``A`` in the form its matrix-vector products are cheapest in.

    A matrix of more than ``SPARSE_PRODUCTS`` rows that is mostly zeros (a chain's Jacobian
    or Delassus matrix: banded) as a CSR matrix, whose products cost O(nnz) instead of
    O(rows x columns); any other as given.
    The integrating laws evaluate such products at every stage of every step.
    """
    import scipy.sparse  # on first use: a closed-form law imports no sparse algebra

    if scipy.sparse.issparse(A):
        return scipy.sparse.csr_matrix(A)
    if A.shape[0] > SPARSE_PRODUCTS and np.count_nonzero(A) <= SPARSE_SHARE * A.size:
        return scipy.sparse.csr_matrix(A)
    return A


def project(Pn: float, Pt: np.ndarray, mu: float) -> tuple[float, np.ndarray]:
    """Euclidean projection of ``(Pn, Pt)`` on the cone ``|Pt| <= mu Pn``."""
    if mu == 0:
        return max(Pn, 0.0), np.zeros_like(Pt)
    norm = float(np.linalg.norm(Pt))
    if norm <= mu * Pn:
        return Pn, Pt
    if mu * norm <= -Pn:
        return 0.0, np.zeros_like(Pt)
    normal = (Pn + mu * norm) / (1.0 + mu * mu)
    return normal, mu * normal * Pt / norm


def project_all(x: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """`project` of every row ``(Pn, Pt...)`` of ``x`` (m, 1 + d) on its cone, at once."""
    normal, tangent = x[:, 0], x[:, 1:]
    norm = np.linalg.norm(tangent, axis=1)
    inside = (norm <= mu * normal) & (normal >= 0)
    polar = mu * norm <= -normal
    projected_normal = (normal + mu * norm) / (1.0 + mu * mu)
    found = np.empty_like(x)
    found[:, 0] = np.where(inside, normal, np.where(polar, 0.0, projected_normal))
    with np.errstate(invalid="ignore", divide="ignore"):
        along = np.where(norm > 0, mu * projected_normal / norm, 0.0)
    found[:, 1:] = np.where(
        inside[:, None], tangent, np.where(polar[:, None], 0.0, along[:, None] * tangent)
    )
    return found


def fc3d_error(W: np.ndarray, q: np.ndarray, mu: np.ndarray, r: np.ndarray) -> float:
    """The FC3D error of a local frictional contact answer ``r``, free of the problem's units.

    ``W``, ``q`` and ``r`` in FCLIB's local order (per contact: normal, then its tangents);
    ``u = W r + q``. The natural map of De Saxce's complementarity (Acary, Brémond and Huber
    2018), per contact ``z_j - P_K(z_j - uhat_j)`` with ``uhat_j = u_j + (mu_j |u_Tj|, 0...)``
    and the impulse taken in units of velocity, ``z_j = W_jj r_j`` (``W_jj`` the contact's
    normal diagonal entry: the natural map's step ``1 / W_jj``, where Siconos'
    ``fc3d_compute_error`` takes 1), joined by every approach ``min(u_Nj, 0)``; in 2-norm over
    every contact, relative to the larger of ``|q|`` and ``|u|``. Every term is a velocity, so
    the measure is the same in any unit of impulse (``W / s``, ``r * s``) and of velocity
    (``W * s``, ``q * s``), contact by contact: impulses of 1e100 cannot dilute it. The
    approaches are counted apart because the natural map sees one only through the dual cone
    ``mu |w_T| <= w_N``, whose aperture shrinks as ``1 / mu``: at ``mu = 1e6`` a contact
    approaching at 1 moves ``uhat`` by 1e-6 from it. A local velocity is known to its rounding,
    ``dim eps (|W| |r| + |q|)`` row by row, and is given it: the modified velocity multiplies
    the rounding of a sticking contact's ``|u_T|`` by ``mu``, which at ``mu = 1e6`` made an
    error of 1e-10 of two roundings of one ``W`` (a global form's ``H.T M^-1 H`` and the
    impact's ``Wc.T M^-1 Wc``), below which no solver's tolerance could be met. Zero exactly
    at a solution; ``inf`` when ``r``, ``u``, the modified velocity or the rounding holds a
    number that is not finite: no tolerance accepts that answer. Norms are taken with their
    entries scaled by the largest first, so that none overflows.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        u = W @ r + q
        dim = r.size // len(mu)
        uj = u.reshape(-1, dim)
        rounding = (dim * EPS * (abs(W) @ np.abs(r) + np.abs(q))).reshape(-1, dim)
        z = np.asarray(W.diagonal())[::dim, None] * r.reshape(-1, dim)
        x = z - uj
        x[:, 0] -= mu * np.maximum(_norms(uj[:, 1:]) - _norms(rounding[:, 1:]), 0.0)
    if not (np.isfinite(x).all() and np.isfinite(z).all() and np.isfinite(rounding).all()):
        return math.inf
    with np.errstate(over="ignore"):  # mu * mu of mu near 1e300: the projection is then 0
        projected = project_all(x, mu)
    approach = np.minimum(uj[:, 0] + rounding[:, 0], 0.0)
    residual = np.concatenate([(z - projected).ravel(), approach])
    error = _norm(residual)
    scale = max(_norm(np.asarray(q, dtype=float)), _norm(u))
    return error / scale if scale > 0.0 else error


def _norm(x: np.ndarray) -> float:
    """The 2-norm of ``x``, its entries scaled by the largest first: squares never overflow."""
    largest = float(np.abs(x).max(initial=0.0))
    return largest * float(np.linalg.norm(x / largest)) if largest > 0 else 0.0


def _norms(x: np.ndarray) -> np.ndarray:
    """The 2-norm of each row of ``x``, overflow-free like `_norm`."""
    largest = np.abs(x).max(axis=1, initial=0.0)
    safe = np.where(largest > 0, largest, 1.0)
    return largest * np.linalg.norm(x / safe[:, None], axis=1)
