"""Walks over syntax trees for the static rules: the statements of an algorithm, the
equations nested in for- and if-equations, the expressions of statements and
modifications, the component references of an expression. Input: ``ir.syntax`` nodes;
output: iterators over nodes."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import fields, is_dataclass

from ...ir import syntax as s


def statements(body: tuple[s.Statement, ...]) -> Iterator[s.Statement]:
    for stmt in body:
        yield stmt
        if isinstance(stmt, s.ForStatement):
            yield from statements(stmt.body)
        elif isinstance(stmt, s.IfStatement):
            for _, branch in stmt.branches:
                yield from statements(branch)
            yield from statements(stmt.otherwise)
        elif isinstance(stmt, (s.WhileStatement, s.WhenStatement)):
            for branch in ([stmt.body] if isinstance(stmt, s.WhileStatement)
                           else [b for _, b in stmt.branches]):
                yield from statements(branch)


def equations(body: tuple[s.Equation, ...]) -> Iterator[s.Equation]:
    """The equations of ``body`` and those nested in its for- and if-equations, each
    before the ones inside it (not into when-equations)."""
    for item in body:
        yield item
        if isinstance(item, s.ForEquation):
            yield from equations(item.body)
        elif isinstance(item, s.IfEquation):
            for _, branch in item.branches:
                yield from equations(branch)
            yield from equations(item.otherwise)


def mod_values(mod: s.Modification | None) -> list[s.Expr]:
    if mod is None:
        return []
    out = [mod.value] if mod.value is not None else []
    for arg in mod.arguments:
        out += mod_values(arg.modification)
    return out


def statement_exprs(stmt: s.Statement) -> list[s.Expr]:
    if isinstance(stmt, s.Assign):
        return [stmt.value]
    if isinstance(stmt, (s.IfStatement, s.WhenStatement)):
        return [c for c, _ in stmt.branches]
    if isinstance(stmt, s.ForStatement):
        return [i.range for i in stmt.indices if i.range is not None]
    return []


def refs(e: object) -> Iterator[s.Ref]:
    """Every component reference inside a syntax expression (function names excluded)."""
    if isinstance(e, s.Ref):
        yield e
        for part in e.parts:
            for sub in part.subscripts:
                yield from refs(sub)
    elif isinstance(e, s.Call):
        for arg in e.args:
            yield from refs(arg)
        for named in e.named:
            yield from refs(named.value)
    elif isinstance(e, s.Unary):
        yield from refs(e.operand)
    elif isinstance(e, s.FieldOf):
        yield from refs(e.record)
    elif isinstance(e, s.Binary):
        yield from refs(e.left)
        yield from refs(e.right)
    elif isinstance(e, s.IfExpr):
        for cond, value in e.branches:
            yield from refs(cond)
            yield from refs(value)
        yield from refs(e.otherwise)
    elif isinstance(e, s.ArrayLit):
        for item in e.items:
            yield from refs(item)
    elif isinstance(e, s.MatrixLit):
        for row in e.rows:
            for item in row:
                yield from refs(item)
    elif isinstance(e, s.Range):
        for bound in (e.start, e.step, e.stop):
            yield from refs(bound)
    elif isinstance(e, s.Comprehension):
        yield from refs(e.body)
        for index in e.indices:
            yield from refs(index.range)


def same_text(a: object, b: object) -> bool:
    """Whether two syntax nodes are the same text up to where they are written."""
    if type(a) is not type(b):
        return False
    if is_dataclass(a):
        return all(f.name == "span" or same_text(getattr(a, f.name), getattr(b, f.name))
                   for f in fields(a))
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(map(same_text, a, b))
    return a == b

