"""The ordering and band of the implicit methods' Newton matrices: a Jacobian's CSC
sparsity -> the band :mod:`.banded_lu` factorises (numpy and scipy only, no numba:
``auto``'s cost model prices a factorization on scipy's loop too)."""

from __future__ import annotations

import numpy as np


def band_layout(n: int, indptr: np.ndarray, indices: np.ndarray, dense_limit: int = 64
                ) -> tuple[np.ndarray, int, int, np.ndarray, np.ndarray]:
    """The ordering and band of ``c I - J`` for a Jacobian with CSC sparsity
    ``(indptr, indices)``: ``order`` (new index -> state), ``kl``, ``ku``, the flat
    position in ``B`` of each non-zero (CSC order) and of each diagonal entry.

    Up to ``dense_limit`` states the band is the whole matrix (a dense LU); above, the
    states are reordered by reverse Cuthill-McKee on the symmetrised pattern, which
    brings a chain's band down to a few entries.
    """
    import scipy.sparse as sp
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    indptr = np.asarray(indptr, dtype=np.int64)
    rows = np.asarray(indices, dtype=np.int64)
    cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
    if n <= dense_limit:
        order = np.arange(n, dtype=np.int64)
    else:
        pattern = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
        pattern = (pattern + pattern.T + sp.identity(n, format="csr")).tocsr()
        order = np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True),
                           dtype=np.int64)
    where = np.empty(n, dtype=np.int64)
    where[order] = np.arange(n, dtype=np.int64)
    i, j = where[rows], where[cols]
    if n <= dense_limit:
        kl = ku = max(n - 1, 0)
    else:
        kl = int(max(0, (i - j).max(initial=0)))
        ku = int(max(0, (j - i).max(initial=0)))
    width = 2 * kl + ku + 1
    positions = i * width + (j - i + kl)
    diagonal = np.arange(n, dtype=np.int64) * width + kl
    return order, kl, ku, positions, diagonal
