"""Alias and trivial-equation elimination: dae.DAE -> (dae.DAE, aliases, warnings).

An equation ``a = b``, ``a = -b`` (``a + b = 0``) or ``a = p`` (a constant or parameter
expression) removes one unknown. Chains are followed with a signed union-find; in each
class the kept variable is the one that ranks highest as a state
(:func:`~springc.simplify.index_reduction.unknown_priority`: ``stateSelect``, a fixed
start, a start value), then one that appears differentiated, then the first declared.
Eliminated variables become observed: ``a = ±kept`` or ``a = value``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..errors import Note
from ..ir import dae
from ..ir import expr as x
from .index_reduction import unknown_priority
from .isolate import fold, free_variables
from .lower import differentiate


@dataclass(frozen=True, slots=True)
class Alias:
    """An eliminated unknown and its value: ``sign * kept`` or a parameter expression."""

    name: str
    value: x.Expr
    equation: dae.Residual


@dataclass(frozen=True)
class AliasResult:
    dae: dae.DAE
    aliases: tuple[Alias, ...]
    warnings: tuple[Note, ...]


def _terms(e: x.Expr, sign: int, unknowns: set[str], out: list[tuple[int, str]],
           rest: list[tuple[int, x.Expr]]) -> bool:
    """Split ``e`` into ±unknown terms and a remainder free of unknowns, left to right.

    Iterative: a sum that flattening built from ``sum(z)`` may have tens of thousands
    of terms."""
    pending: list[tuple[x.Expr, int]] = [(e, sign)]
    while pending:
        e, sign = pending.pop()
        if isinstance(e, x.BinOp) and e.op in "+-":
            pending.append((e.right, sign if e.op == "+" else -sign))
            pending.append((e.left, sign))
        elif isinstance(e, x.Neg):
            pending.append((e.arg, -sign))
        elif isinstance(e, x.Var) and e.name in unknowns:
            out.append((sign, e.name))
            if len(out) > 2:
                return False
        elif any(n in unknowns or dae.is_derivative(n) for n in free_variables(e)) or any(
                isinstance(n, x.Time) for n in x.walk(e)):
            return False
        else:
            rest.append((sign, e))
    return True


def _signed_sum(terms: list[tuple[int, x.Expr]]) -> x.Expr:
    """``t1 ± t2 ± ...``, kept shallow for long runs as flatten's ``sum`` is."""
    return x.fold_chunked(
        terms, lambda value, st: x.add(value, st[1]) if st[0] == 1 else x.sub(value, st[1]),
        x.add, x.ZERO)


def _classify(r: dae.Residual, unknowns: set[str]
              ) -> tuple[str, str, int, x.Expr] | None:
    """``(a, b, sign, 0)`` for ``a = sign*b``, ``(a, "", 0, value)`` for ``a = value``."""
    count = 0  # one loop over the names: this runs for every equation, twice
    for n in r.variables:
        if dae.is_derivative(n):
            return None
        count += n in unknowns
    if count > 2:
        return None
    terms: list[tuple[int, str]] = []
    rest: list[tuple[int, x.Expr]] = []
    if not _terms(r.expr, 1, unknowns, terms, rest):
        return None
    rest = [(sign, e) for sign, e in rest if e != x.ZERO]  # left by a substitution
    if len(terms) == 2 and not rest and terms[0][1] != terms[1][1]:
        (sa, a), (sb, b) = terms
        return a, b, -sa * sb, x.ZERO
    if len(terms) == 1:
        (sa, a), = terms
        value = _signed_sum(rest)
        return a, "", 0, value if sa == -1 else x.neg(value)
    return None


def eliminate_aliases(system: dae.DAE) -> AliasResult:
    """Remove alias and trivial equations; see the module docstring."""
    unknowns = {u.name: u for u in system.unknowns}
    order = {u.name: i for i, u in enumerate(system.unknowns)}
    names = set(unknowns)
    # Step 1: classify equations and join alias classes (signed union-find).
    parent, value_of, members_eq, kept = _join_classes(system.equations, names)

    # Step 2: pick the kept variable of each class and express the others through it.
    classes: dict[str, list[tuple[str, int]]] = {}
    for name in unknowns:
        root, sign = _find(parent, name)
        classes.setdefault(root, []).append((name, sign))
    mapping: dict[str, x.Expr] = {}
    aliases: list[Alias] = []
    warnings: list[Note] = []
    new_unknowns: dict[str, dae.Unknown] = {}
    differentiated = set(system.differentiated)
    for root, members in classes.items():
        if root in value_of:
            value, eq = value_of[root]
            for name, sign in members:
                mapping[name] = x.neg(value) if sign == -1 else value
                aliases.append(Alias(name, mapping[name], members_eq.get(name, eq)))
            continue
        if len(members) == 1:
            continue
        rep, rep_sign = max(members, key=lambda m: _priority(unknowns[m[0]], differentiated,
                                                             order))
        warnings += _start_conflicts(members, rep, rep_sign, unknowns)
        for name, sign in members:
            if name == rep:
                continue
            rel = sign * rep_sign  # name = rel * rep
            mapping[name] = x.Var(rep) if rel == 1 else x.neg(x.Var(rep))
            aliases.append(Alias(name, mapping[name], members_eq.get(name) or
                                 members_eq.get(root) or system.equations[0]))
        new_unknowns[rep] = _inherit_start(unknowns[rep], members, rep_sign, unknowns)

    # Step 3: substitute into the remaining equations (derivatives too).
    der_map: dict[str, x.Expr] = {}

    def varying(name: str) -> bool:
        return name in names or dae.is_derivative(name)

    for name, value in mapping.items():
        if name in differentiated:
            der_map[dae.derivative_name(name)] = differentiate(value, varying)
            differentiated.update(v for v in free_variables(value) if v in names)
    full = {**mapping, **der_map}
    value_vars = {name: free_variables(value) for name, value in full.items()}

    def rewrite(r: dae.Residual) -> dae.Residual:
        used = [n for n in r.variables if n in full]
        if not used:
            return r
        names = set(r.variables).difference(used).union(*(value_vars[n] for n in used))
        held = r.pre_only.difference(used).difference(*(value_vars[n] for n in used))
        expr = x.substitute(r.expr, full)
        if any(isinstance(full[n], x.Const) for n in used):
            # a constant may remove terms: `c*der(v)` with `c = 0` (an evaluated
            # parameter) no longer reads der(v), and v is no state for it
            expr = fold(expr)
            present = free_variables(expr)
            names &= present
            held = held.intersection(present)
        return replace(r, expr=expr, variables=frozenset(names), pre_only=held)

    equations = tuple(rewrite(r) for r in kept)
    initial = tuple(rewrite(r) for r in system.initial_equations)
    remaining = tuple(new_unknowns.get(u.name, u) for u in system.unknowns
                      if u.name not in mapping)
    differentiated -= set(mapping)
    differentiated &= {dae.derivative_base(n) for r in equations + initial
                       for n in r.variables}
    reduced = replace(system, unknowns=remaining, equations=equations,
                      initial_equations=initial, differentiated=frozenset(differentiated))
    # Step 4: a substitution may have made an alias of a kept equation (``s = f - z``
    # with ``z = 0``): eliminate again, and express the first aliases through what is
    # left (observed values name only unknowns).
    # Only a rewritten equation can have become one: the others read no eliminated
    # name, so ``_classify`` sees them in ``left`` as it did in ``names``, where it found
    # nothing (a kept equation it classified reads an eliminated name: rewritten).
    left = {u.name for u in remaining}
    if mapping and any(_classify(r, left) is not None
                       for r, before in zip(equations, kept) if r is not before):
        again = eliminate_aliases(reduced)
        later = {a.name: a.value for a in again.aliases}
        earlier = tuple(replace(a, value=x.substitute(a.value, later)) for a in aliases)
        return AliasResult(again.dae, again.aliases + earlier,
                           tuple(warnings) + again.warnings)
    return AliasResult(reduced, tuple(aliases), tuple(warnings))


Classes = tuple[dict[str, tuple[str, int]], dict[str, tuple[x.Expr, dae.Residual]],
                dict[str, dae.Residual], list[dae.Residual]]
"""A signed union-find's parents, each class's value (with its equation), the equation
that joined each member, and the equations kept."""


def _find(parent: dict[str, tuple[str, int]], a: str) -> tuple[str, int]:
    """The root of ``a``'s class and the sign of ``a`` against it."""
    sign = 1
    while a in parent:
        a, s = parent[a]
        sign *= s
    return a, sign


def _join_classes(equations: tuple[dae.Residual, ...], names: set[str]) -> Classes:
    """Classify ``equations`` and join the alias classes they state."""
    parent: dict[str, tuple[str, int]] = {}
    value_of: dict[str, tuple[x.Expr, dae.Residual]] = {}
    members_eq: dict[str, dae.Residual] = {}
    kept: list[dae.Residual] = []
    for r in equations:
        found = _classify(r, names)
        if found is None:
            kept.append(r)
            continue
        a, b, sign, value = found
        ra, sa = _find(parent, a)
        if not b:
            if ra in value_of:
                kept.append(r)  # a second value for the class: leave it to the checks
                continue
            value_of[ra] = (x.neg(value) if sa == -1 else value, r)
            continue
        rb, sb = _find(parent, b)
        if ra == rb or (ra in value_of and rb in value_of):
            kept.append(r)
            continue
        # a = sign*b, a = sa*ra, b = sb*rb  =>  rb = sa*sign*sb * ra
        parent[rb] = (ra, sa * sign * sb)
        members_eq[rb] = r
        if rb in value_of:
            v, eq = value_of.pop(rb)
            value_of[ra] = (x.neg(v) if sa * sign * sb == -1 else v, eq)
    return parent, value_of, members_eq, kept


def _priority(u: dae.Unknown, differentiated: set[str], order: dict[str, int]
              ) -> tuple[float, int, int]:
    return unknown_priority(u), int(u.name in differentiated), -order[u.name]


def _start_conflicts(members: list[tuple[str, int]], rep: str, rep_sign: int,
                     unknowns: dict[str, dae.Unknown]) -> list[Note]:
    seen: dict[float, str] = {}
    for name, sign in members:
        start = unknowns[name].start
        if isinstance(start, x.Const):
            seen.setdefault(float(start.value) * sign * rep_sign, name)
    if len(seen) <= 1:
        return []
    listing = ", ".join(f"{name} = {value:g}" for value, name in seen.items())
    return [Note(f"aliases of '{rep}' have conflicting start values ({listing}); "
                 f"'{rep}' keeps its own", unknowns[rep].span)]


def _inherit_start(rep: dae.Unknown, members: list[tuple[str, int]], rep_sign: int,
                   unknowns: dict[str, dae.Unknown]) -> dae.Unknown:
    """A kept variable without a start value takes a member's (fixed ones first)."""
    if rep.start is not None:
        return rep
    candidates = sorted((m for m in members if unknowns[m[0]].start is not None),
                        key=lambda m: not unknowns[m[0]].fixed)
    if not candidates:
        return rep
    name, sign = candidates[0]
    start = unknowns[name].start
    assert start is not None
    rel = sign * rep_sign
    return replace(rep, start=start if rel == 1 else x.neg(start),
                   fixed=rep.fixed or unknowns[name].fixed)
