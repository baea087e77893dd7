"""The C printer (codegen/c_printer.py) against the Python printer: every built-in
function of its name map, operators, precedence and if-expressions, printed both ways,
evaluate to the same numbers (the C compiled by the system compiler)."""

from __future__ import annotations

import ctypes
import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from springc.codegen.c_printer import C_FUNCTIONS, HELPERS, c_function_body
from springc.codegen.printer import HELPERS as PY_HELPERS
from springc.codegen.printer import function_lines
from springc.codegen.statements import Load, Namer, Store
from springc.errors import CodegenError
from springc.ir.expr import BinOp, Call, Const, Expr, If, Neg, Not, Var
from springc.pipeline.c_build import build_library

a, b = Var("a"), Var("b")
ARITY = {"atan2": 2, "min": 2, "max": 2, "mod": 2, "div": 2, "rem": 2}
EXPRESSIONS: list[Expr] = [
    Call(name, (a, b)[:ARITY.get(name, 1)]) for name in sorted(C_FUNCTIONS)
    if name not in ("sqrt", "log", "log10", "asin", "acos")
] + [
    Call("sqrt", (Call("abs", (a,)),)), Call("log", (Call("abs", (b,)),)),
    Call("asin", (BinOp("/", a, Const(10.0)),)),
    Call("max", (a, b, Const(0.5))),  # n-ary: folded left
    BinOp("^", a, Const(2)), BinOp("^", Call("abs", (a,)), b), BinOp("-", a, Neg(Neg(b))),
    Neg(Const(-1.5)), BinOp("/", Const(1), Const(4)),  # integers divide as doubles
    If(BinOp("and", BinOp("<", a, b), Not(BinOp("==", a, Const(0)))), BinOp("+", a, b),
       If(BinOp("or", BinOp(">=", a, b), BinOp("<>", b, Const(1))), a, Neg(b))),
    BinOp("*", BinOp("-", a, b), BinOp("+", a, Neg(b))),
    BinOp("==", BinOp("<", a, b), BinOp(">", b, a)),
    Call("noEvent", (Call("smooth", (Const(1), BinOp("-", b, a))),)),
]


def python_values(av: float, bv: float) -> list[float]:
    namer, helpers = Namer(), set[str]()
    stmts = [Load("a", "a_in"), Load("b", "b_in")]
    stmts += [Store(f"out[{i}]", e) for i, e in enumerate(EXPRESSIONS)]
    body = function_lines(namer, helpers, stmts)
    text = "\n".join(PY_HELPERS[h] for h in sorted(helpers))
    text += "\ndef f(a_in, b_in, out):\n" + "\n".join(body) + "\n"
    scope: dict[str, object] = {"math": math}
    exec(text, scope)
    out = [0.0] * len(EXPRESSIONS)
    scope["f"](av, bv, out)  # type: ignore[operator]
    return [float(v) for v in out]


def c_function() -> Any:
    helpers: set[str] = set()
    stmts = [Load("a", "a_in"), Load("b", "b_in")]
    stmts += [Store(f"out[{i}]", e) for i, e in enumerate(EXPRESSIONS)]
    body = c_function_body(Namer(), helpers, stmts)
    text = "#include <math.h>\n#define SPRINGC_FN static\n"
    text += "\n".join(HELPERS[h] for h in sorted(helpers))
    text += "\nvoid f(double a_in, double b_in, double *out)\n{\n" + "\n".join(body) + "\n}\n"
    folder = tempfile.mkdtemp()
    path = Path(folder) / "f.so"
    path.write_bytes(build_library(text, Path(folder)))
    function = ctypes.CDLL(str(path)).f
    function.argtypes = [ctypes.c_double, ctypes.c_double,
                         np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS")]
    return function


def test_every_builtin_and_operator_computes_what_python_computes() -> None:
    function = c_function()
    for av, bv in [(0.3, 0.7), (-2.5, 0.4), (1.0, 1.0), (3.7, -1.2), (-0.2, -3.0)]:
        out = np.zeros(len(EXPRESSIONS))
        function(av, bv, out)
        np.testing.assert_allclose(out, python_values(av, bv), rtol=1e-15, atol=0)


def test_an_unknown_function_names_itself() -> None:
    with pytest.raises(CodegenError) as caught:
        c_function_body(Namer(), set(), [Store("out[0]", Call("bessel", (a,)))])
    assert caught.value.message == "cannot generate C code for the function 'bessel'"
    assert caught.value.node == Call("bessel", (a,))  # type: ignore[attr-defined]
