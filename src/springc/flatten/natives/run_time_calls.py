"""A call of a library's ``external "C"`` function whose inputs are known only during
the simulation (the samples ``Modelica.Blocks.Math.RealFFT`` transforms at
``terminal()``): the library is built now (``foreign_calls``), and the call becomes one
node of the flat model that the generated python module evaluates at run time
(:mod:`springc.native.foreign_calls`: its name holds the call's signature, its
arguments are the scalar elements of the inputs); each element of the outputs reads
that node. The C parameters follow the same mapping as a call while flattening.
"""

from __future__ import annotations

import ctypes
from typing import Any, NamedTuple

from ...errors import FlattenError, Note
from ...ir import expr as x
from ...ir import syntax as s
from ...native.foreign_calls import OUTPUT, Signature, call_name
from ...parse import ClassEntry
from .. import arrays as a

C_TYPES: dict[str, tuple[str, Any]] = {
    "Real": ("double", ctypes.c_double), "Integer": ("int", ctypes.c_int),
    "Boolean": ("int", ctypes.c_int), "String": ("const char *", ctypes.c_char_p)}
_CODES = {"Real": "R", "Integer": "I", "Boolean": "B"}

RunTimeArg = tuple[str, str, list[x.Expr], str | None]
"""One C parameter of a run-time call: its C type, its signature code, the scalar
expressions it passes, the variable it names (an output's)."""


class Source(NamedTuple):
    """What an argument of an external clause passes: a literal or a dimension
    (``name`` None: ``kind`` and the ``literal`` value) or the function's variable
    ``name`` (of type ``kind``)."""

    kind: str
    literal: Any
    name: str | None


def argument_source(entry: ClassEntry, e: s.Expr, names: dict[str, Any],
                    declared: dict[str, s.Component], kinds: dict[str, str],
                    call: s.Call) -> Source:
    """The one reading of what springc passes to C (a call while flattening and a
    run-time call alike): literals, ``size(v, k)`` and the function's variables."""
    if isinstance(e, s.Number):
        return Source("Integer" if isinstance(e.value, int) else "Real", e.value, None)
    if isinstance(e, s.Bool):
        return Source("Integer", int(e.value), None)
    if isinstance(e, s.String):
        return Source("String", e.value, None)
    if (isinstance(e, s.Call) and e.func.dotted == "size" and len(e.args) == 2
            and isinstance(e.args[0], s.Ref) and e.args[0].dotted in declared
            and isinstance(e.args[1], s.Number)):
        shape = a.shape(names[e.args[0].dotted])
        if not 1 <= int(e.args[1].value) <= len(shape):
            raise FlattenError(f"'{e.args[0].dotted}' has no dimension {e.args[1].value}",
                               e.span)
        return Source("Integer", shape[int(e.args[1].value) - 1], None)
    name = e.dotted if isinstance(e, s.Ref) and not any(
        p.subscripts for p in e.parts) else None
    if name is None or name not in declared:
        raise FlattenError("springc passes to C only the function's variables, "
                           "'size(v, k)' and literals", e.span,
                           [Note(f"in the external clause of '{entry.full_name}'",
                                 call.span)])
    return Source(kinds[name], None, name)


def check_output_size(entry: ClassEntry, e: s.Expr, name: str, comp: s.Component,
                      value: Any) -> None:
    """An output array passed to C has a size known before the call."""
    dims = (*comp.dims, *comp.type_dims)
    if dims and (not a.is_array(value) or any(isinstance(d, s.Colon) for d in dims)):
        raise FlattenError(f"the size of '{name}' must be known before the external call "
                           f"of '{entry.full_name}'", e.span, [Note("declared here",
                                                                    comp.span)])


def run_time_argument(entry: ClassEntry, e: s.Expr, names: dict[str, Any],
                      declared: dict[str, s.Component], kinds: dict[str, str],
                      call: s.Call) -> RunTimeArg:
    """The C parameter of the external call's argument ``e`` for a run-time call."""
    source = argument_source(entry, e, names, declared, kinds, call)
    if source.name is None:
        if source.kind == "String":
            return "const char *", "S" + source.literal.encode().hex(), [], None
        return (C_TYPES[source.kind][0], _CODES[source.kind], [x.Const(source.literal)],
                None)
    name = source.name
    comp, kind, value = declared[name], kinds[name], names[name]
    if kind == "String":
        if comp.causality != "input" or not isinstance(value, str):
            raise FlattenError(f"springc passes to C only String inputs known before the "
                               f"simulation ('{name}')", e.span)
        return "const char *", "S" + value.encode().hex(), [], None
    c_type = C_TYPES[kind][0]
    if comp.causality == "input":
        if not a.is_array(value):
            return c_type, _CODES[kind], [_expr(value)], None
        items = [_expr(v) for v in a.scalars(value)]
        return f"const {c_type} *", f"{_CODES[kind]}{len(items)}", items, None
    check_output_size(entry, e, name, comp, value)
    size = len(a.scalars(value)) if a.is_array(value) else 0
    code = f"o{_CODES[kind]}{size}" if a.is_array(value) else f"o{_CODES[kind]}"
    return f"{c_type} *", code, [], name


def _expr(value: Any) -> x.Expr:
    if isinstance(value, (x.Const, x.Var, x.Time, x.Der, x.Neg, x.Not, x.BinOp, x.Call,
                          x.If)):
        return value
    return x.Const(value)


def run_time_outputs(entry: ClassEntry, c_name: str, key: str, names: dict[str, Any],
                     run: list[RunTimeArg], returned: str | None, result: str | None,
                     outputs: list[s.Component], call: s.Call, count: int) -> Any:
    """The outputs (the first, or a list of the first ``count``) of the run-time call:
    arrays of nodes reading the one node of the call."""
    if result == "String":
        raise FlattenError(f"springc does not take a String result of a C function during "
                           f"the simulation ('{entry.full_name}')", call.span)
    signature = Signature(key, entry.full_name, c_name, tuple(r[1] for r in run),
                          _CODES[result] if result else "")
    node = x.Call(call_name(signature), tuple(v for r in run for v in r[2]))
    slots = {r[3]: k for k, r in enumerate(run) if r[3] is not None}
    values: list[Any] = []
    for comp in outputs:
        if comp.name == returned:
            values.append(_element(len(run), 0, node))
            continue
        if comp.name not in slots:
            raise FlattenError(f"the external call of '{entry.full_name}' does not set its "
                               f"output '{comp.name}'", call.span,
                               [Note("declared here", comp.span)])
        k = slots[comp.name]
        code = run[k][1]
        if len(code) == 2:
            values.append(_element(k, 0, node))
            continue
        items = [_element(k, i, node) for i in range(int(code[2:]))]
        values.append(a.make_array(items, a.shape(names[comp.name])))
    return values[0] if count == 1 else values


def _element(slot: int, index: int, node: x.Expr) -> x.Expr:
    return x.Call(OUTPUT, (x.Const(slot), x.Const(index), node))
