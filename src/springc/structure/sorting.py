"""Incidence + perfect matching -> block lower triangular (BLT) order of equations.

Equation ``e`` depends on the equation matched to each variable it contains. The
strongly connected components of that dependency graph are the blocks (single
equations or algebraic loops); they are returned in evaluation order, every block
after all blocks it depends on. Variables that are already known (states, parameters,
time) must be left out of the incidence by the caller, so that the matching of the
remaining unknowns is perfect.

Cost: O(n + nnz) for the graph and scipy's strong components, plus a heap-based
topological sort of the condensation, O(n_blocks log n_blocks + nnz).
"""

from __future__ import annotations

import heapq
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.sparse import csr_matrix

from .graph import Incidence, biadjacency
from .matching import Matching, validate_matching

Block = tuple[int, ...]


def blt(incidence: Incidence, matching: Matching) -> tuple[Block, ...]:
    """Return the blocks of the system in evaluation order.

    ``matching`` must be a perfect matching of ``incidence`` (the variable count is
    ``len(matching.var_to_eq)``). Each block lists its equations ascending; among
    blocks that could be evaluated at the same point, the one holding the smallest
    equation index comes first, so the order is deterministic.
    """
    n_var = len(matching.var_to_eq)
    graph = biadjacency(incidence, n_var)
    validate_matching(graph, matching)
    if not matching.is_perfect:
        raise ValueError(
            f"BLT needs a perfect matching; {matching.size} of {graph.shape[0]} equations "
            f"and {n_var} variables are matched"
        )
    if graph.shape[0] == 0:
        return ()
    # Step 1: dependency graph: edge e -> equation matched to each variable of e.
    labels = _strong_components(graph, np.asarray(matching.var_to_eq, dtype=np.int64))
    # Step 2: group equations by component; a block's key is its smallest equation.
    order = np.argsort(labels, kind="stable")
    counts = np.bincount(labels)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    first_eq = order[starts]
    # Step 3: evaluation order of the components.
    sequence = _topological_order(graph, labels, np.asarray(matching.var_to_eq), first_eq)
    eqs = order.tolist()
    bounds = np.cumsum(counts).tolist()
    begins = starts.tolist()
    return tuple(tuple(eqs[begins[b] : bounds[b]]) for b in sequence)


def _strong_components(graph: csr_matrix, var_to_eq: np.ndarray) -> np.ndarray:
    """Label each equation with its strongly connected component in the dependency graph."""
    n_eq = graph.shape[0]
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    dependency = csr_matrix(
        (np.ones(graph.nnz), var_to_eq[graph.indices], graph.indptr), shape=(n_eq, n_eq)
    )
    _, labels = connected_components(dependency, directed=True, connection="strong")
    return np.asarray(labels, dtype=np.int64)


def _topological_order(
    graph: csr_matrix, labels: np.ndarray, var_to_eq: np.ndarray, first_eq: np.ndarray
) -> list[int]:
    """Kahn's algorithm on the condensation: components, dependencies first.

    Ready components are taken smallest ``first_eq`` first (a heap of those keys).
    """
    n_blocks = first_eq.size
    # Step 1: condensation edges from a dependency's component to the dependent one.
    rows = np.arange(graph.shape[0]).repeat(np.diff(graph.indptr))
    dependent = labels[rows]
    dependency = labels[var_to_eq[graph.indices]]
    keep = dependent != dependency
    keys = np.sort(dependency[keep] * n_blocks + dependent[keep])
    keys = keys[np.concatenate([[True], keys[1:] != keys[:-1]])] if keys.size else keys
    sources, targets = np.divmod(keys, n_blocks)
    indptr = np.searchsorted(sources, np.arange(n_blocks + 1)).tolist()
    successors = targets.tolist()
    waiting = np.bincount(targets, minlength=n_blocks).tolist()
    # Step 2: repeatedly emit the ready component with the smallest first equation.
    block_of_eq = labels.tolist()
    keys_of_block = first_eq.tolist()
    ready = [keys_of_block[b] for b in range(n_blocks) if waiting[b] == 0]
    heapq.heapify(ready)
    sequence: list[int] = []
    while ready:
        block = block_of_eq[heapq.heappop(ready)]
        sequence.append(block)
        for successor in successors[indptr[block] : indptr[block + 1]]:
            waiting[successor] -= 1
            if waiting[successor] == 0:
                heapq.heappush(ready, keys_of_block[successor])
    return sequence
