"""Integer DAE structure -> IndexReduction: Pantelides' choice of equations to differentiate.

Input: ``incidence``, ``var_derivative``, ``eq_derivative`` and ``n_var`` as below, plus
an optional hook giving the exact incidence of a differentiated equation.
Output: :class:`IndexReduction`, the augmented structure whose highest-derivative
variables are perfectly matched to its highest-derivative equations, or
:class:`StructurallySingular` when no number of differentiations achieves that.

Representation (integers only; no sympy here, the caller differentiates symbolically):

- Variables are ``0..n_var-1``. ``var_derivative[v]`` is the variable that is
  ``der(v)``, or ``-1``. Derivatives are variables too, so ``x -> der(x) -> der(der(x))``
  is a chain; the chain starting at a variable nobody derives from is its *family*.
- Equations are ``0..n_eq-1``; ``incidence[e]`` lists the variables of ``e`` and
  ``eq_derivative[e]`` is the equation that is ``d/dt`` of ``e``, or ``-1``.
- Only *highest* derivatives are unknowns of the matching: a variable ``v`` with
  ``var_derivative[v] != -1`` is never matched (it is a candidate state, known from
  integration). Likewise only equations with ``eq_derivative[e] == -1`` are matched;
  a differentiated equation is represented by its derivative.

Differentiating ``e`` appends a new equation whose structural incidence is every
``v`` of ``e`` (conservatively) plus ``der(v)``; ``der(v)`` is appended as a new
variable when ``var_derivative[v] == -1``. A :data:`DifferentiateEquation` hook may
return the exact incidence instead (a subset of that rule).

Cost: O(n_eq + n_var + nnz) when the initial maximum matching (Hopcroft-Karp in scipy)
is already perfect, which is the common index-1 case; otherwise each still unmatched
equation runs coloured augmenting-path searches (iterative depth-first, as in
Pantelides 1988 and ModelingToolkit's ``pantelides.jl``) over the part it reaches.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass

from .matching import augmenting_path, dulmage_mendelsohn, maximum_matching

NONE = -1
"""Marks a missing derivative or an unmatched vertex."""

DEFAULT_MAX_STEPS = 100

DifferentiateEquation = Callable[[int, Sequence[int]], Iterable[int]]
"""``hook(eq, var_derivative) -> incidence of d/dt(eq)``.

Called once per new equation, in the order of the new equation indices (so the new
equation is ``len(incidence)`` at call time). ``der(v)`` already exists for every
``v`` of ``eq`` and can be read from the read-only ``var_derivative``. The result must
be a subset of ``incidence[eq]`` and the derivatives of its variables.
"""


class StructurallySingular(Exception):
    """No matching covers the equations, however often they are differentiated.

    ``equations`` and ``variables`` are sorted indices of the system given to
    :func:`pantelides` (never of variables or equations it created): the
    overdetermined equations and the variables they contain.
    """

    def __init__(self, equations: Iterable[int], variables: Iterable[int], reason: str) -> None:
        self.equations = tuple(sorted(set(equations)))
        self.variables = tuple(sorted(set(variables)))
        self.reason = reason
        super().__init__(
            f"structurally singular: {reason}; equations {list(self.equations)}, "
            f"variables {list(self.variables)}"
        )


@dataclass(frozen=True, slots=True)
class IndexReduction:
    """The augmented structure after Pantelides' algorithm.

    Equations ``n_original_eq..n_eq-1`` and variables ``n_original_var..n_var-1`` were
    created here. ``differentiated[k]`` is the equation whose derivative is equation
    ``n_original_eq + k`` (always a smaller index, so symbolic differentiation can run
    in index order). ``eq_to_var`` and ``var_to_eq`` match the highest-derivative
    equations and variables; every other entry is ``-1``.
    """

    incidence: tuple[tuple[int, ...], ...]
    var_derivative: tuple[int, ...]
    eq_derivative: tuple[int, ...]
    n_var: int
    eq_to_var: tuple[int, ...]
    var_to_eq: tuple[int, ...]
    differentiated: tuple[int, ...]
    n_original_eq: int
    n_original_var: int

    @property
    def n_eq(self) -> int:
        """The number of equations, original and differentiated."""
        return len(self.incidence)

    def origin(self, eq: int) -> tuple[int, int]:
        """``(original equation, order)``: ``eq`` is d^order/dt^order of the original."""
        order = 0
        while eq >= self.n_original_eq:
            eq = self.differentiated[eq - self.n_original_eq]
            order += 1
        return eq, order

    def original_variable(self, var: int) -> int:
        """The input variable that ``var`` is a (repeated) derivative of, or ``var``."""
        if var < self.n_original_var:
            return var
        antiderivative = {d: v for v, d in enumerate(self.var_derivative) if d != NONE}
        while var >= self.n_original_var:
            var = antiderivative[var]
        return var

    def differentiation_counts(self) -> dict[int, int]:
        """How many times each original equation was differentiated (only those > 0)."""
        counts: dict[int, int] = {}
        for eq in range(self.n_original_eq, self.n_eq):
            original, order = self.origin(eq)
            counts[original] = max(counts.get(original, 0), order)
        return counts


def pantelides(
    incidence: Sequence[Sequence[int]],
    var_derivative: Sequence[int],
    eq_derivative: Sequence[int],
    n_var: int,
    differentiate_equation: DifferentiateEquation | None = None,
    max_steps: int = DEFAULT_MAX_STEPS,
) -> IndexReduction:
    """Differentiate equations until the highest derivatives have a perfect matching.

    ``max_steps`` bounds how often the search started from one equation may
    differentiate (roughly the index). Raises :class:`StructurallySingular` when some
    equations can never be matched, ``ValueError`` for an inconsistent input.
    """
    # Step 1: check the input and compute each variable's family.
    _check_input(incidence, var_derivative, eq_derivative, n_var)
    family = _chain_roots(var_derivative, "variable")
    _chain_roots(eq_derivative, "equation")
    # Step 2: maximum matching of the active equations to the highest derivatives.
    eq_to_var = _initial_matching(incidence, var_derivative, eq_derivative, n_var)
    unmatched = [e for e, v in enumerate(eq_to_var) if v == NONE and eq_derivative[e] == NONE]
    # Step 3: fast path: already perfect for the equations (index <= 1).
    if not unmatched:
        return _unchanged(incidence, var_derivative, eq_derivative, n_var, eq_to_var)
    # Step 4: Pantelides terminates iff the equations match distinct families.
    _check_families(incidence, eq_derivative, family, n_var)
    # Step 5: differentiate until each unmatched equation (or its derivative) matches.
    work = _Work(incidence, var_derivative, eq_derivative, n_var, eq_to_var)
    for root in unmatched:
        _reduce(work, root, differentiate_equation, max_steps)
    return work.result()


def _check_input(
    incidence: Sequence[Sequence[int]],
    var_derivative: Sequence[int],
    eq_derivative: Sequence[int],
    n_var: int,
) -> None:
    """Raise ``ValueError`` for mismatched lengths or indices out of range."""
    if len(var_derivative) != n_var:
        raise ValueError(f"var_derivative has {len(var_derivative)} entries, n_var is {n_var}")
    if len(eq_derivative) != len(incidence):
        raise ValueError(
            f"eq_derivative has {len(eq_derivative)} entries for {len(incidence)} equations"
        )
    for what, targets, size in (
        ("var_derivative", var_derivative, n_var),
        ("eq_derivative", eq_derivative, len(incidence)),
    ):
        bad = [i for i, t in enumerate(targets) if not NONE <= t < size or t == i]
        if bad:
            raise ValueError(f"{what}[{bad[0]}] = {targets[bad[0]]} is not a valid index")


def _chain_roots(derivative: Sequence[int], what: str) -> list[int]:
    """For each index, the start of its derivative chain; rejects shared or cyclic chains."""
    antiderivative = [NONE] * len(derivative)
    for i, d in enumerate(derivative):
        if d == NONE:
            continue
        if antiderivative[d] != NONE:
            raise ValueError(f"{what} {d} is the derivative of both {antiderivative[d]} and {i}")
        antiderivative[d] = i
    roots = [NONE] * len(derivative)
    for start in (i for i, a in enumerate(antiderivative) if a == NONE):
        i = start
        while i != NONE:
            roots[i] = start
            i = derivative[i]
    if NONE in roots:
        raise ValueError(f"{what} {roots.index(NONE)} is its own repeated derivative")
    return roots


def _initial_matching(
    incidence: Sequence[Sequence[int]],
    var_derivative: Sequence[int],
    eq_derivative: Sequence[int],
    n_var: int,
) -> list[int]:
    """Maximum matching of active equations to highest-derivative variables (scipy)."""
    _check_variables(incidence, n_var)
    highest = [d == NONE for d in var_derivative]
    unknowns = [
        [v for v in row if highest[v]] if eq_derivative[e] == NONE else []
        for e, row in enumerate(incidence)
    ]
    return list(maximum_matching(unknowns, n_var).eq_to_var)


def _check_variables(incidence: Sequence[Sequence[int]], n_var: int) -> None:
    """Raise ``ValueError`` for a variable index outside ``0..n_var-1``."""
    for e, row in enumerate(incidence):
        if row and (min(row) < 0 or max(row) >= n_var):
            raise ValueError(f"equation {e} has a variable index outside 0..{n_var - 1}")


def _check_families(
    incidence: Sequence[Sequence[int]],
    eq_derivative: Sequence[int],
    family: Sequence[int],
    n_var: int,
) -> None:
    """Raise StructurallySingular unless active equations match distinct families.

    Differentiating never adds a family, so this is the termination criterion of
    Pantelides' algorithm; the overdetermined Dulmage-Mendelsohn part names the culprits.
    """
    by_family = [
        [family[v] for v in row] if eq_derivative[e] == NONE else []
        for e, row in enumerate(incidence)
    ]
    matching = maximum_matching(by_family, n_var)
    eq_to_family = matching.eq_to_var
    blocked = [e for e, f in enumerate(eq_to_family) if f == NONE and eq_derivative[e] == NONE]
    if not blocked:
        return
    over = dulmage_mendelsohn(by_family, n_var, matching).over_equations
    culprits = sorted(set(over) | set(blocked))
    variables = {v for e in culprits for v in incidence[e]}
    raise StructurallySingular(
        culprits, variables, "more equations than unknowns, even counting derivatives"
    )


def _unchanged(
    incidence: Sequence[Sequence[int]],
    var_derivative: Sequence[int],
    eq_derivative: Sequence[int],
    n_var: int,
    eq_to_var: Sequence[int],
) -> IndexReduction:
    """The result of the fast path: the input with its matching."""
    var_to_eq = [NONE] * n_var
    for e, v in enumerate(eq_to_var):
        if v != NONE:
            var_to_eq[v] = e
    return IndexReduction(
        incidence=tuple(map(tuple, incidence)),
        var_derivative=tuple(var_derivative),
        eq_derivative=tuple(eq_derivative),
        n_var=n_var,
        eq_to_var=tuple(eq_to_var),
        var_to_eq=tuple(var_to_eq),
        differentiated=(),
        n_original_eq=len(incidence),
        n_original_var=n_var,
    )


class _ReadOnly(Sequence[int]):
    """A read-only view of a growing list, handed to the differentiation hook."""

    __slots__ = ("_items",)

    def __init__(self, items: list[int]) -> None:
        self._items = items

    def __len__(self) -> int:
        return len(self._items)

    def __getitem__(self, index: int) -> int:  # type: ignore[override]
        return self._items[index]

    def __iter__(self) -> Iterator[int]:
        return iter(self._items)


class _Work:
    """The mutable working structure of one Pantelides run (never escapes it)."""

    def __init__(
        self,
        incidence: Sequence[Sequence[int]],
        var_derivative: Sequence[int],
        eq_derivative: Sequence[int],
        n_var: int,
        eq_to_var: Sequence[int],
    ) -> None:
        self.n_original_eq = len(incidence)
        self.n_original_var = n_var
        self.incidence: list[tuple[int, ...]] = [tuple(row) for row in incidence]
        self.var_derivative = list(var_derivative)
        self.eq_derivative = list(eq_derivative)
        self.eq_to_var = list(eq_to_var)
        self.var_to_eq = [NONE] * n_var
        for e, v in enumerate(self.eq_to_var):
            if v != NONE:
                self.var_to_eq[v] = e
        self.differentiated: list[int] = []
        self.antiderivative = [NONE] * n_var
        for v, d in enumerate(self.var_derivative):
            if d != NONE:
                self.antiderivative[d] = v

    def match(self, eq: int, var: int) -> None:
        self.eq_to_var[eq] = var
        self.var_to_eq[var] = eq

    def derivative_of_variable(self, var: int) -> int:
        """``der(var)``, appended as a new variable if missing."""
        if self.var_derivative[var] == NONE:
            new = len(self.var_derivative)
            self.var_derivative[var] = new
            self.var_derivative.append(NONE)
            self.var_to_eq.append(NONE)
            self.antiderivative.append(var)
        return self.var_derivative[var]

    def differentiate(self, eq: int, hook: DifferentiateEquation | None) -> int:
        """Append ``d/dt(eq)``; every variable of ``eq`` must already have a derivative."""
        row = self.incidence[eq]
        structural = sorted(set(row) | {self.var_derivative[v] for v in row})
        if hook is None:
            new_row = tuple(structural)
        else:
            new_row = tuple(sorted(set(hook(eq, _ReadOnly(self.var_derivative)))))
            if not set(new_row) <= set(structural):
                raise ValueError(
                    f"the derivative of equation {eq} may only contain {structural}, "
                    f"the hook returned {list(new_row)}"
                )
        new = len(self.incidence)
        self.incidence.append(new_row)
        self.eq_derivative.append(NONE)
        self.eq_to_var.append(NONE)
        self.eq_derivative[eq] = new
        self.differentiated.append(eq)
        return new

    def original_variable(self, var: int) -> int:
        while var >= self.n_original_var:
            var = self.antiderivative[var]
        return var

    def original_equation(self, eq: int) -> int:
        while eq >= self.n_original_eq:
            eq = self.differentiated[eq - self.n_original_eq]
        return eq

    def result(self) -> IndexReduction:
        return IndexReduction(
            incidence=tuple(self.incidence),
            var_derivative=tuple(self.var_derivative),
            eq_derivative=tuple(self.eq_derivative),
            n_var=len(self.var_derivative),
            eq_to_var=tuple(self.eq_to_var),
            var_to_eq=tuple(self.var_to_eq),
            differentiated=tuple(self.differentiated),
            n_original_eq=self.n_original_eq,
            n_original_var=self.n_original_var,
        )


def _reduce(work: _Work, root: int, hook: DifferentiateEquation | None, max_steps: int) -> None:
    """Differentiate the coloured subgraph until an augmenting path from ``root`` exists."""
    for step in range(max_steps + 1):
        found, eqs, variables = _augment(work, root)
        if found:
            return
        if step == max_steps:
            break
        root = _differentiate_coloured(work, root, eqs, variables, hook)
    raise StructurallySingular(
        map(work.original_equation, eqs),
        map(work.original_variable, {v for e in eqs for v in work.incidence[e]}),
        f"still unmatched after differentiating {max_steps} times",
    )


def _augment(work: _Work, root: int) -> tuple[bool, tuple[int, ...], tuple[int, ...]]:
    """Coloured augmenting-path search from the unmatched equation ``root`` over
    active equations and highest derivatives (:func:`augmenting_path`). On success
    the path is flipped into the matching; either way the coloured (visited)
    equations and variables are returned."""
    var_derivative, var_to_eq = work.var_derivative, work.var_to_eq
    found = augmenting_path(root, work.incidence.__getitem__, var_to_eq.__getitem__,
                            lambda var: var_derivative[var] == NONE)
    for eq, var in found.pairs:
        work.match(eq, var)
    return bool(found.pairs), found.left, found.right


def _differentiate_coloured(
    work: _Work,
    root: int,
    eqs: Sequence[int],
    variables: Sequence[int],
    hook: DifferentiateEquation | None,
) -> int:
    """Differentiate the coloured equations, promote the coloured variables to
    their derivatives, carry the matching along; return the new root."""
    for var in variables:
        work.derivative_of_variable(var)
    for eq in eqs:
        work.differentiate(eq, hook)
    for var in variables:
        eq = work.var_to_eq[var]
        work.var_to_eq[var] = NONE
        work.eq_to_var[eq] = NONE
        work.match(work.eq_derivative[eq], work.var_derivative[var])
    return work.eq_derivative[root]
