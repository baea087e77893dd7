"""Deduced ``for`` ranges (section 11.2.2.1): ``for i loop ... x[i] ... end for``.

Input: a loop index without a range and the loop body. Output: the index with the
range ``1:n``, ``n`` being the size of every array dimension the index subscripts
directly in the body (``x[i]``, ``a[i].b``, ``m[j, i]``); the sizes must agree.
"""

from __future__ import annotations

from collections.abc import Iterator

from ..errors import FlattenError, Note, Span
from ..ir import syntax as s
from . import arrays as a
from .scope import ClassScope, ExpressionEvaluator, Scope


def with_range(ev: ExpressionEvaluator, index: s.ForIndex, body: object, scope: Scope
               ) -> s.ForIndex:
    """``index`` itself if it has a range, else with the range deduced from ``body``."""
    if index.range is not None:
        return index
    sizes: list[tuple[int, Span]] = []
    for ref, k, d in _uses(index.name, body):
        sizes.append((_size(ev, ref, k, d, scope), ref.span))
    if not sizes:
        raise FlattenError(f"cannot deduce the range of '{index.name}': it is not used as "
                           "a subscript of an array in the loop", index.span,
                           hint=f"give the range: 'for {index.name} in 1:n'")
    n, first = sizes[0]
    for m, span in sizes[1:]:
        if m != n:
            raise FlattenError(f"the range of '{index.name}' cannot be deduced: it "
                               f"subscripts dimensions of sizes {n} and {m}", index.span,
                               [Note(f"size {n} here", first), Note(f"size {m} here", span)],
                               hint=f"give the range: 'for {index.name} in 1:{n}'")
    one = s.Number(1, index.span)
    return s.ForIndex(index.name, s.Range(one, None, s.Number(n, index.span), index.span),
                      index.span)


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
