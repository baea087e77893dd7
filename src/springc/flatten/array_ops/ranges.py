"""Deduced ``for`` ranges (section 11.2.2.1): ``for i loop ... x[i] ... end for``.

Input: a loop index without a range and the loop body. Output: the index with the
range ``1:n``, ``n`` being the size of every array dimension the index subscripts
directly in the body (``x[i]``, ``a[i].b``, ``m[j, i]``); the sizes must agree. A
dimension declared ``[Boolean]`` or ``[E]`` gives the range ``false:true`` or ``E``.

Also the ranges of Boolean and enumeration values: ``false:true``, ``E.a:E.c``, and
the type names ``Boolean`` and ``E`` as ranges.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from ...errors import FlattenError, Note, Span
from ...ir import expr as x
from ...ir import syntax as s
from .. import arrays as a
from ..scopes import (
    ClassScope,
    DimensionKind,
    Enumeration,
    EnumLiteral,
    ExpressionEvaluator,
    FlattenContext,
    Primitive,
    Scope,
    kind_name,
    literal_values,
    value_kind,
)
from .dimensions import typed_dimension


def with_range(ev: ExpressionEvaluator, index: s.ForIndex, body: object, scope: Scope
               ) -> s.ForIndex:
    """``index`` itself if it has a range, else with the range deduced from ``body``."""
    if index.range is not None:
        return index
    sizes: list[tuple[int, DimensionKind, Span]] = []
    for ref, k, d in _uses(index.name, body):
        sizes.append((_size(ev, ref, k, d, scope), _kind(ev, ref, k, d, scope), ref.span))
    if not sizes:
        raise FlattenError(f"cannot deduce the range of '{index.name}': it is not used as "
                           "a subscript of an array in the loop", index.span,
                           hint=f"give the range: 'for {index.name} in 1:n'")
    n, kind, first = sizes[0]
    for m, other, span in sizes[1:]:
        if m != n:
            raise FlattenError(f"the range of '{index.name}' cannot be deduced: it "
                               f"subscripts dimensions of sizes {n} and {m}", index.span,
                               [Note(f"size {n} here", first), Note(f"size {m} here", span)],
                               hint=f"give the range: 'for {index.name} in 1:{n}'")
        if other != kind:
            raise FlattenError(f"the range of '{index.name}' cannot be deduced: it "
                               f"subscripts dimensions indexed by {kind_name(kind)} and "
                               f"by {kind_name(other)} values", index.span,
                               [Note(f"{kind_name(kind)} here", first),
                                Note(f"{kind_name(other)} here", span)],
                               hint="a deduced range needs dimensions of one size and kind "
                               "(Modelica 3.6, section 11.2.2.1)")
    return s.ForIndex(index.name, _range_of(kind, n, index.span), index.span)


def _range_of(kind: DimensionKind, n: int, span: Span) -> s.Expr:
    """The range of a dimension: ``1:n``, ``false:true``, or an enumeration type."""
    if kind is None:
        return s.Range(s.Number(1, span), None, s.Number(n, span), span)
    if isinstance(kind, str):
        return s.Range(s.Bool(False, span), None, s.Bool(True, span), span)
    return TypeRange((s.RefPart(kind.name, (), span),), span, False, kind)


@dataclass(frozen=True, slots=True)
class TypeRange(s.Ref):
    """The range of a deduced index over a dimension ``[E]``: the enumeration itself
    (its name need not be visible where the loop is)."""

    enumeration: Enumeration | None = None


def type_range(ctx: FlattenContext, ref: s.Ref, scope: Scope) -> list[x.Expr] | None:
    """``for b in Boolean``, ``for e in E``: every value of the type in order; None if
    ``ref`` does not name Boolean or an enumeration type (section 11.2.2.2)."""
    if isinstance(ref, TypeRange) and ref.enumeration is not None:
        return literal_values(ref.enumeration)
    typed = typed_dimension(ctx, ref, scope)
    kind = typed[1] if typed is not None else None
    if isinstance(kind, str):
        return [x.Const(False), x.Const(True)]
    return literal_values(kind) if kind is not None else None


def typed_range_bounds(start: object, stop: object, e: s.Range) -> bool:
    """Whether ``start:stop`` is a range of Boolean or enumeration values (section
    10.4.3); such a range has no step, and both bounds are of one type."""
    kinds = value_kind(start), value_kind(stop)
    if kinds == (None, None):
        return False
    if kinds[0] != kinds[1]:
        raise FlattenError(f"the bounds of a range are of different types: "
                           f"{kind_name(kinds[0])} and {kind_name(kinds[1])}", e.span,
                           hint="both bounds are Integers or Reals, both Booleans, or both "
                           "literals of one enumeration (Modelica 3.6, section 10.4.3)")
    if e.step is not None:
        raise FlattenError(f"a range of {kind_name(kinds[0])} values has no step", e.step.span,
                           hint="write 'a:b' (Modelica 3.6, section 10.4.3)")
    return True


def typed_range(start: object, stop: object) -> list[x.Expr]:
    """The values ``start:stop`` of a Boolean or enumeration range, in order."""
    if isinstance(start, EnumLiteral):
        return literal_values(start.enumeration)[int(start) - 1:int(stop)]  # type: ignore[call-overload]
    return [x.Const(bool(v)) for v in range(int(bool(start)), int(bool(stop)) + 1)]


def _kind(ev: ExpressionEvaluator, ref: s.Ref, k: int, d: int, scope: Scope
          ) -> DimensionKind:
    """The kind of dimension ``d`` of part ``k`` of ``ref`` (Integer, Boolean or an
    enumeration); only primitive variables have dimensions of other kinds."""
    name, span = ref.parts[k].name, ref.parts[k].span
    if k == 0:
        member = scope.lookup(name, span)
    else:
        bare = tuple(s.RefPart(p.name, (), p.span) for p in ref.parts[:k])
        owner = ev.reference(s.Ref(bare, ref.span), scope)
        if a.is_array(owner) and owner.size:
            owner = owner.flat[0]
        if not isinstance(owner, ClassScope) or not owner.has_member(name):
            return None
        member = owner.member(name, span)
    if isinstance(member, Primitive) and member.kinds:
        return member.kinds[d]
    return None


def _size(ev: ExpressionEvaluator, ref: s.Ref, k: int, d: int, scope: Scope) -> int:
    """The size of dimension ``d`` of part ``k`` of ``ref``, its earlier parts taken
    whole (without subscripts)."""
    bare = tuple(s.RefPart(p.name, (), p.span) for p in ref.parts[:k + 1])
    before = a.shape(_value(ev, s.Ref(bare[:k], ref.span), scope)) if k else ()
    shape = a.shape(_value(ev, s.Ref(bare, ref.span), scope))
    return shape[len(before) + d]


def _value(ev: ExpressionEvaluator, ref: s.Ref, scope: Scope) -> object:
    value = ev.reference(ref, scope)
    if isinstance(value, ClassScope):
        return ()
    return value


def _uses(name: str, node: object) -> Iterator[tuple[s.Ref, int, int]]:
    """``(ref, part, dimension)`` of every subscript that is just ``name``."""
    if isinstance(node, s.Ref):
        for k, part in enumerate(node.parts):
            for d, sub in enumerate(part.subscripts):
                if isinstance(sub, s.Ref) and len(sub.parts) == 1 \
                        and sub.parts[0].name == name and not sub.parts[0].subscripts:
                    yield node, k, d
                else:
                    yield from _uses(name, sub)
        return
    if isinstance(node, tuple):
        for item in node:
            yield from _uses(name, item)
        return
    fields = getattr(node, "__dataclass_fields__", None)
    if fields is None or isinstance(node, Span):
        return
    for field in fields:
        yield from _uses(name, getattr(node, field))
