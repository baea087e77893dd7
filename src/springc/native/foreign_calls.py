"""Calls of a library's foreign C functions at run time: the ``Call`` nodes of the flat
model that stand for them, and their evaluation by the generated python module.

A call of an ``external "C"`` function whose inputs are known only during the
simulation (the samples of ``Modelica.Blocks.Math.RealFFT`` at ``terminal()``) cannot
be made while flattening. It becomes one node ``Call(name, inputs)``, ``name`` the
call's :class:`Signature` (:func:`call_name`) and ``inputs`` the scalar elements of its
inputs in the order of the C parameters; each element of its outputs is
``Call(OUTPUT, (Const(slot), Const(index), call))``. The library (its key names it in
the foreign cache, :mod:`.foreign`) was built and loaded while flattening; at run time
:func:`run_call` finds it loaded, or loads it again from the verified cache, and calls
its wrapper ``springc_call``, the last call remembered per signature (the elements of
one call's outputs are read from one C call). Only the python backend prints these
nodes: numba and the C model refuse them with :data:`REFUSAL`, so springc runs such a
model on the python backend.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Any

from ..errors import CodegenError, SpringcError
from .foreign import ForeignLibrary, loaded

PREFIX = "foreign:"
OUTPUT = "foreign.output"
"""The name of the node reading one element of a run-time call's outputs."""
REFUSAL = ("{} cannot call the external C function '{}' during the simulation; the python "
           "backend does")
"""Why numba and the C model cannot take a model with a run-time foreign call."""

HELPER = ("def _foreign(name, args):\n"
          "    from springc.native.foreign_calls import run_call\n"
          "    return run_call(name, args)\n")
"""The function a generated python module calls for a run-time foreign call."""

_SCALAR: dict[str, Any] = {"R": ctypes.c_double, "I": ctypes.c_int, "B": ctypes.c_int}


def is_foreign(name: str) -> bool:
    """Whether a call node is a run-time foreign call or reads one's outputs."""
    return name == OUTPUT or name.startswith(PREFIX)


def calls_foreign(source: str) -> bool:
    """Whether a generated module's text calls foreign functions at run time."""
    return HELPER.splitlines()[0] in source


class RunTimeCallRefused(CodegenError):
    """A backend that calls no foreign function at run time (numba) refused the model;
    ``derived``: the system derived for it, from which springc generates the python
    backend's module where it chose the backend itself (``api``)."""

    derived: Any = None


class ForeignCallFailed(SpringcError):
    """A run-time call of a foreign function failed (ModelicaError, library gone)."""


@dataclass(frozen=True)
class Signature:
    """One run-time call: the library's ``key``, the Modelica ``function`` and its
    ``c_name``, each C parameter's code and the C function's value (``result``, ``""``
    for none). A parameter is ``R``/``I``/``B`` (a Real, Integer, Boolean input:
    one element), ``Rn``/``In``/``Bn`` (an input array of n elements), ``S<hex>`` (a
    String known while flattening, UTF-8 in hex), ``oR``/``oRn`` and the like (an
    output or protected variable, scalar or of n elements, passed by address)."""

    key: str
    function: str
    c_name: str
    params: tuple[str, ...]
    result: str = ""

    def name(self) -> str:
        return f"{PREFIX}{self.key}:{self.function}:{self.c_name}:" \
               f"{','.join(self.params)}:{self.result}"

    def inputs(self) -> int:
        """How many scalar arguments the node takes."""
        return sum(_count(p) for p in self.params if p[0] in _SCALAR)

    def slots(self) -> list[tuple[int, str, int]]:
        """(slot, kind, elements) of each output: the parameters' ``o`` codes, then
        the result (slot ``len(params)``)."""
        found = [(k, p[1], _count(p[1:])) for k, p in enumerate(self.params) if p[0] == "o"]
        if self.result:
            found.append((len(self.params), self.result, 1))
        return found


def call_name(signature: Signature) -> str:
    return signature.name()


def parse_name(name: str) -> Signature:
    """The signature a node's name holds (:meth:`Signature.name`)."""
    if not name.startswith(PREFIX):
        raise ValueError(f"not a foreign call: {name!r}")
    key, function, c_name, params, result = name[len(PREFIX):].split(":")
    return Signature(key, function, c_name, tuple(p for p in params.split(",") if p), result)


def function_of(name: str) -> str:
    """The Modelica name of the function a foreign call node calls."""
    return parse_name(name).function


def _count(code: str) -> int:
    return int(code[1:]) if len(code) > 1 else 1


_LAST: dict[str, tuple[tuple[Any, ...], tuple[Any, ...]]] = {}
"""The last call of each signature: its arguments and its outputs."""


def run_call(name: str, args: tuple[Any, ...]) -> tuple[Any, ...]:
    """The outputs of the call ``name`` on the scalar arguments ``args``, by slot: a
    list of each output's elements (row-major), ``None`` for an input's slot."""
    last = _LAST.get(name)
    if last is not None and last[0] == args:
        return last[1]
    signature = parse_name(name)
    library = loaded(signature.key)
    if library is None:
        raise ForeignCallFailed(
            f"the C library of the external function '{signature.function}' is not in "
            "springc's cache any more; compile the model again")
    outputs = _call(library, signature, args)
    _LAST[name] = (args, outputs)
    return outputs


def _call(library: ForeignLibrary, signature: Signature, args: tuple[Any, ...]
          ) -> tuple[Any, ...]:
    values: list[Any] = []
    buffers: list[Any] = [None] * (len(signature.params) + 1)
    at = 0
    for k, code in enumerate(signature.params):
        if code[0] == "S":
            values.append(ctypes.c_char_p(bytes.fromhex(code[1:])))
            continue
        if code[0] == "o":
            ctype = _SCALAR[code[1]]
            buffer = (ctype * max(_count(code[1:]), 1))() if len(code) > 2 else ctype()
            buffers[k] = buffer
            values.append(ctypes.cast(buffer, ctypes.c_void_p) if len(code) > 2
                          else ctypes.byref(buffer))
            continue
        ctype, size = _SCALAR[code[0]], _count(code)
        taken = args[at:at + size]
        at += size
        items = [float(v) for v in taken] if code[0] == "R" else [int(v) for v in taken]
        values.append((ctype * max(size, 1))(*items) if len(code) > 1 else ctype(items[0]))
    if signature.result:
        buffers[-1] = _SCALAR[signature.result]()
        values.append(ctypes.byref(buffers[-1]))
    wrapper = library.lib.springc_call
    wrapper.restype = ctypes.c_int
    status = wrapper(*values)
    try:
        if status != 0:
            raise ForeignCallFailed(f"the external function '{signature.function}' "
                                    f"('{signature.c_name}') failed: "
                                    f"{library.error_message()}")
        return tuple(_read(signature, k, buffers[k]) for k in range(len(buffers)))
    finally:
        library.lib.springc_release_strings()


def _read(signature: Signature, slot: int, buffer: Any) -> Any:
    if buffer is None:
        return None
    code = signature.result if slot == len(signature.params) else signature.params[slot][1:]
    items = list(buffer[:_count(code)]) if isinstance(buffer, ctypes.Array) \
        else [buffer.value]
    if code[0] == "R":
        return [float(v) for v in items]
    return [bool(v) for v in items] if code[0] == "B" else [int(v) for v in items]
