"""Calls of external functions (section 12.9) while flattening.

springc calls no foreign code: the external functions it knows by their C names
(``ir.native_externals``) are evaluated here, the ModelicaStandardTables by ``tables``
and the ModelicaStrings functions of ``Modelica.Utilities.Strings`` on their string
arguments (which are known while flattening: springc has no string variables). A call
of any other external function is a located error naming it; declaring one is not.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ...errors import FlattenError, Note
from ...ir import expr as x
from ...ir import syntax as s
from ...ir.native_externals import NATIVE_EXTERNALS
from ...parse import ClassEntry
from ..scopes import ExpressionEvaluator
from .tables import native_call


def is_external(entry: ClassEntry) -> bool:
    """Whether ``entry`` is a function with an ``external`` clause."""
    return entry.defn.external is not None


def external_value(ev: ExpressionEvaluator, entry: ClassEntry, names: dict[str, Any],
                   call: s.Call) -> Any:
    """The value of ``call`` of the external function ``entry``, its inputs bound in
    ``names``; an error naming the function where springc does not implement it."""
    external = entry.defn.external
    assert external is not None
    c_name = external.name or entry.defn.name
    known = NATIVE_EXTERNALS.get(c_name)
    if known is None:
        raise FlattenError(
            f"the external function '{entry.full_name}' ({external.language} function "
            f"'{c_name}') is not supported yet", call.span,
            [Note("its external clause", external.span), *_sources(entry, external)],
            "springc calls no foreign code yet; it evaluates the tables "
            "(ModelicaStandardTables) and string functions (ModelicaStrings) of the "
            "Modelica Standard Library itself")
    operation, roles = known
    if not operation.startswith("strings."):
        return native_call(ev, entry, names, call)
    given = {role: names[arg.dotted] for role, arg in zip(roles, external.args)
             if role is not None and isinstance(arg, s.Ref) and arg.dotted in names}
    return _string_function(ev, operation[len("strings."):], given, call)


def _string_function(ev: ExpressionEvaluator, name: str, given: dict[str, Any],
                     call: s.Call) -> Any:
    """ModelicaStrings_length, _substring, _compare and _skipWhiteSpace, as
    the MSL documents them (indices 1-based)."""
    text = _string(ev, given["string"], call)
    if name == "length":
        return x.Const(len(text))
    if name == "substring":
        first, last = _index(ev, given, "startIndex", call), _index(ev, given, "endIndex", call)
        if not 1 <= first <= max(len(text), 1) or last > len(text) or last < first - 1:
            raise FlattenError(f"Strings.substring: the indices {first}..{last} are not in "
                               f"the string \"{text}\" (length {len(text)})", call.span)
        return text[first - 1:last]
    if name == "compare":
        other = _string(ev, given["string2"], call)
        case = bool(ev.fold(given.get("caseSensitive", x.ONE)))
        a, b = (text, other) if case else (text.lower(), other.lower())
        return x.Const(1 if a < b else 2 if a == b else 3)  # Types.Compare's ordinals
    assert name == "skipWhiteSpace", name
    index = _index(ev, given, "startIndex", call)
    while index <= len(text) and text[index - 1] in " \t\n\r":
        index += 1
    return x.Const(index)


def _string(ev: ExpressionEvaluator, value: Any, call: s.Call) -> str:
    while isinstance(value, x.If):
        value = value.then if ev.fold(value.cond) else value.otherwise
    if not isinstance(value, str):
        raise FlattenError("a string function of Modelica.Utilities.Strings needs a "
                           "String known before the simulation", call.span)
    return value


def _index(ev: ExpressionEvaluator, given: dict[str, Any], role: str, call: s.Call) -> int:
    try:
        return int(ev.fold(given.get(role, x.ONE)))
    except KeyError as missing:
        raise FlattenError(f"the {role} of a string function must be known before the "
                           f"simulation, but it depends on {missing.args[0]}",
                           call.span) from None


def _sources(entry: ClassEntry, external: s.ExternalCall) -> list[Note]:
    """Where the external clause's annotation (12.9.4) says the function's C code is:
    its libraries, and its include directory (``modelica://Top/Resources/Include`` by
    default) with whether the library at hand ships it."""
    notes: dict[str, list[str]] = {}
    for arg in external.annotation.arguments if external.annotation else ():
        value = arg.modification.value if arg.modification else None
        items = value.items if isinstance(value, s.ArrayLit) else (value,)
        notes[".".join(arg.path)] = [i.value for i in items if isinstance(i, s.String)]
    found: list[Note] = []
    if notes.get("Library"):
        found.append(Note("it links the librar" + ("y " if len(notes["Library"]) == 1
                                                   else "ies ")
                          + ", ".join(f"'{name}'" for name in notes["Library"])))
    top = entry
    while top.parent is not None and top.parent.parent is not None:
        top = top.parent  # up to the top-level class, below the tree's root
    include = (notes.get("IncludeDirectory") or
               [f"modelica://{top.defn.name}/Resources/Include"])[0]
    folder = _resolved(include, top)
    if folder is None:
        return found
    where = f"its include directory {include} ({folder})"
    if not folder.is_dir():
        found.append(Note(f"{where} is not in this copy of the library"))
    else:
        sources = sorted(p.name for p in folder.glob("*.c"))
        listed = ", ".join(sources[:4]) + (", ..." if len(sources) > 4 else "")
        found.append(Note(f"{where} holds its C sources" + (
            f" ({listed})" if sources else "")))
    return found


def _resolved(uri: str, top: ClassEntry) -> Path | None:
    """The folder a ``modelica://Top/path`` URI names, where ``Top`` is the library
    ``top`` stored as a folder; None where it is another library or not a folder."""
    prefix = f"modelica://{top.defn.name}/"
    if not uri.startswith(prefix) or top.folder is None:
        return None
    return top.folder.joinpath(*uri[len(prefix):].split("/"))
