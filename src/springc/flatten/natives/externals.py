"""Calls of external functions (section 12.9) while flattening.

The external functions springc knows by their C names (``ir.native_externals``) are
evaluated here, the ModelicaStandardTables by ``tables`` and the ModelicaStrings
functions of ``Modelica.Utilities.Strings`` on their string arguments (which are known
while flattening: springc has no string variables). Any other ``external "C"`` function
whose C sources the library ships (``library_sources``) is compiled and called
(``foreign_calls``); a call of one without them is a located error naming it and where
its sources would be; declaring one is not.
"""

from __future__ import annotations

from typing import Any

from ...errors import FlattenError, Note, SpringcError
from ...ir import expr as x
from ...ir import syntax as s
from ...ir.native_externals import FILES, NATIVE_EXTERNALS, READS, REFUSED_EXTERNALS
from ...parse import ClassEntry
from ..scopes import ExpressionEvaluator
from .foreign_calls import foreign_value
from .library_sources import (
    CSources,
    annotation_strings,
    c_sources,
    include_uri,
    resolved,
    top_class,
)
from .tables import native_call

SKIPPED = (FILES, READS)
"""The refusals a model's call statement is skipped for (:func:`skipped_call`)."""


class FileCallRefused(FlattenError):
    """A call of a function that writes or reads files (``REFUSED_EXTERNALS``): the
    model's call statement that made it is skipped (:func:`skipped_call`)."""

    function = ""
    file: str | None = None


IMPURE = "`impure` functions are"
"""How the parser's refusal of an ``impure`` function begins (``parse.rules_classes``)."""


def skipped_call(refused: SpringcError, call: s.Call) -> str | None:
    """The located warning of a model's call statement skipped because the function it
    calls writes or reads files (a :class:`FileCallRefused`) or calls an ``impure``
    function, which springc does not call (a file's ``removeFile``, ``print``): springc
    writes no file a model names (model text is data) and reads none its cache key
    does not cover. None where ``refused`` is another error (raised again)."""
    if isinstance(refused, FileCallRefused):
        file = f" on the file '{refused.file}'" if refused.file is not None else ""
        inner = f"'{refused.function}'{file}"
    elif refused.message.startswith(IMPURE):
        inner = f"the impure function declared at {refused.span}"
    else:
        return None
    return (f"{call.span}: warning: springc does not write or read files named by a model "
            f"nor call impure functions; the call of '{call.func.dotted}' is skipped (it "
            f"calls {inner})")


def is_external(entry: ClassEntry) -> bool:
    """Whether ``entry`` is a function with an ``external`` clause."""
    return entry.defn.external is not None


def external_value(ev: ExpressionEvaluator, entry: ClassEntry, names: dict[str, Any],
                   call: s.Call, comps: list[s.Component], count: int = 1) -> Any:
    """The value of ``call`` of the external function ``entry`` (the first output, or
    the first ``count`` as a list), its variables (``comps``) bound in ``names``; an
    error naming the function where springc neither implements it nor finds its C
    sources in the library."""
    external = entry.defn.external
    assert external is not None
    c_name = external.name or entry.defn.name
    known = NATIVE_EXTERNALS.get(c_name)
    if c_name in REFUSED_EXTERNALS:
        message = (f"springc does not call the external function '{entry.full_name}' "
                   f"('{c_name}'): {REFUSED_EXTERNALS[c_name]}")
        notes = [Note("its external clause", external.span)]
        hint = ("springc calls a library's C functions while translating the model, once; "
                "it writes no file a model names (docs/msl.md, External C functions)")
        if REFUSED_EXTERNALS[c_name] in SKIPPED:
            file = names.get("fileName")
            refused = FileCallRefused(message, call.span, notes, hint)
            refused.function = entry.full_name
            refused.file = file if isinstance(file, str) else None
            raise refused
        raise FlattenError(message, call.span, notes, hint)
    if known is None:
        sources = c_sources(entry, external) if external.language == "C" else []
        if isinstance(sources, CSources):
            return foreign_value(ev, entry, names, comps, call, sources, count)
        raise FlattenError(
            f"the external function '{entry.full_name}' ({external.language} function "
            f"'{c_name}') is not supported: its library does not ship its C sources",
            call.span,
            [Note("its external clause", external.span),
             *_sources(entry, external, sources)],
            "springc compiles and calls the C functions whose sources the library ships "
            "(its Resources/C-Sources); it evaluates the tables "
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


def _sources(entry: ClassEntry, external: s.ExternalCall, missing: list[str]) -> list[Note]:
    """Where the external clause's annotation (12.9.4) says the function's C code is:
    its libraries (those whose C files this copy of the library lacks), and its include
    directory (``modelica://Top/Resources/Include`` by default) with whether the
    library at hand ships it."""
    notes = annotation_strings(external)
    found: list[Note] = []
    if notes.get("Library"):
        found.append(Note("it links the librar" + ("y " if len(notes["Library"]) == 1
                                                   else "ies ")
                          + ", ".join(f"'{name}'" for name in notes["Library"])))
    if missing:
        found.append(Note("the C sources of " + ", ".join(f"'{name}'" for name in missing)
                          + " are not in this copy of the library (looked for in its "
                          "include directory and Resources/C-Sources)"))
    top = top_class(entry)
    include = include_uri(external, top)
    folder = resolved(include, top)
    if folder is None:
        return found
    where = f"its include directory {include} ({folder})"
    if not folder.is_dir():
        found.append(Note(f"{where} is not in this copy of the library"))
    else:
        sources = sorted(p.name for p in folder.glob("*.c"))
        listed = ", ".join(sources[:4]) + (", ..." if len(sources) > 4 else "")
        found.append(Note(f"{where} holds C sources ({listed})" if sources
                          else f"{where} holds no C source"))
    return found
