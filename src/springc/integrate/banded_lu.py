"""Banded LU with partial pivoting, compiled (real and complex), for the implicit method.

A matrix of lower bandwidth ``kl`` and upper bandwidth ``ku`` is stored by rows:
``B[i, j - i + kl]`` holds ``A[i, j]``, ``2 kl + ku + 1`` entries per row (the ``kl``
extra ones take the fill-in of row interchanges). Elimination keeps LAPACK's
convention (``gbtrf``): the multipliers stay where they were computed, the
interchanges are replayed in order when solving. The cost is ``n kl (kl + ku)`` per
factorisation and ``n (2 kl + ku)`` per solve, so a chain's Newton matrix (bandwidth
2-3 after a reverse Cuthill-McKee ordering) factorises in linear time; a small dense
system is the band ``kl = ku = n - 1``.

:func:`band_layout` (Python, scipy, in :mod:`.ordering`: no numba, so that springc can
price a factorization without it) chooses the ordering and the bandwidths from a
Jacobian's CSC sparsity, and where each non-zero lands in ``B``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .ordering import band_layout

__all__ = ["band_factor", "band_layout", "band_solve"]


@njit(cache=True, error_model="numpy", nogil=True)
def band_factor(B: np.ndarray, kl: int, ku: int, pivots: np.ndarray) -> bool:
    """Factorise ``B`` in place (see the module text); False if a pivot is zero."""
    n = B.shape[0]
    width = kl + ku  # the reach of a row after interchanges, right of the diagonal
    for k in range(n):
        last = min(n - 1, k + kl)
        p = k
        best = abs(B[k, kl])
        for i in range(k + 1, last + 1):
            size = abs(B[i, k - i + kl])
            if size > best:
                best, p = size, i
        pivots[k] = p
        if best == 0.0:
            return False
        right = min(n - 1, k + width)
        if p != k:
            for j in range(k, right + 1):
                a = B[k, j - k + kl]
                B[k, j - k + kl] = B[p, j - p + kl]
                B[p, j - p + kl] = a
        pivot = B[k, kl]
        for i in range(k + 1, last + 1):
            m = B[i, k - i + kl] / pivot
            B[i, k - i + kl] = m
            if m != 0.0:
                for j in range(k + 1, right + 1):
                    B[i, j - i + kl] -= m * B[k, j - k + kl]
    return True


@njit(cache=True, error_model="numpy", nogil=True)
def band_solve(B: np.ndarray, kl: int, ku: int, pivots: np.ndarray, b: np.ndarray) -> None:
    """Solve ``A x = b`` in place with the factors of :func:`band_factor`."""
    n = B.shape[0]
    width = kl + ku
    for k in range(n):
        p = pivots[k]
        if p != k:
            a = b[k]
            b[k] = b[p]
            b[p] = a
        bk = b[k]
        for i in range(k + 1, min(n - 1, k + kl) + 1):
            b[i] -= B[i, k - i + kl] * bk
    for k in range(n - 1, -1, -1):
        s = b[k]
        for j in range(k + 1, min(n - 1, k + width) + 1):
            s -= B[k, j - k + kl] * b[j]
        b[k] = s / B[k, kl]
