"""Calls of a library's own ``external "C"`` functions (Modelica 12.9) while flattening:
compiled from the C sources the library ships (:mod:`.library_sources`) by the system C
compiler (:mod:`springc.native.foreign`) and called through ctypes on the arguments'
values, which must be known before the simulation (constants, or parameters, which
then become structural: ``FlatModel.evaluated``, as for a call decided by parameter
values). The outputs become constants of the flat model.

The argument mapping of 12.9.1.1: Real is ``double``, Integer and Boolean ``int``,
String ``const char *``; an array (any number of dimensions, row-major) a pointer to
its first element, its sizes passed where the call writes ``size(a, k)``; inputs by
value (arrays as ``const``), outputs and protected variables by address, the clause's
``y = f(...)`` the C function's value. Each call runs inside springc's wrapper
(``glue.c``): a ``ModelicaError`` returns to it and becomes a located error here.
"""

from __future__ import annotations

import ctypes
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import FlattenError, Note, SpringcError
from ...ir import expr as x
from ...ir import syntax as s
from ...native import foreign
from ...parse import ClassEntry
from ...source_files import read_regular
from .. import arrays as a
from ..scopes import ExpressionEvaluator
from .library_sources import CSources, inside
from .run_time_calls import (
    C_TYPES,
    argument_source,
    check_output_size,
    run_time_argument,
    run_time_outputs,
)

IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
INCLUDE_LINE = re.compile(r'\s*#\s*include\s*("[^"/\\]+(/[^"/\\]+)*"|<[^<>/\\]+(/[^<>/\\]+)*>)\s*'
                          r"(//.*)?")
"""An ``Include`` line springc compiles: ``#include "name.h"`` or ``<name.h>`` (a
relative name, no ``..``), with a line comment at most."""
CODE_TOKENS = re.compile(r"<%|%>|%:|\?\?[=/'()!<>-]|\b(?:__)?asm(?:__)?\b|\\\s*$")
"""What would let model text define code or macros without a ``{`` or a ``#``: the
digraphs ``<%`` ``%>`` ``%:`` (``{`` ``}`` ``#``), trigraphs, file-scope ``asm`` and a
line continued by a backslash."""


@dataclass
class _Arg:
    """One argument of the C call: its C parameter text and its ctypes value; ``name``
    and ``shape`` of a variable whose value the call may write."""

    c_type: str
    value: Any
    buffer: Any = None
    name: str | None = None
    kind: str = "Real"
    shape: tuple[int, ...] | None = None


def foreign_value(ev: ExpressionEvaluator, entry: ClassEntry, names: dict[str, Any],
                  comps: list[s.Component], call: s.Call, sources: CSources,
                  count: int) -> Any:
    """The outputs (the first, or a list of the first ``count``) of the call ``call`` of
    the external function ``entry``, its variables bound in ``names``."""
    external = entry.defn.external
    assert external is not None
    c_name = external.name or entry.defn.name
    where = [Note("its external clause", external.span)]
    if not IDENTIFIER.fullmatch(c_name):
        raise FlattenError(f"'{c_name}' is not a C function name", external.span)
    declared = {c.name: c for c in comps}
    returned = external.output if external.name else next(
        (c.name for c in comps if c.causality == "output"), None)
    if returned is not None and returned not in declared:
        raise FlattenError(f"'{returned}' is not a variable of '{entry.full_name}'",
                           external.span)
    passed = _call_args(external, comps)
    used = {returned, *(n for e in passed for n in _names(e))}
    kinds = {c.name: _kind(ev, entry, c, call) for c in comps if c.name in used}
    result = kinds[returned] if returned else None
    _check_include(sources.include, entry, external.span)
    late = _run_time_input(ev, passed, names, declared)
    if late is not None:
        run = [run_time_argument(entry, e, names, declared, kinds, call) for e in passed]
        library = _library(entry, c_name, sources, _glue(c_name, [r[0] for r in run],
                                                         result, sources.include), call)
        return run_time_outputs(entry, c_name, library.key, names, run, returned, result,
                                [c for c in comps if c.causality == "output"][:count],
                                call, count)
    args = [_argument(ev, entry, e, names, declared, kinds, call) for e in passed]
    library = _library(entry, c_name, sources,
                       _glue(c_name, [arg.c_type for arg in args], result, sources.include), call)
    out = C_TYPES[result][1]() if result else None
    wrapper = library.lib.springc_call
    wrapper.restype = ctypes.c_int
    status = wrapper(*(arg.value for arg in args),
                     *((ctypes.byref(out),) if out is not None else ()))
    if status != 0:
        message = library.error_message()
        library.lib.springc_release_strings()
        raise FlattenError(f"the external function '{entry.full_name}' ('{c_name}') "
                           f"failed: {message}", call.span, where)
    values = dict(names)
    if returned and out is not None:
        values[returned] = _constant(out.value, kinds[returned])
    for arg in args:
        if arg.name is not None and arg.shape is not None:
            values[arg.name] = _read(arg)
    library.lib.springc_release_strings()
    outputs = [c for c in comps if c.causality == "output"][:count]
    unset = [c for c in outputs if values[c.name] is None or c.name not in used]
    if unset:
        raise FlattenError(f"the external call of '{entry.full_name}' does not set its "
                           f"output '{unset[0].name}'", call.span,
                           [Note("declared here", unset[0].span), *where])
    return values[outputs[0].name] if count == 1 else [values[c.name] for c in outputs]


def _library(entry: ClassEntry, c_name: str, sources: CSources, glue: str,
             call: s.Call) -> foreign.ForeignLibrary:
    external = entry.defn.external
    assert external is not None
    try:
        return foreign.load(foreign.ForeignBuild(
            tuple(_source(path, sources) for path in sources.files),
            _headers(sources), glue))
    except SpringcError as failed:
        raise FlattenError(f"the external function '{entry.full_name}' ('{c_name}') could "
                           f"not be built: {failed.message}", call.span,
                           [Note("its external clause", external.span)],
                           failed.hint or "springc compiles a library's C sources "
                           "(Resources/C-Sources) with the system C compiler, or zig cc "
                           "(pip install ziglang)") from None


def _run_time_input(ev: ExpressionEvaluator, passed: tuple[s.Expr, ...],
                    names: dict[str, Any], declared: dict[str, s.Component]) -> str | None:
    """The first input of the call known only during the simulation, else None."""
    for e in passed:
        if isinstance(e, s.Ref) and e.dotted in declared \
                and declared[e.dotted].causality == "input":
            value = names[e.dotted]
            if isinstance(value, str):
                continue
            try:
                ev.fold(value)
            except KeyError:
                return e.dotted
    return None


def _names(e: s.Expr) -> list[str]:
    """The variables an argument of the external call names (``v``, ``size(v, k)``)."""
    if isinstance(e, s.Ref):
        return [e.dotted]
    if isinstance(e, s.Call) and e.args:
        return _names(e.args[0])
    return []


def _kind(ev: ExpressionEvaluator, entry: ClassEntry, comp: s.Component,
          call: s.Call) -> str:
    rtype = ev.flattener.resolve_type(comp.type_name, entry)
    kind = "Integer" if rtype.enumeration is not None else rtype.primitive
    if kind not in C_TYPES:
        raise FlattenError(f"the external function '{entry.full_name}' has "
                           f"'{comp.name}' of type {comp.type_name.dotted}: springc passes "
                           "only Real, Integer, Boolean and String values to C",
                           call.span, [Note("declared here", comp.span)])
    return str(kind)


def _call_args(external: s.ExternalCall, comps: list[s.Component]) -> tuple[s.Expr, ...]:
    if external.name:  # an explicit call, as written
        return external.args
    # the default call (12.9.1.2): the inputs, then the outputs after the first
    inputs = [c for c in comps if c.causality == "input"]
    outputs = [c for c in comps if c.causality == "output"]
    return tuple(s.Ref((s.RefPart(c.name, (), c.span),), c.span) for c in [*inputs, *outputs[1:]])


def _argument(ev: ExpressionEvaluator, entry: ClassEntry, e: s.Expr, names: dict[str, Any],
              declared: dict[str, s.Component], kinds: dict[str, str], call: s.Call) -> _Arg:
    """The C parameter and the value of the external call's argument ``e``."""
    source = argument_source(entry, e, names, declared, kinds, call)
    if source.name is None:
        if source.kind == "String":
            return _Arg("const char *", ctypes.c_char_p(source.literal.encode()))
        return _Arg(C_TYPES[source.kind][0], C_TYPES[source.kind][1](source.literal))
    name = source.name
    comp, kind, value = declared[name], kinds[name], names[name]
    ctype = C_TYPES[kind][1]
    if comp.causality == "input":
        folded = _folded(ev, entry, name, value, call)
        if isinstance(folded, np.ndarray):
            flat = [_c_value(v, kind) for v in folded.ravel()]
            return _Arg(f"const {C_TYPES[kind][0]} *".replace("const const", "const"),
                        (ctype * max(len(flat), 1))(*flat))
        return _Arg(C_TYPES[kind][0], ctype(_c_value(folded, kind)))
    if kind == "String":
        raise FlattenError(f"springc does not take String outputs of C functions as "
                           f"arguments ('{name}')", e.span)
    check_output_size(entry, e, name, comp, value)
    shape = a.shape(value) if a.is_array(value) else ()
    size = math.prod(shape)
    buffer = (ctype * max(size, 1))() if shape else ctype()
    pointer = ctypes.cast(buffer, ctypes.c_void_p) if shape else ctypes.byref(buffer)
    return _Arg(f"{C_TYPES[kind][0]} *", pointer, buffer, name, kind, shape)


def _folded(ev: ExpressionEvaluator, entry: ClassEntry, name: str, value: Any,
            call: s.Call) -> Any:
    """The value of input ``name`` before the simulation; the parameters it reads are
    evaluated (structural) from now on."""
    try:
        folded = ev.fold(value)
    except KeyError as missing:
        raise FlattenError(
            f"the external function '{entry.full_name}' is called with its input '{name}' "
            f"known only during the simulation (it depends on {missing.args[0]})",
            call.span, [Note("its external clause", entry.defn.external.span)]
            if entry.defn.external else [],
            "springc calls a library's C functions while translating the model, on "
            "values known before the simulation (constants and parameters)") from None
    if not isinstance(value, str):
        ev.flattener.evaluated.update(n for v in a.scalars(value) for n in x.variables(v))
    return folded


def _c_value(value: Any, kind: str) -> Any:
    if kind == "String":
        if not isinstance(value, str):
            raise TypeError(f"not a string: {value!r}")
        return value.encode()
    if kind == "Real":
        return float(value)
    return int(value)


def _constant(value: Any, kind: str) -> Any:
    if kind == "String":
        return (value or b"").decode("utf-8", "replace")
    if kind == "Boolean":
        return x.Const(bool(value))
    return x.Const(int(value) if kind == "Integer" else float(value))


def _read(arg: _Arg) -> Any:
    """The value the call left in the variable of ``arg``."""
    assert arg.shape is not None
    if not arg.shape:
        return _constant(arg.buffer.value, arg.kind)
    items = arg.buffer[:math.prod(arg.shape)]
    out = np.empty(arg.shape, dtype=object)
    out.ravel()[:] = [_constant(v, arg.kind) for v in items]
    return out


def _check_include(text: str, entry: ClassEntry, span: Any) -> None:
    """Model text is data: the ``Include`` annotation may name headers and declare
    functions, but neither define code (a ``{``) nor macros, which would run when
    springc calls the function while flattening; the C code itself must be in the
    source files the library ships."""
    for line in text.splitlines():
        stripped = line.strip()
        directive = stripped.startswith("#")
        if (directive and (not INCLUDE_LINE.fullmatch(line) or ".." in stripped)) or \
                (not directive and "{" in stripped) or CODE_TOKENS.search(line):
            raise FlattenError(
                f"the Include annotation of the external function '{entry.full_name}' "
                f"holds C code ('{stripped[:60]}'); springc compiles only the C source "
                "files a library ships, never code written in model text", span,
                hint="put the function into a .c file of the library's "
                     "Resources/C-Sources folder and name it with Library=\"...\"")


def _glue(c_name: str, args: list[str], result: str | None, include: str) -> str:
    """springc's C wrapper of the call: the ``Include`` text, the function's prototype
    where it gives none, and ``springc_call``, which returns 1 after a ModelicaError."""
    params = [f"{c_type} a{k}" for k, c_type in enumerate(args)]
    value = C_TYPES[result][0] if result else "void"
    if result:
        params.append(f"{value} *springc_result")
    call_text = f"{c_name}({', '.join(f'a{k}' for k in range(len(args)))})"
    prototype = "" if include.strip() else (
        f"{value} {c_name}({', '.join(args) or 'void'});\n")
    return ("#include <setjmp.h>\n"
            "extern jmp_buf springc_error_jump;\n"
            "void springc_guard_begin(void);\nvoid springc_guard_end(void);\n"
            f"{include}\n{prototype}\n"
            f"int springc_call({', '.join(params) or 'void'}) {{\n"
            "    if (setjmp(springc_error_jump)) {\n        springc_guard_end();\n"
            "        return 1;\n    }\n"
            "    springc_guard_begin();\n"
            f"    {'*springc_result = ' if result else ''}{call_text};\n"
            "    springc_guard_end();\n    return 0;\n}\n")


def _source(path: Path, sources: CSources) -> tuple[str, bytes]:
    """A library C file as the build takes it: its subfolder (MSL's ``zlib``) and text."""
    try:
        return _subfolder(path.parent, sources), read_regular(path)
    except OSError as exc:
        raise foreign.ForeignBuildFailed(f"cannot read '{path}': {exc.strerror or exc}"
                                         ) from None


def _subfolder(folder: Path, sources: CSources) -> str:
    """The folder's name in the build: ``""`` for the sources' own folder, else its name
    where springc puts it on a command line (a plain name), else ``include``."""
    if sources.root is None or folder == sources.root:
        return ""
    return folder.name if foreign.SUBFOLDER_NAME.fullmatch(folder.name) else "include"


def _headers(sources: CSources) -> tuple[tuple[str, str, bytes], ...]:
    """The headers the sources and the ``Include`` text may name: those of the include
    directory and of the sources' folders."""
    folders = {p.parent for p in sources.files}
    if sources.include_folder is not None:
        folders.add(sources.include_folder)
    found: dict[tuple[str, str], bytes] = {}
    for folder in sorted(folders):
        sub = _subfolder(folder, sources)
        for header in sorted(folder.glob("*.h")):
            if header.is_file() and inside(header, folder):  # no link out of it
                found.setdefault((sub, header.name), read_regular(header))
    return tuple((sub, name, data) for (sub, name), data in found.items())
