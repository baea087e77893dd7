"""A cheap stiffness estimate for ``--solver auto``: Jacobian + time scale -> choice.

The spectral radius ``rho`` of the Jacobian at the start gives the fastest local
time scale ``1/rho``. An explicit method needs about ``rho * T`` steps over a span
``T`` for stability alone, while an implicit method's step is limited only by
accuracy; past a few thousand such steps the implicit method wins despite its
linear solves. ``rho`` comes from ARPACK (or the exact eigenvalues of a small dense
Jacobian), so the estimate costs a few dozen Jacobian-vector products.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .solver_names import EXPLICIT, RACE_IMPLICIT

if TYPE_CHECKING:
    from scipy.sparse import spmatrix

STIFF_THRESHOLD = 2000.0
"""``rho * T`` above which the implicit solver is chosen."""

DENSE_LIMIT = 400
"""Jacobians up to this size get exact eigenvalues."""

START_SEED = 28
"""The seed of ARPACK's start vector (see :func:`spectral_radius`)."""


@dataclass(frozen=True)
class Choice:
    solver: str
    spectral_radius: float
    stiffness: float  # rho * T
    reason: str


def is_sparse(jac: object) -> bool:
    """Whether ``jac`` is a scipy.sparse matrix, without importing scipy.sparse (a
    third of a second): no sparse matrix exists before it is imported, and a small
    model's Jacobian is dense."""
    sparse = sys.modules.get("scipy.sparse")
    return sparse is not None and bool(sparse.issparse(jac))


def as_dense(jac: np.ndarray | spmatrix) -> np.ndarray:
    """``jac`` as a dense float array."""
    if is_sparse(jac):
        import scipy.sparse as sp  # already loaded: ``jac`` is one of its matrices

        return np.asarray(sp.csr_matrix(jac).toarray(), dtype=float)
    return np.asarray(jac, dtype=float)


def spectral_radius(jac: np.ndarray | spmatrix) -> float:
    """Largest eigenvalue magnitude: exact for small Jacobians, ARPACK for large ones.

    (A singular-value bound would be useless here: for a mass-spring system it is
    about ``omega**2`` while the spectral radius is ``omega``.)
    """
    n = jac.shape[0]
    values = jac.data if is_sparse(jac) else np.asarray(jac)
    if not np.all(np.isfinite(values)):
        return float("inf")
    if n == 0:
        return 0.0
    if n <= DENSE_LIMIT:
        dense = as_dense(jac)
        return float(np.max(np.abs(np.linalg.eigvals(dense))))
    import scipy.sparse as sp  # a large Jacobian: ARPACK
    from scipy.sparse.linalg import ArpackNoConvergence, eigs

    operator = sp.csr_matrix(jac, dtype=float)
    # ARPACK's own start vector comes from a generator that runs on from call to call
    # in a process: a fixed one gives the same estimate in every process
    start = np.random.default_rng(START_SEED).standard_normal(n)
    try:
        largest = eigs(operator, k=1, which="LM", tol=1e-2, maxiter=500, v0=start,
                       return_eigenvectors=False)
    except ArpackNoConvergence as partial:
        largest = partial.eigenvalues
        if not len(largest):
            return float(sp.linalg.norm(operator, np.inf))  # Gershgorin bound
    return float(np.max(np.abs(largest)))


def numerical_jacobian(rhs: Callable[[float, np.ndarray], np.ndarray], t: float,
                       y: np.ndarray) -> np.ndarray:
    """Forward differences of ``rhs`` at ``(t, y)`` (for systems without an analytic
    Jacobian, such as the switching driver's reference evaluator; small ones)."""
    y = np.asarray(y, dtype=float)
    f0 = np.asarray(rhs(t, y), dtype=float)
    jac = np.empty((len(f0), len(y)))
    for j in range(len(y)):
        h = 1e-7 * max(1.0, abs(y[j]))
        shifted = y.copy()
        shifted[j] += h
        jac[:, j] = (np.asarray(rhs(t, shifted), dtype=float) - f0) / h
    return jac


def choose_solver(jac: np.ndarray | spmatrix, span: float,
                  explicit: str = EXPLICIT, implicit: str = RACE_IMPLICIT) -> Choice:
    """Pick ``explicit`` or ``implicit`` from ``rho * span`` and say why.

    For large Jacobians the row-sum (Gershgorin) bound ``rho <= ||J||_inf`` is tried
    first: when even the bound is not stiff, no eigenvalue computation is needed.
    """
    if jac.shape[0] > DENSE_LIMIT:
        bound = _row_sum_bound(jac)
        if math.isfinite(bound) and bound * abs(span) <= STIFF_THRESHOLD:
            reason = (f"non-stiff: spectral radius <= {bound:.3g} 1/s (row-sum bound) over "
                      f"{span:g} s (rho*T <= {bound * abs(span):.3g} <= {STIFF_THRESHOLD:g})")
            return Choice(explicit, bound, bound * abs(span), reason)
    rho = spectral_radius(jac)
    stiffness = rho * abs(span)
    if not np.isfinite(stiffness):
        return Choice(implicit, rho, stiffness,
                      "the Jacobian is not finite at the start; using an implicit method")
    if stiffness > STIFF_THRESHOLD:
        reason = (f"stiff: fastest time scale 1/{rho:.3g} s is {stiffness:.3g}x shorter "
                  f"than the {span:g} s span")
        return Choice(implicit, rho, stiffness, reason)
    reason = (f"non-stiff: spectral radius {rho:.3g} 1/s over {span:g} s "
              f"(rho*T = {stiffness:.3g} <= {STIFF_THRESHOLD:g})")
    return Choice(explicit, rho, stiffness, reason)


def _row_sum_bound(jac: np.ndarray | spmatrix) -> float:
    """``||J||_inf``, an upper bound of the spectral radius."""
    if is_sparse(jac):
        import scipy.sparse as sp  # already loaded: ``jac`` is one of its matrices

        sums = np.asarray(abs(sp.csr_matrix(jac)).sum(axis=1)).ravel()
        return float(np.max(sums, initial=0.0))
    return float(np.max(np.abs(np.asarray(jac)).sum(axis=1), initial=0.0))
