"""The registry of built-ins (springc.ir.builtins) is complete and each entry is right.

Complete: every name flattening handles, every name the printers print, is in it, and
each entry of the flat model has a value, a derivative and its spellings. Right: the
values agree with numpy's functions, the derivatives with central differences, the
Python, numpy, LaTeX (sympy) and C (the system's libm, through ctypes) spellings with
the values, at stated points and tolerances.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
import re
import subprocess
from pathlib import Path
from typing import Any, cast

import numpy as np
import pytest

from springc.codegen.printer import FunctionWriter, NumpyWriter
from springc.errors import CodegenError
from springc.flatten.calls.builtins import SCALAR_FUNCTIONS, Builtins
from springc.flatten.evaluate import UNSUPPORTED_CALLS
from springc.flatten.events.event_calls import BOOLEAN_CALLS, EVENT_CALLS
from springc.ir import builtins as b
from springc.ir import expr as x
from springc.ir import latex
from springc.pipeline import find_compiler

ROOT = Path(__file__).resolve().parents[2]

#: The stored value of each math built-in, from numpy (an independent reference).
REFERENCE: dict[str, Any] = {
    "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin,
    "acos": np.arccos, "atan": np.arctan, "atan2": np.arctan2, "sinh": np.sinh,
    "cosh": np.cosh, "tanh": np.tanh, "exp": np.exp, "log": np.log, "log10": np.log10,
    "abs": np.abs, "sign": np.sign, "floor": np.floor, "ceil": np.ceil,
    "integer": np.floor, "mod": np.mod, "rem": np.fmod,
    "div": lambda a, c: np.trunc(a / c), "min": np.minimum, "max": np.maximum,
}

#: Points inside each function's domain, away from its switches.
POINTS = [(0.3, 0.7), (-0.45, 0.2), (0.8, -1.3)]
POSITIVE = {"sqrt", "log", "log10"}

#: The functions of C99's <math.h> (ISO/IEC 9899:1999, 7.12) that the registry may name.
C99_MATH = {"sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh",
            "tanh", "exp", "log", "log10", "fabs", "floor", "ceil", "fmod", "fmin", "fmax",
            "trunc", "round", "pow", "cbrt", "hypot", "exp2", "log2", "expm1", "log1p"}

MATH_NAMES = sorted(b.names(lambda e: e.kind == b.MATH))


def _args(name: str, point: tuple[float, float]) -> tuple[float, ...]:
    values = tuple(abs(v) if name in POSITIVE else v for v in point)
    return values[:b.BUILTINS[name].arity[1]]


def _call(name: str, arity: int) -> x.Call:
    return x.Call(name, tuple(x.Var(v) for v in "ab"[:arity]))


def test_the_math_built_ins_are_the_expected_ones() -> None:
    assert set(MATH_NAMES) == set(REFERENCE)
    assert set(SCALAR_FUNCTIONS) == set(MATH_NAMES) - {"min", "max"}


def test_every_name_flattening_handles_is_registered() -> None:
    table = Builtins(cast(Any, None)).table
    handled = set(table) | set(EVENT_CALLS) | {"delay", "cardinality", "print"}
    assert handled == set(b.BUILTINS)
    assert not set(b.BUILTINS) & UNSUPPORTED_CALLS


def test_event_properties() -> None:
    assert set(EVENT_CALLS) == {"pre", "edge", "change", "initial", "terminal", "sample",
                                "reinit", "terminate"}
    assert set(BOOLEAN_CALLS) == {"edge", "change", "initial", "terminal", "sample"}
    assert b.names(lambda e: e.quiet) == {"noEvent", "smooth"}
    assert b.names(lambda e: e.phase) == {"initial", "terminal"}
    assert b.names(lambda e: e.reads_pre) == {"pre", "edge", "change"}
    assert b.names(lambda e: e.kind == b.EQUATION) == {"reinit", "terminate", "print"}
    assert b.names(lambda e: e.floored) == {"floor", "ceil", "integer", "div", "mod",
                                            "rem"}
    assert b.names(lambda e: e.switching) == b.names(lambda e: e.floored) | {
        "abs", "sign", "min", "max"}
    assert {n: b.BUILTINS[n].transparent for n in b.names(
        lambda e: e.transparent is not None)} == {"noEvent": 0, "smooth": 1, "homotopy": 0}


@pytest.mark.parametrize("name", MATH_NAMES)
def test_value_matches_numpy(name: str) -> None:
    entry = b.BUILTINS[name]
    assert entry.evaluate is not None
    for point in POINTS:
        args = _args(name, point)
        assert entry.evaluate(*args) == pytest.approx(float(REFERENCE[name](*args)),
                                                      rel=1e-15, abs=1e-15)
        assert x.evaluate(_call(name, len(args)), dict(zip("ab", args))) == \
            pytest.approx(float(REFERENCE[name](*args)), rel=1e-15, abs=1e-15)


@pytest.mark.parametrize("name", sorted(b.names(lambda e: e.derivative is not None
                                                and e.evaluate is not None)))
def test_derivative_matches_central_differences(name: str) -> None:
    entry = b.BUILTINS[name]
    arity = entry.arity[1]
    for point in POINTS:
        args = _args(name, point) if name in REFERENCE else point[:arity]
        env = dict(zip("ab", args))
        for k, var in enumerate("ab"[:arity]):
            h = 1e-6
            up, down = list(args), list(args)
            up[k] += h
            down[k] -= h
            call = _call(name, arity)
            expected = (x.evaluate(call, dict(zip("ab", up)))
                        - x.evaluate(call, dict(zip("ab", down)))) / (2 * h)
            assert x.evaluate(x.diff(call, var), env) == pytest.approx(
                expected, rel=1e-6, abs=1e-8), (name, var, args)


@pytest.mark.parametrize("name", MATH_NAMES)
def test_python_and_numpy_spellings_compute_the_value(name: str) -> None:
    arity = b.BUILTINS[name].arity[1]
    helpers: set[str] = set()
    text = FunctionWriter(lambda v: v, helpers).expr(_call(name, arity))
    scope: dict[str, Any] = {"math": math, "np": np}
    for helper in helpers:
        exec(b.PYTHON_HELPERS[helper], scope)  # the registry's own text
    vector = NumpyWriter(lambda v: v, set()).expr(_call(name, arity))
    columns = [np.array([_args(name, p)[k] for p in POINTS]) for k in range(arity)]
    got = eval(vector, {"np": np}, dict(zip("ab", columns)))
    for row, point in enumerate(POINTS):
        args = _args(name, point)
        want = float(REFERENCE[name](*args))
        assert eval(text, scope, dict(zip("ab", args))) == pytest.approx(
            want, rel=1e-15, abs=1e-15)
        assert got[row] == pytest.approx(want, rel=1e-15, abs=1e-15)


def test_transparent_operators_print_their_argument() -> None:
    writer = FunctionWriter(lambda v: v, set())
    smooth = x.Call("smooth", (x.Const(1), x.Call("noEvent", (x.Var("a"),))))
    assert writer.expr(smooth) == "a"
    assert writer.expr(x.Call("homotopy", (x.Var("a"), x.Var("b")))) == "a"


@pytest.fixture(scope="module")
def c_library(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    """libm with the registry's C helpers, compiled by the C compiler springc finds."""
    folder = tmp_path_factory.mktemp("c_helpers")
    source = folder / "helpers.c"
    source.write_text("#include <math.h>\n#define SPRINGC_FN\n"
                      + "\n".join(b.C_HELPERS.values()) + "\n")
    library = folder / "helpers.so"
    subprocess.run([*find_compiler(), "-std=c99", "-shared", "-fPIC", "-o", str(library),
                    str(source), "-lm"], check=True, capture_output=True, timeout=120)
    return ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)


@pytest.mark.parametrize("name", MATH_NAMES)
def test_c_spelling_computes_the_value(name: str, c_library: ctypes.CDLL) -> None:
    entry = b.BUILTINS[name]
    assert entry.c is None or entry.c in C99_MATH
    assert entry.c_call is not None
    source = c_library if entry.c is None else ctypes.CDLL(ctypes.util.find_library("m"))
    function = getattr(source, entry.c_call)
    function.restype = ctypes.c_double
    function.argtypes = [ctypes.c_double] * entry.arity[1]
    for point in [*POINTS, (0.5, 0.5)]:  # with a tie
        args = _args(name, point)
        assert function(*args) == pytest.approx(float(REFERENCE[name](*args)),
                                                rel=1e-15, abs=1e-15)


def test_c_spellings() -> None:
    spelled = {n: b.BUILTINS[n].c for n in MATH_NAMES}
    assert spelled["abs"] == "fabs" and spelled["rem"] == "fmod"
    assert spelled["integer"] == "floor" and spelled["ceil"] == "ceil"
    assert {n for n, c in spelled.items() if c is None} == {"sign", "mod", "div", "min",
                                                            "max"}
    assert b.BUILTINS["sign"].c_call == "springc_sign"
    assert b.BUILTINS["sqrt"].c_call == "sqrt"
    assert b.BUILTINS["noEvent"].c_call is None


@pytest.mark.parametrize("name", sorted(b.names(lambda e: e.sympy is not None)))
def test_latex_form_has_the_value(name: str) -> None:
    arity = b.BUILTINS[name].arity[1]
    form = latex.to_sympy(_call(name, arity))
    for point in POINTS:
        args = _args(name, point)
        value = form.subs({latex.to_sympy(x.Var(v)): a for v, a in zip("ab", args)})
        assert float(value) == pytest.approx(float(REFERENCE[name](*args)), rel=1e-12,
                                             abs=1e-12)


def test_every_built_in_is_documented() -> None:
    text = (ROOT / "docs" / "language.md").read_text()
    section = text[text.index("## Built-ins"):text.index("## Annotations")]
    missing = [n for n in b.BUILTINS if not re.search(rf"\b{n}\b", section)]
    assert missing == []


def test_unknown_names() -> None:
    assert b.lookup("spline") is None
    with pytest.raises(ValueError, match=r"cannot differentiate delay\(\.\.\.\)"):
        x.diff(x.Call("delay", (x.Var("a"), x.Const(1.0))), "a")


@pytest.mark.parametrize("writer", [FunctionWriter, NumpyWriter])
@pytest.mark.parametrize("name", ["spline", "pre", "delay", "sum"])
def test_printers_refuse_what_the_registry_gives_no_spelling(
        writer: type[FunctionWriter], name: str) -> None:
    with pytest.raises(CodegenError,
                       match=rf"\Aerror: cannot generate code for the function '{name}'\Z"):
        writer(lambda v: v, set()).expr(x.Call(name, (x.Var("a"),)))


@pytest.mark.parametrize("name", ["pre", "edge", "change", "sample", "initial", "terminal"])
def test_event_operators_are_constant_between_events(name: str) -> None:
    """Section 3.7.5: their values change only at events, so d/dt is 0 between them."""
    arity = b.BUILTINS[name].arity[1]
    call = x.Call(name, tuple(x.Var(v) for v in "ab"[:arity]))
    assert x.diff(call, "a") == x.ZERO
