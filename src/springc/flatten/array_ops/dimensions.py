"""Array dimensions named by a type (Modelica 3.6, section 10.1): ``Real x[Boolean]``
has the indices ``false`` and ``true``, ``Real x[E]`` the literals of ``E``.

Input: a dimension expression of a declaration and the scope it is written in.
Output: its size and kind (``BOOLEAN`` or the :class:`Enumeration`), or None when the
expression is an ordinary Integer size.
"""

from __future__ import annotations

from ...errors import FlattenError, Span
from ...ir import syntax as s
from ...parse import lookup_class
from ..checks import rule_error
from ..scopes import (
    BOOLEAN,
    BUILTIN_ENUMERATIONS,
    ClassScope,
    ClassViews,
    DimensionKind,
    EnumLiteral,
    Scope,
    kind_name,
    value_kind,
)


def typed_dimension(ctx: ClassViews, d: s.Expr, where: Scope
                    ) -> tuple[int, DimensionKind] | None:
    """``[Boolean]`` or ``[E]``: the size and the kind of the dimension; None for a
    dimension that is not a type name."""
    if not isinstance(d, s.Ref) or any(p.subscripts for p in d.parts):
        return None
    first = d.parts[0].name
    if isinstance(where, ClassScope) and where.has_member(first):
        return None  # a component (a parameter size)
    entry = where.entry
    if len(d.parts) == 1 and not d.is_global and lookup_class(first, entry) is None:
        if first == "Boolean":
            return 2, BOOLEAN
        builtin = BUILTIN_ENUMERATIONS.get(first)
        return (len(builtin.literals), builtin) if builtin is not None else None
    try:
        ctx.resolve_class(d, entry)
        rtype = ctx.resolve_type(d, entry)
    except FlattenError:  # not a class (a package constant): an Integer size
        return None
    if rtype.dims:
        return None
    if rtype.enumeration is not None:
        return len(rtype.enumeration.literals), rtype.enumeration
    return (2, BOOLEAN) if rtype.primitive == "Boolean" else None


def typed_index(value: object, kind: DimensionKind, span: Span, name: str) -> int:
    """The position (1, 2, ...) of a subscript value in a dimension of ``kind``: the
    value must be of that kind (``x[true]`` for ``[Boolean]``, ``x[E.a]`` for ``[E]``,
    an Integer otherwise; section 10.5.1)."""
    found = value_kind(value)
    if found != kind:
        shown = _shown(value)
        raise rule_error(
            f"'{name}' has a dimension indexed by {kind_name(kind)} values, but the "
            f"subscript is {shown}", span,
            "a dimension declared [Boolean] is indexed by false and true, one declared [E] "
            "by the literals of E, an Integer size by Integers", "10.5.1")
    if kind == BOOLEAN:
        return int(bool(value)) + 1
    return value  # type: ignore[return-value]


def _shown(value: object) -> str:
    if isinstance(value, EnumLiteral):
        return f"{value.enumeration.name}.{value.literal}"
    if isinstance(value, bool):
        return "true" if value else "false"
    return f"the Integer {value}" if isinstance(value, int) else repr(value)
