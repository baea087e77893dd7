"""Records as values inside functions (section 12.6): a record constructor call
``R(1, k = 2)`` and the record components of a function (inputs given as records,
outputs and locals filled field by field with ``r.x := e``).

Input: a record class and the call's arguments, or a function's component. Output:
an :class:`~springc.flatten.arrays.RecordValue`, each field an expression, an array of
them, or a nested record.
"""

from __future__ import annotations

from typing import Any

from ...errors import FlattenError, Note, Span
from ...ir import syntax as s
from ...parse import ClassEntry, lookup_class
from .. import arrays as a
from ..redeclare import constructor_fields
from ..scopes import ExpressionEvaluator, FunctionScope

_PRIMITIVES = frozenset({"Real", "Integer", "Boolean", "String"})


def construct(ev: ExpressionEvaluator, entry: ClassEntry, args: list[a.Value],
              named: dict[str, tuple[a.Value, Span]], call: s.Call) -> Any:
    """``R(...)``: the given fields, the others at their declared defaults."""
    view = ev.flattener.view(entry)
    inputs = [c.name for c in constructor_fields(view)]
    if len(args) > len(inputs):
        raise FlattenError(f"record constructor '{entry.full_name}' takes {len(inputs)} "
                           f"argument(s), {len(args)} given", call.span,
                           [Note("record defined here", entry.defn.span)])
    given: dict[str, a.Value] = dict(zip(inputs, args))
    for name, (value, span) in named.items():
        if name not in inputs:
            raise FlattenError(f"record '{entry.full_name}' has no field '{name}' to set",
                               span, hint=f"its fields are: {', '.join(inputs)}")
        if name in given:
            raise FlattenError(f"field '{name}' is given twice", span)
        given[name] = value
    scope = FunctionScope(dict(given), ev.flattener.package_scope(entry.parent or entry),
                          entry)
    for comp in view.components.values():
        decl = comp.decl
        if decl.name in given:
            continue
        mod = decl.modification
        if mod is None or mod.value is None:
            raise FlattenError(f"field '{decl.name}' of record '{entry.full_name}' needs a "
                               "value in this constructor call", call.span,
                               [Note("declared here", decl.span)])
        scope.names[decl.name] = ev.value(mod.value, scope)
    return a.RecordValue(entry.full_name, {c: scope.names[c] for c in view.components})


def record_class(ev: ExpressionEvaluator, comp: s.Component, function: ClassEntry
                 ) -> ClassEntry | None:
    """The record class of a function's component, None for any other type."""
    first = comp.type_name.parts[0].name
    if first in _PRIMITIVES or comp.dims or comp.type_dims \
            or lookup_class(first, function) is None:
        return None
    entry = ev.flattener.resolve_class(comp.type_name, function)
    if entry.defn.kind != "record":
        return None
    return ev.flattener.follow_short(entry)[0] if entry.defn.short is not None else entry


def empty_record(ev: ExpressionEvaluator, entry: ClassEntry) -> a.RecordValue:
    """A record component of a function before any assignment: each field at its
    declared default (evaluated), or unassigned (None)."""
    view = ev.flattener.view(entry)
    scope = FunctionScope({}, ev.flattener.package_scope(entry.parent or entry), entry)
    for comp in view.components.values():
        mod = comp.decl.modification
        nested = record_class(ev, comp.decl, entry)
        if mod is not None and mod.value is not None:
            scope.names[comp.decl.name] = ev.value(mod.value, scope)
        elif nested is not None:
            scope.names[comp.decl.name] = empty_record(ev, nested)
        else:
            scope.names[comp.decl.name] = None
    return a.RecordValue(entry.full_name, dict(scope.names))


def store_field(record: a.RecordValue, parts: tuple[s.RefPart, ...], value: Any,
                target: s.Ref) -> a.RecordValue:
    """``r.x := value`` (``parts``: ``x`` and below, without subscripts): a new record."""
    name = parts[0].name
    if name not in record.fields:
        raise FlattenError(f"record '{record.name}' has no field '{name}'", parts[0].span,
                           hint="its fields are: " + ", ".join(record.fields))
    if len(parts) > 1:
        inner = record.fields[name]
        if not isinstance(inner, a.RecordValue):
            raise FlattenError(f"'{name}' is not a record", parts[0].span)
        value = store_field(inner, parts[1:], value, target)
    return a.RecordValue(record.name, {**record.fields, name: value})
