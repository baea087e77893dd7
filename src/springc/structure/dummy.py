"""IndexReduction -> StateSelection: dummy derivatives (Mattsson and Söderlind, 1993).

Input: the :class:`~springc.structure.index.IndexReduction` of a DAE, a priority
per variable (see :func:`state_priority`) and an optional numeric check.
Output: :class:`StateSelection`: the variables that stay states (their derivative is
a true derivative), the derivatives turned into algebraic *dummy* derivatives, and
the square blocks whose nonsingularity the choice relies on.

The method, level by level (level 1 = the highest derivatives):

1. Rows: the highest-order equations that were obtained by differentiation.
   Columns: the highest derivatives they contain (all are derivatives of something).
2. Pick as many columns as rows such that the block is nonsingular; these become
   dummy derivatives. Columns are tried from the lowest priority up, so the
   high-priority candidates keep their true derivatives and remain states.
3. Next level: rows are the equations those rows are derivatives of, when these are
   themselves derivatives; columns are the antiderivatives of the chosen dummies,
   when these are derivatives themselves. Repeat until no rows are left.

Restricting level i+1 to antiderivatives of level-i dummies keeps the choice nested
(a dummy ``der(x)`` implies a dummy ``der(der(x))``) and is always feasible: the
Jacobian of ``d/dt g`` with respect to the highest derivatives equals that of ``g``
with respect to the next lower ones, so level i+1's block is a row subset of level i's.

What is checked here and what is not: the choice is *structural*, a maximum matching
of rows to columns taken greedily in priority order (the greedy basis of the
transversal matroid, so it is the best choice by priority). A structurally regular
block can still be numerically singular (e.g. ``der(x)*x + der(y)*y`` at ``x = 0``).
The caller may pass ``is_nonsingular(rows, cols)``, which then vets each block (split
into connected components first); a rejected block is replaced by the next
structurally regular column set in priority order. Without it every block is assumed
nonsingular and :attr:`StateSelection.blocks` lists what the caller must check later.

Instead the caller may pass ``choose(equations, columns, tiers)``, which picks the
dummies itself among all candidate columns of a block (given in priority order, with
``tiers`` grouping columns of equal priority and differentiation order), e.g. the
best-conditioned choice at given values. This is what dynamic state selection
(:mod:`springc.switching`) re-runs during simulation; each block records its
candidates and tiers so that the choice can be monitored.

Cost: O(n_eq + n_var) when no equation was differentiated; otherwise the augmenting
searches run only over the differentiated equations and their columns.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from .index import NONE, IndexReduction, StructurallySingular
from .matching import UNMATCHED, augmenting_path

ALWAYS = math.inf
PREFER = 2.0
DEFAULT = 1.0
AVOID = 0.0
NEVER = -math.inf
FIXED_START_BONUS = 0.5
"""Added for a fixed start value: prefer > default + fixed > default > avoid + fixed."""

STATE_SELECT = {
    "always": ALWAYS,
    "prefer": PREFER,
    "default": DEFAULT,
    "avoid": AVOID,
    "never": NEVER,
}

DEFAULT_MAX_TRIES = 1000

IsNonsingular = Callable[[tuple[int, ...], tuple[int, ...]], bool]
"""``is_nonsingular(equations, variables)``: is this square Jacobian block regular?"""

Choose = Callable[[tuple[int, ...], tuple[int, ...], tuple[int, ...]], tuple[int, ...] | None]
"""``choose(equations, columns, tiers)``: the dummies among ``columns`` (priority order;
``tiers[k]`` numbers the priority class of ``columns[k]``, ascending), or None when no
choice is acceptable."""


class NumericallySingular(Exception):
    """The caller's ``is_nonsingular`` rejected every structurally regular choice.

    ``equations`` and ``variables`` are indices of the augmented system (those that
    were passed to ``is_nonsingular``).
    """

    def __init__(self, equations: Sequence[int], variables: Sequence[int], tries: int) -> None:
        self.equations = tuple(sorted(equations))
        self.variables = tuple(sorted(variables))
        super().__init__(
            f"no nonsingular choice of dummy derivatives among variables "
            f"{list(self.variables)} for equations {list(self.equations)} ({tries} tried)"
        )


@dataclass(frozen=True, slots=True)
class SelectedBlock:
    """One square block of the method: ``equations`` solved for the ``dummies``."""

    level: int
    equations: tuple[int, ...]
    dummies: tuple[int, ...]
    candidates: tuple[int, ...] = ()
    """All columns of the block, in priority order (the first becomes a dummy first)."""
    tiers: tuple[int, ...] = ()
    """Priority class of each candidate (equal priority and differentiation order)."""


@dataclass(frozen=True, slots=True)
class StateSelection:
    """The chosen states; indices refer to the augmented system.

    ``states[i]`` has the true derivative ``state_derivatives[i]``. Every other
    variable, the ``dummy_derivatives`` included, is algebraic. ``blocks`` lists
    the square Jacobian blocks that must be nonsingular for the choice to be valid.
    """

    states: tuple[int, ...]
    state_derivatives: tuple[int, ...]
    dummy_derivatives: tuple[int, ...]
    blocks: tuple[SelectedBlock, ...]


def state_priority(state_select: str = "default", fixed_start: bool = False) -> float:
    """The priority of a variable from its ``stateSelect`` and whether its start is fixed."""
    try:
        value = STATE_SELECT[state_select]
    except KeyError:
        raise ValueError(
            f"unknown stateSelect {state_select!r}; expected one of {sorted(STATE_SELECT)}"
        ) from None
    return value + FIXED_START_BONUS if fixed_start else value


def kept_by_preference(priorities: Sequence[float], dummies: Sequence[bool]) -> bool:
    """Are the candidates a block keeps as states exactly its preferred ones?

    ``priorities[k]`` is that of candidate k's state (see :func:`state_priority`),
    ``dummies[k]`` whether it became a dummy. As Modelica tools do, a block whose
    ``StateSelect.prefer`` (or ``always``) candidates are as many as the states it keeps,
    and which the selection could keep (a nonsingular block of the others), is a static
    choice: its states are never switched during a run.
    """
    preferred = [p >= PREFER for p in priorities]
    return any(preferred) and all(p != d for p, d in zip(preferred, dummies))


def dummy_derivatives(
    reduction: IndexReduction,
    priority: Sequence[float] | None = None,
    is_nonsingular: IsNonsingular | None = None,
    max_tries: int = DEFAULT_MAX_TRIES,
    choose: Choose | None = None,
) -> StateSelection:
    """Choose the dummy derivatives of ``reduction``; keep high-priority states.

    ``priority[v]`` (missing entries and variables created by Pantelides: ``DEFAULT``)
    ranks ``v`` as a state: ``der(v)`` is made a dummy before the derivatives of
    higher-priority variables. ``NEVER`` on ``v`` also pushes ``der(der(v))``, ...
    first, since keeping those would keep ``v``. Ties keep states of lower
    differentiation order (``vx`` rather than ``der(x)``), then of lower family index.
    ``max_tries`` bounds the column sets tried per block once ``is_nonsingular``
    rejected the best one. Raises :class:`StructurallySingular` (naming input indices
    of Pantelides, as there) when a level has no structurally regular choice, and
    :class:`NumericallySingular` when the caller rejects every choice tried.
    ``choose``, when given, replaces the greedy choice and ``is_nonsingular`` (see the
    module docstring); its choice must be structurally regular.
    """
    # Step 1: antiderivatives and the order in which columns become dummies.
    antiderivative = _inverse(reduction.var_derivative)
    parent_eq = _inverse(reduction.eq_derivative)
    key = _dummy_order(reduction.var_derivative, antiderivative, priority)
    # Step 2: level 1: highest-order equations obtained by differentiation.
    rows = [e for e, d in enumerate(reduction.eq_derivative) if d == NONE and parent_eq[e] != NONE]
    allowed = {
        v
        for e in rows
        for v in reduction.incidence[e]
        if reduction.var_derivative[v] == NONE and antiderivative[v] != NONE
    }
    # Step 3: choose per level and component; descend to the antiderivatives.
    blocks: list[SelectedBlock] = []
    level = 1
    while rows:
        chosen = _choose_level(reduction, level, rows, allowed, key, is_nonsingular, max_tries,
                               choose)
        blocks.extend(chosen)
        picked = [v for block in chosen for v in block.dummies]
        allowed = {antiderivative[v] for v in picked if antiderivative[antiderivative[v]] != NONE}
        rows = [parent_eq[e] for e in rows if parent_eq[parent_eq[e]] != NONE]
        level += 1
    # Step 4: states are the variables whose derivative stayed a true derivative.
    return _selection(reduction, blocks)


def _inverse(derivative: Sequence[int]) -> list[int]:
    """``inverse[derivative[i]] = i``; ``NONE`` where nothing derives to the index."""
    inverse = [NONE] * len(derivative)
    for i, d in enumerate(derivative):
        if d != NONE:
            inverse[d] = i
    return inverse


def _dummy_order(
    var_derivative: Sequence[int],
    antiderivative: Sequence[int],
    priority: Sequence[float] | None,
) -> Callable[[int], tuple[float, int, int, int]]:
    """Sort key of candidate columns: the first sorted becomes a dummy first.

    Making ``der(v)`` a dummy costs the state ``v``, so a column ranks by ``v``'s
    priority, but as ``NEVER`` if ``v`` or any variable it derives from is ``NEVER``
    (keeping ``der(v)`` would keep all of them states). Ties: high differentiation
    order first, then high family index (the lower-index family keeps its state),
    then high variable index.
    """
    n_var = len(var_derivative)
    values = list(priority or ())
    if len(values) > n_var:
        raise ValueError(f"{len(values)} priorities for {n_var} variables")
    values += [DEFAULT] * (n_var - len(values))
    root, order, lost = [NONE] * n_var, [0] * n_var, [DEFAULT] * n_var
    for start in (v for v in range(n_var) if antiderivative[v] == NONE):
        var, depth, never_below = start, 0, False
        while var != NONE:
            root[var], order[var] = start, depth
            if depth:
                below = antiderivative[var]
                never_below = never_below or values[below] == NEVER
                lost[var] = NEVER if never_below else values[below]
            var, depth = var_derivative[var], depth + 1
    return lambda v: (lost[v], -order[v], -root[v], -v)


def _choose_level(
    reduction: IndexReduction,
    level: int,
    rows: list[int],
    allowed: set[int],
    key: Callable[[int], tuple[float, int, int, int]],
    is_nonsingular: IsNonsingular | None,
    max_tries: int,
    choose: Choose | None = None,
) -> list[SelectedBlock]:
    """The dummies of one level, one block per connected component of rows x columns."""
    columns_of = {e: [v for v in reduction.incidence[e] if v in allowed] for e in rows}
    blocks = []
    for group in _components(rows, columns_of):
        rows_of: dict[int, list[int]] = {}
        for e in group:
            for v in columns_of[e]:
                rows_of.setdefault(v, []).append(e)
        columns = sorted(rows_of, key=key)
        tiers = _tiers(columns, key)
        dummies = _greedy(group, columns, rows_of)
        if len(dummies) < len(group):
            raise _singular(reduction, group, columns_of, level)
        if choose is not None:
            picked = choose(tuple(group), tuple(columns), tiers)
            if picked is None:
                raise NumericallySingular(group, columns, 1)
            if len(picked) != len(group) or len(_greedy(group, picked, rows_of)) < len(group):
                raise ValueError(f"choose returned a structurally singular block {picked}")
            dummies = tuple(picked)
        elif is_nonsingular is not None and not is_nonsingular(tuple(group), dummies):
            dummies = _search(group, columns, rows_of, dummies, is_nonsingular, max_tries)
        blocks.append(SelectedBlock(level, tuple(group), dummies, tuple(columns), tiers))
    return blocks


def _tiers(columns: Sequence[int], key: Callable[[int], tuple[float, int, int, int]]
           ) -> tuple[int, ...]:
    """Number the priority classes (priority and differentiation order) of ``columns``."""
    tiers: list[int] = []
    for k, column in enumerate(columns):
        same = k and key(column)[:2] == key(columns[k - 1])[:2]
        tiers.append(tiers[-1] if same else (tiers[-1] + 1 if tiers else 0))
    return tuple(tiers)


def _components(rows: list[int], columns_of: dict[int, list[int]]) -> list[list[int]]:
    """Rows grouped by connected component of the row-column graph, in row order."""
    parent = {e: e for e in rows}

    def find(e: int) -> int:
        while parent[e] != e:
            parent[e] = parent[parent[e]]
            e = parent[e]
        return e

    owner: dict[int, int] = {}
    for e in rows:
        for v in columns_of[e]:
            if v in owner:
                parent[find(e)] = find(owner[v])
            else:
                owner[v] = e
    groups: dict[int, list[int]] = {}
    for e in rows:
        groups.setdefault(find(e), []).append(e)
    return list(groups.values())


def _greedy(
    rows: Sequence[int], columns: Sequence[int], rows_of: dict[int, list[int]]
) -> tuple[int, ...]:
    """Columns taken in order whenever an augmenting path still matches them."""
    row_mate: dict[int, int] = {}
    taken = []
    for column in columns:
        if _assign(column, rows_of, row_mate):
            taken.append(column)
            if len(taken) == len(rows):
                break
    return tuple(taken)


def _assign(column: int, rows_of: dict[int, list[int]], row_mate: dict[int, int]) -> bool:
    """Match ``column`` by an augmenting path (:func:`augmenting_path`), if one exists."""
    found = augmenting_path(column, rows_of.__getitem__,
                            lambda row: row_mate.get(row, UNMATCHED))
    for col, row in found.pairs:
        row_mate[row] = col
    return bool(found.pairs)


def _search(
    rows: list[int],
    columns: list[int],
    rows_of: dict[int, list[int]],
    rejected: tuple[int, ...],
    is_nonsingular: IsNonsingular,
    max_tries: int,
) -> tuple[int, ...]:
    """The first structurally regular column set, in priority order, the caller accepts."""
    tried = 1
    for subset in itertools.combinations(columns, len(rows)):
        if tried >= max_tries:
            break
        if subset == rejected or len(_greedy(rows, subset, rows_of)) < len(rows):
            continue
        tried += 1
        if is_nonsingular(tuple(rows), subset):
            return subset
    raise NumericallySingular(rows, columns, tried)


def _singular(
    reduction: IndexReduction, rows: list[int], columns_of: dict[int, list[int]], level: int
) -> StructurallySingular:
    """The error for a level without a structurally regular choice."""
    return StructurallySingular(
        (reduction.origin(e)[0] for e in rows),
        (reduction.original_variable(v) for e in rows for v in reduction.incidence[e]),
        f"no regular choice of dummy derivatives at level {level} "
        f"(candidates {sorted({v for e in rows for v in columns_of[e]})})",
    )


def _selection(reduction: IndexReduction, blocks: list[SelectedBlock]) -> StateSelection:
    """Collect states and dummies from the chosen blocks."""
    dummies = {v for block in blocks for v in block.dummies}
    states = [v for v, d in enumerate(reduction.var_derivative) if d != NONE and d not in dummies]
    return StateSelection(
        states=tuple(states),
        state_derivatives=tuple(reduction.var_derivative[v] for v in states),
        dummy_derivatives=tuple(sorted(dummies)),
        blocks=tuple(blocks),
    )
