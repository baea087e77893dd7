"""Incidence -> maximum matching and Dulmage-Mendelsohn parts.

``maximum_matching`` pairs equations with variables (Hopcroft-Karp in scipy,
O(nnz sqrt(n))). ``augmenting_path`` is the one incremental search (iterative
depth-first) that Pantelides and the dummy-derivative choice grow their matchings with.
``dulmage_mendelsohn`` splits a system by alternating paths from the unmatched vertices
of a maximum matching into an overdetermined part (the equations to blame as
redundant), an underdetermined part (the variables left undetermined) and the
well-determined rest, in O(n + nnz) using ``scipy.sparse.csgraph`` searches.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.sparse import csr_matrix

from .graph import Incidence, biadjacency

UNMATCHED = -1


@dataclass(frozen=True, slots=True)
class Matching:
    """A matching between equations and variables; ``-1`` marks an unmatched vertex."""

    eq_to_var: tuple[int, ...]
    var_to_eq: tuple[int, ...]

    @classmethod
    def from_eq_to_var(cls, eq_to_var: Sequence[int], n_var: int) -> Matching:
        """Build a matching from the variable matched to each equation (``-1``: none)."""
        var_to_eq = [UNMATCHED] * n_var
        for eq, var in enumerate(eq_to_var):
            if var == UNMATCHED:
                continue
            if var_to_eq[var] != UNMATCHED:
                raise ValueError(f"variable {var} matched to equations {var_to_eq[var]}, {eq}")
            var_to_eq[var] = eq
        return cls(tuple(int(v) for v in eq_to_var), tuple(var_to_eq))

    @property
    def size(self) -> int:
        """The number of matched (equation, variable) pairs."""
        return len(self.eq_to_var) - self.eq_to_var.count(UNMATCHED)

    @property
    def is_perfect(self) -> bool:
        """Whether every equation and every variable is matched."""
        return len(self.eq_to_var) == len(self.var_to_eq) == self.size

    def pairs(self) -> frozenset[tuple[int, int]]:
        """The matched (equation, variable) pairs."""
        return frozenset((e, v) for e, v in enumerate(self.eq_to_var) if v != UNMATCHED)


@dataclass(frozen=True, slots=True)
class DMParts:
    """The coarse Dulmage-Mendelsohn decomposition; each field is sorted ascending.

    ``over_*``: equations reachable by alternating paths from unmatched equations and
    the variables they contain (more equations than variables: some are redundant).
    ``under_*``: variables reachable by alternating paths from unmatched variables and
    the equations containing them (more variables than equations). ``well_*``: the
    rest, which has a perfect matching of its own.
    """

    over_equations: tuple[int, ...]
    over_variables: tuple[int, ...]
    under_equations: tuple[int, ...]
    under_variables: tuple[int, ...]
    well_equations: tuple[int, ...]
    well_variables: tuple[int, ...]


def maximum_matching(incidence: Incidence, n_var: int) -> Matching:
    """Return a maximum matching of the equations to the variables they contain."""
    graph = biadjacency(incidence, n_var)
    if graph.shape[0] == 0 or n_var == 0:
        return Matching((UNMATCHED,) * graph.shape[0], (UNMATCHED,) * n_var)
    from scipy.sparse.csgraph import maximum_bipartite_matching

    eq_to_var = maximum_bipartite_matching(graph, perm_type="column")
    var_to_eq = np.full(n_var, UNMATCHED, dtype=np.int64)
    matched = np.flatnonzero(eq_to_var >= 0)
    var_to_eq[eq_to_var[matched]] = matched
    return Matching(tuple(eq_to_var.tolist()), tuple(var_to_eq.tolist()))


SMALL = 5000
"""Equations up to which :func:`perfectly_matchable` searches in Python."""


def perfectly_matchable(incidence: Incidence, n_var: int) -> bool:
    """Whether each equation can be matched to a variable of its own, every variable
    matched: by augmenting paths in Python for up to :data:`SMALL` equations (the
    balance check of a model that size never imports scipy), else by
    :func:`maximum_matching`."""
    if len(incidence) != n_var:
        return False
    if n_var > SMALL:
        return maximum_matching(incidence, n_var).is_perfect
    mate = [UNMATCHED] * n_var
    for eq in range(len(incidence)):
        found = augmenting_path(eq, incidence.__getitem__, mate.__getitem__)
        if not found.pairs:
            return False
        for left, right in found.pairs:
            mate[right] = left
    return True


@dataclass(frozen=True, slots=True)
class AugmentingPath:
    """The result of :func:`augmenting_path`: ``pairs`` (left, right) to match, in
    path order (empty when no path exists); ``left`` and ``right`` the vertices visited
    (the search's *coloured* part, which Pantelides differentiates on failure)."""

    pairs: tuple[tuple[int, int], ...]
    left: tuple[int, ...]
    right: tuple[int, ...]


def augmenting_path(
    root: int,
    neighbours: Callable[[int], Sequence[int]],
    mate: Callable[[int], int],
    usable: Callable[[int], bool] | None = None,
) -> AugmentingPath:
    """Depth-first search for an augmenting path from the unmatched left vertex ``root``.

    ``neighbours(left)`` lists the right vertices of a left vertex, in the order they
    are tried; ``mate(right)`` is the left vertex matched to it, or ``UNMATCHED``;
    ``usable(right)`` (default: all) excludes right vertices from the search. Iterative,
    so deep paths need no recursion. On success, matching every pair of ``pairs``
    (left to right) flips the path and grows the matching by one.
    """
    seen_left: set[int] = {root}
    seen_right: set[int] = set()
    left, right = [root], []
    path, positions = [root], [0]
    via: list[int] = []  # via[k]: the right vertex leading to path[k+1]
    while path:
        candidates, pos = neighbours(path[-1]), positions[-1]
        while pos < len(candidates):
            vertex = candidates[pos]
            pos += 1
            if vertex in seen_right or (usable is not None and not usable(vertex)):
                continue
            seen_right.add(vertex)
            right.append(vertex)
            owner = mate(vertex)
            if owner == UNMATCHED:
                pairs = tuple(zip(path, [*via, vertex], strict=True))
                return AugmentingPath(pairs, tuple(left), tuple(right))
            if owner not in seen_left:
                seen_left.add(owner)
                left.append(owner)
                positions[-1] = pos
                path.append(owner)
                positions.append(0)
                via.append(vertex)
                break
        else:
            path.pop()
            positions.pop()
            if via:
                via.pop()
    return AugmentingPath((), tuple(left), tuple(right))


def validate_matching(graph: csr_matrix, matching: Matching) -> None:
    """Raise ``ValueError`` unless ``matching`` is a consistent matching of ``graph``.

    ``graph`` is the biadjacency from :func:`~springc.structure.graph.biadjacency`.
    Checks sizes, that both directions agree, and that every pair is an edge.
    """
    n_eq, n_var = graph.shape
    if len(matching.eq_to_var) != n_eq or len(matching.var_to_eq) != n_var:
        raise ValueError(
            f"matching is for {len(matching.eq_to_var)} equations and "
            f"{len(matching.var_to_eq)} variables, the system has {n_eq} and {n_var}"
        )
    eq_to_var = np.asarray(matching.eq_to_var, dtype=np.int64)
    var_to_eq = np.asarray(matching.var_to_eq, dtype=np.int64)
    eqs = np.flatnonzero(eq_to_var >= 0)
    vars_ = eq_to_var[eqs]
    if np.count_nonzero(var_to_eq >= 0) != eqs.size or np.any(var_to_eq[vars_] != eqs):
        raise ValueError("eq_to_var and var_to_eq disagree")
    # Step 1: an edge (e, v) exists iff v is found in row e's sorted column slice.
    starts = graph.indptr[eqs]
    ends = graph.indptr[eqs + 1]
    keys = np.arange(n_eq).repeat(np.diff(graph.indptr)) * n_var + graph.indices
    found = np.searchsorted(keys, eqs * n_var + vars_)
    if np.any((found < starts) | (found >= ends)) or np.any(keys[found] != eqs * n_var + vars_):
        raise ValueError("matching pairs an equation with a variable it does not contain")


def dulmage_mendelsohn(
    incidence: Incidence, n_var: int, matching: Matching | None = None
) -> DMParts:
    """Split the system into over-, under- and well-determined parts.

    ``matching`` must be a maximum matching (computed here when omitted); a matching
    that still has an augmenting path raises ``ValueError``.
    """
    graph = biadjacency(incidence, n_var)
    if matching is None:
        matching = maximum_matching(incidence, n_var)
    validate_matching(graph, matching)
    eq_to_var = np.asarray(matching.eq_to_var, dtype=np.int64)
    var_to_eq = np.asarray(matching.var_to_eq, dtype=np.int64)
    # Step 1: overdetermined: from unmatched equations, equation -> variable -> its equation.
    over_eqs = _alternating_reach(graph, var_to_eq, np.flatnonzero(eq_to_var < 0))
    over_vars = _neighbours(graph, over_eqs)
    # Step 2: underdetermined: the same walk on the transposed graph.
    graph_t = graph.T.tocsr()
    under_vars = _alternating_reach(graph_t, eq_to_var, np.flatnonzero(var_to_eq < 0))
    under_eqs = _neighbours(graph_t, under_vars)
    if np.any(var_to_eq[over_vars] < 0) or np.any(eq_to_var[under_eqs] < 0):
        raise ValueError("the matching is not maximum (an augmenting path exists)")
    # Step 3: the rest is well determined.
    well_eqs = np.setdiff1d(np.arange(graph.shape[0]), np.union1d(over_eqs, under_eqs))
    well_vars = np.setdiff1d(np.arange(n_var), np.union1d(over_vars, under_vars))
    return DMParts(
        *(_as_tuple(a) for a in (over_eqs, over_vars, under_eqs, under_vars, well_eqs, well_vars))
    )


def _alternating_reach(graph: csr_matrix, col_to_row: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Rows reachable from ``starts`` by row -> column -> the row matched to the column.

    A super source (index ``n_rows``) joined to every start lets one breadth-first
    search cover all of them. Returns the reached rows, sorted.
    """
    n_rows = graph.shape[0]
    if starts.size == 0:
        return np.zeros(0, dtype=np.int64)
    rows = np.arange(n_rows).repeat(np.diff(graph.indptr))
    targets = col_to_row[graph.indices]
    keep = targets >= 0
    src = np.concatenate([rows[keep], np.full(starts.size, n_rows)])
    dst = np.concatenate([targets[keep], starts])
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import breadth_first_order

    walk = csr_matrix((np.ones(src.size), (src, dst)), shape=(n_rows + 1, n_rows + 1))
    reached = breadth_first_order(walk, n_rows, directed=True, return_predecessors=False)
    return np.sort(reached[reached != n_rows])


def _neighbours(graph: csr_matrix, rows: np.ndarray) -> np.ndarray:
    """The sorted columns that any of ``rows`` contains."""
    if rows.size == 0:
        return np.zeros(0, dtype=np.int64)
    return np.unique(graph[rows].indices)


def _as_tuple(values: np.ndarray) -> tuple[int, ...]:
    return tuple(int(v) for v in values.tolist())
