"""Incidence (list form) -> sparse biadjacency and transposed incidence.

An *incidence* lists, for each equation ``0..n_eq-1``, the indices of the variables
``0..n_var-1`` it contains. The structural algorithms of this package work on these
integer graphs only; they never see expressions. The helpers here turn the list form
into a CSR matrix (rows: equations, columns: variables) that ``scipy.sparse.csgraph``
can walk at C speed, and back into lists when a caller wants them. All run in
O(n_eq + n_var + nnz) apart from the sort that merges duplicate entries.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.sparse import csr_matrix

Incidence = Sequence[Sequence[int]]
"""For each equation, the indices of the variables it contains."""


def biadjacency(incidence: Incidence, n_var: int) -> csr_matrix:
    """Return the ``n_eq x n_var`` CSR biadjacency of ``incidence``.

    Entries are ones; duplicate variables in one equation are merged and column
    indices are sorted within each row. Raises ``ValueError`` for a variable index
    outside ``0..n_var-1``.
    """
    n_eq = len(incidence)
    lengths = np.fromiter((len(row) for row in incidence), dtype=np.int64, count=n_eq)
    indptr = np.zeros(n_eq + 1, dtype=np.int64)
    np.cumsum(lengths, out=indptr[1:])
    nnz = int(indptr[-1])
    indices = np.fromiter(itertools.chain.from_iterable(incidence), dtype=np.int64, count=nnz)
    if nnz and (indices.min() < 0 or indices.max() >= n_var):
        bad = int(indices[(indices < 0) | (indices >= n_var)][0])
        raise ValueError(f"variable index {bad} outside 0..{n_var - 1}")
    data = np.ones(nnz, dtype=np.int8)
    from scipy.sparse import csr_matrix  # scipy when a graph is built: a check never needs it

    matrix = csr_matrix((data, indices, indptr), shape=(n_eq, n_var))
    matrix.sum_duplicates()
    matrix.data[:] = 1
    return matrix


def to_incidence(matrix: csr_matrix) -> tuple[tuple[int, ...], ...]:
    """Return the list form of a CSR matrix: for each row, its column indices."""
    indptr = matrix.indptr.tolist()
    indices = matrix.indices.tolist()
    return tuple(tuple(indices[indptr[i] : indptr[i + 1]]) for i in range(matrix.shape[0]))


def transpose(incidence: Incidence, n_var: int) -> tuple[tuple[int, ...], ...]:
    """Return, for each variable, the sorted indices of the equations containing it."""
    return to_incidence(biadjacency(incidence, n_var).T.tocsr())
