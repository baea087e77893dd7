"""Component references in expressions: ``a.b[i].c`` -> a value, a scope or an array
of scopes, with member selection, subscripts (``end``, vector subscripts) and their
errors. A base class of :class:`~springc.flatten.evaluate.Evaluator`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import FlattenError, Note, Span, close_names
from ...ir import expr as x
from ...ir import syntax as s
from ...parse import ClassEntry
from .. import arrays as a
from ..array_ops import typed_index
from ..calls import CONSTANTS
from ..calls import read as read_string
from ..checks import check_access_component
from ..redeclare import instance_scope, redeclared_package
from ..scopes import (
    BuiltinEnumeration,
    ClassScope,
    DimensionKind,
    Disabled,
    DisabledReference,
    FlattenContext,
    Ident,
    LocalScope,
    Primitive,
    Scope,
    literal_value,
    value_kind,
)


class ReferenceResolver:
    """Follows component references for the :class:`Evaluator` that derives from it."""

    flattener: FlattenContext
    uses_end: dict[Ident[s.Expr], bool]

    if TYPE_CHECKING:
        def constant(self, e: s.Expr, scope: Scope, what: str,
                     hint: str = "use parameters and constants with values here") -> Any:
            ...

        def value(self, e: s.Expr, scope: Scope) -> a.Value:
            ...

    def _Ref(self, e: s.Ref, scope: Scope) -> a.Value:
        v = self.reference(e, scope)
        if isinstance(v, ClassScope) and v.kind == "record":
            record: a.Value = self.record_value(v)
            return record
        if isinstance(v, (ClassEntry, ClassScope)) or (
                a.is_array(v) and v.size and isinstance(v.flat[0], ClassScope)):
            raise FlattenError(f"'{e.dotted}' is a component or class, not a value", e.span,
                               hint="refer to one of its variables, e.g. "
                               f"'{e.dotted}.<name>'")
        value: a.Value = v
        return value

    def record_value(self, record: ClassScope) -> Any:
        """A record component as a value: its fields read one by one."""
        fields = {}
        for name in record.view.components:
            member = record.member(name)
            if isinstance(member, ClassScope) and member.kind == "record":
                fields[name] = self.record_value(member)
            else:
                fields[name] = self.member_value(member)
        return a.RecordValue(record.entry.full_name, fields)

    def reference(self, e: s.Ref, scope: Scope) -> Any:
        """Follow a component reference; the result may be a scope or array of scopes."""
        first = e.parts[0]
        if first.name == "Modelica" and e.dotted in CONSTANTS:
            return x.Const(CONSTANTS[e.dotted])
        if e.is_global:  # .A.B: a class from the top-level package (section 5.3.3)
            current = self.flattener.resolve_class(s.Ref((first,), first.span, True),
                                                   scope.entry)
        else:
            instance = instance_scope(scope)
            package = None if instance is None or len(e.parts) == 1 else \
                redeclared_package(self.flattener, instance, first.name)
            current = package if package is not None else \
                self._subscript(scope.lookup(first.name, first.span), first, scope)
        for part in e.parts[1:]:
            current = self._select(current, part, scope, e)
        return current

    def _select(self, current: Any, part: s.RefPart, scope: Scope, ref: s.Ref) -> Any:
        if isinstance(current, BuiltinEnumeration):
            if part.name not in current.literals:
                raise FlattenError(f"'{part.name}' is not a literal of {current.name}",
                                   part.span, hint="its literals are: "
                                   + ", ".join(current.literals))
            return literal_value(current, current.literals.index(part.name) + 1)
        if isinstance(current, a.RecordValue):
            if part.name not in current.fields:
                raise FlattenError(f"record '{current.name}' has no field '{part.name}'",
                                   part.span, hint="its fields are: "
                                   + ", ".join(current.fields))
            return self._subscript(current.fields[part.name], part, scope)
        if isinstance(current, ClassEntry):
            found = self.flattener.class_member(current, part.name, part.span)
            return self._subscript(found, part, scope)
        if isinstance(current, ClassScope):
            if not current.has_member(part.name):
                self._no_member(current, part)
            check_access_component(current.view, part.name, part.span, current.prefix)
            return self._subscript(current.member(part.name, part.span), part, scope)
        if a.is_array(current) and current.size and isinstance(current.flat[0], ClassScope):
            items = [self._select(c, part, scope, ref) for c in current.flat]
            inner = a.shape(items[0])
            out = np.empty(current.shape + inner, dtype=object)
            for idx, item in zip(np.ndindex(current.shape), items):
                out[idx] = item
            return out
        raise FlattenError(f"'{part.name}' cannot be selected from a value", part.span)

    def _no_member(self, owner: ClassScope, part: s.RefPart) -> None:
        close = close_names(part.name, list(owner.view.components), 1)
        hint = f"did you mean '{close[0]}'?" if close else None
        raise FlattenError(
            f"'{owner.prefix}' (of class '{owner.entry.full_name}') has no element "
            f"'{part.name}'", part.span,
            [Note(f"class '{owner.entry.full_name}' is defined here", owner.entry.defn.span)],
            hint)

    def member_value(self, member: Any) -> Any:
        if not isinstance(member, Primitive):
            return member
        return read_string(member.value) if member.type == "String" else member.value

    def _subscript(self, current: Any, part: s.RefPart, scope: Scope) -> Any:
        if isinstance(current, Disabled):
            raise DisabledReference(
                f"'{current.name}' is a conditional component whose condition is false",
                part.span, [Note("declared here", current.decl.span)],
                "a disabled conditional component may only be named in connect(...)")
        value = self.member_value(current)
        if not part.subscripts:
            return value
        dims = a.shape(value)
        if len(part.subscripts) > len(dims):
            raise FlattenError(f"'{part.name}' has {len(dims)} dimension(s) but "
                               f"{len(part.subscripts)} subscript(s) are given", part.span)
        kinds = current.kinds if isinstance(current, Primitive) else ()
        index = tuple(self._index(sub, dims[k], scope, part, kinds[k] if kinds else None)
                      for k, sub in enumerate(part.subscripts))
        return _selected(value, index)

    def _index(self, sub: s.Expr, size: int, scope: Scope, part: s.RefPart,
               kind: DimensionKind = None) -> Any:
        try:
            return self._known_index(sub, size, scope, part, kind)
        except _UnknownIndex as unknown:
            found = self.value(sub, scope) if kind is None else None
            if isinstance(found, x.Expr) and not isinstance(found, x.Const):
                return _RunTimeIndex(found, size)  # an Integer variable (section 10.5)
            raise unknown.error from None

    def _known_index(self, sub: s.Expr, size: int, scope: Scope, part: s.RefPart,
                     kind: DimensionKind = None) -> Any:
        if isinstance(sub, s.Colon):
            return slice(None)
        uses_end = self.uses_end.get(Ident(sub))
        if uses_end is None:
            uses_end = self.uses_end[Ident(sub)] = _uses_end(sub)
        if uses_end:
            scope = LocalScope({}, scope, size)
        v = self._loop_index(sub, scope)
        if v is None:
            try:
                v = self.constant(sub, scope, "a subscript")
            except FlattenError as err:  # not a parameter expression: maybe run time
                raise _UnknownIndex(err) from None
        values = list(v.flat) if isinstance(v, np.ndarray) else [v]
        if kind is not None or any(value_kind(i) is not None for i in values):
            values = [typed_index(i, kind, sub.span, part.name) for i in values]
            v = np.array(values, dtype=object) if isinstance(v, np.ndarray) else values[0]
        for i in values:
            if isinstance(i, bool | str) or not math.isfinite(i) or i != int(i):
                raise FlattenError(f"a subscript must be an integer, found {i!r}", sub.span)
            if not 1 <= i <= size:
                raise FlattenError(
                    f"index {i} is out of range for '{part.name}' of size {size}"
                    + _loop_context(scope), sub.span,
                    hint=f"subscripts of '{part.name}' run from 1 to {size}")
        if isinstance(v, np.ndarray):
            return np.array([int(i) - 1 for i in values], dtype=int)
        return int(v) - 1

    @staticmethod
    def _loop_index(sub: s.Expr, scope: Scope) -> Any:
        """The value of a subscript that names a for-loop index (``p[i]``), the most
        common subscript, without the general evaluator; None for any other."""
        if type(sub) is not s.Ref or len(sub.parts) != 1 or sub.parts[0].subscripts:
            return None
        part = sub.parts[0]
        while type(scope) is LocalScope:
            if part.name in scope.names:
                found = scope.names[part.name]
                return found.value if type(found) is x.Const else None
            scope = scope.parent
        return None


def _uses_end(e: Any) -> bool:
    """Whether a subscript expression contains ``end`` (which needs the dimension's
    size in scope)."""
    if isinstance(e, s.End):
        return True
    if isinstance(e, tuple):
        return any(_uses_end(item) for item in e)
    fields = getattr(e, "__dataclass_fields__", None)
    if fields is None or isinstance(e, Span):
        return False
    return any(_uses_end(getattr(e, name)) for name in fields)


def _loop_context(scope: Scope) -> str:
    """`` (with i = 3)``: the values of the enclosing for-loop indices, if any."""
    values: list[str] = []
    while isinstance(scope, LocalScope):
        values = [f"{k} = {v.value}" for k, v in scope.names.items()
                  if isinstance(v, x.Const) and isinstance(v.value, (int, np.integer))
                  and not isinstance(v.value, bool)] + values
        scope = scope.parent
    return f" (with {', '.join(values)})" if values else ""


class _UnknownIndex(Exception):
    """A subscript with no value while flattening (``error`` says why): a run-time
    subscript where it is an Integer variable, else ``error``. A subscript whose value
    is known and out of range is its own error, never a run-time subscript (an
    unselected if-branch's index is left to the branch's pruning)."""

    def __init__(self, error: FlattenError) -> None:
        super().__init__(error.message)
        self.error = error


class _RunTimeIndex:
    """A subscript known only during the simulation: ``expr[i]`` with ``i`` a
    discrete Integer selects by an if-expression on ``i`` (:func:`_selected`)."""

    def __init__(self, index: x.Expr, size: int) -> None:
        self.index, self.size = index, size


def _selected(value: Any, index: tuple[Any, ...]) -> Any:
    """``value[index]``; a :class:`_RunTimeIndex` becomes ``if i == 1 then value[1]
    elseif ... else value[n]`` element by element (an index out of range takes the
    last element: checking it is not supported yet)."""
    for k, i in enumerate(index):
        if isinstance(i, _RunTimeIndex):
            choices = [_selected(value, (*index[:k], j, *index[k + 1:]))
                       for j in range(i.size)]
            if not choices:
                raise IndexError("a run-time subscript of an empty dimension")
            found = choices[-1]
            for j in reversed(range(i.size - 1)):
                at = x.BinOp("==", i.index, x.Const(j + 1))
                found = a.elementwise(lambda c, o, at=at: x.If(at, c, o), choices[j], found)
            return found
    return _constant_selected(value, index)


def _constant_selected(value: Any, index: tuple[Any, ...]) -> Any:
    if sum(isinstance(i, np.ndarray) for i in index) > 1:
        # several vector subscripts select a block (x[1:2, 2:3]), not numpy's
        # element pairs: take them one dimension at a time
        result = value
        for axis in reversed(range(len(index))):
            if not isinstance(index[axis], slice):
                result = np.take(result, index[axis], axis=axis)
    else:
        result = value[index]
    if isinstance(result, np.ndarray) and result.ndim == 0:
        return result.item()
    return result
