"""Statements of generated functions (:mod:`.statements`) -> C99 source lines.

The C writer is the Python writer (:class:`.printer.FunctionWriter`: the expression
walk, common subexpressions, operator precedence) with C spelling: ``;`` and braces,
``/* */`` comments, ``pow``, ``&&``, ``?:``, doubles for every number. The printed
code is also CUDA device code: only ``<math.h>`` functions and the helpers below.

Model text reaches C only through :func:`c_string` (string literals), :func:`c_comment`
(comments) and the namer (identifiers, with C's and C++'s reserved words taken).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence

from ..ir.builtins import BUILTINS, C_HELPERS
from ..ir.expr import BinOp, Call, Const, Expr, If, Neg, Not, Time
from ..native.foreign_calls import is_foreign
from .locate import untranslatable
from .printer import FunctionWriter
from .statements import Stmt, prune

# The C spelling of each built-in function is the registry's (``Builtin.c_call``); a
# helper of C_HELPERS that a call names is defined in the file that uses it.
C_FUNCTIONS = {name: entry.c_call for name, entry in BUILTINS.items()
               if entry.c_call is not None}
HELPERS = C_HELPERS

# Identifiers a model name must not become: C and C++ keywords (CUDA compiles C++),
# <math.h>'s functions and macros, CUDA's qualifiers, and the names of the C model file.
_RESERVED_WORDS = (
    "auto break case char const continue default do double else enum extern float for goto if "
    "inline int long register restrict return short signed sizeof static struct switch "
    "typedef union unsigned void volatile while _Bool _Complex _Imaginary bool true false "
    "alignas alignof and and_eq asm bitand bitor catch class compl const_cast constexpr "
    "decltype delete dynamic_cast explicit export friend mutable namespace new noexcept not "
    "not_eq nullptr operator or or_eq private protected public reinterpret_cast static_assert "
    "static_cast template this thread_local throw try typeid typename using virtual wchar_t "
    "xor xor_eq char16_t char32_t override final main std NULL acos acosh asin asinh atan "
    "atan2 atanh cbrt ceil copysign cos cosh erf erfc exp exp2 expm1 fabs fdim floor fma fmax "
    "fmin fmod frexp hypot ilogb ldexp lgamma llrint llround log log10 log1p log2 logb lrint "
    "lround modf nan nearbyint nextafter nexttoward pow remainder remquo rint round scalbln "
    "scalbn sin sinh sqrt tan tanh tgamma trunc j0 j1 jn y0 y1 yn gamma isnan isinf isfinite "
    "isnormal signbit fpclassify isgreater isless isgreaterequal islessequal islessgreater "
    "isunordered HUGE_VAL HUGE_VALF HUGE_VALL INFINITY NAN FP_NAN FP_INFINITE FP_ZERO "
    "FP_NORMAL FP_SUBNORMAL FP_ILOGB0 FP_ILOGBNAN MATH_ERRNO MATH_ERREXCEPT math_errhandling "
    "M_E M_LOG2E M_LOG10E M_LN2 M_LN10 M_PI M_PI_2 M_PI_4 M_1_PI M_2_PI M_2_SQRTPI M_SQRT2 "
    "M_SQRT1_2 errno __device__ __host__ __global__ __forceinline__ __constant__ __shared__ t "
    "x p z dx g out xn given n "
)
C_RESERVED = frozenset(_RESERVED_WORDS.split()) | frozenset(HELPERS)

_PLAIN = re.compile(r"[\x20\x21\x23-\x3e\x40-\x5b\x5d-\x7e]*")
"""Printable ASCII but ``"``, ``?`` and ``\\``: a C string literal as it is."""
_C_PREC_OP = {"<>": "!=", "==": "==", "and": "&&", "or": "||"}


def c_string(text: str) -> str:
    """``text`` as a C string literal: its UTF-8 bytes, printable ASCII as itself except
    ``"``, ``\\`` and ``?`` (no trigraph can form), every other byte a 3-digit octal
    escape (which cannot run into a following digit)."""
    if _PLAIN.fullmatch(text):  # most names: nothing to escape
        return '"' + text + '"'
    out = []
    for byte in text.encode("utf-8"):
        char = chr(byte)
        if 32 <= byte < 127 and char not in '"\\?':
            out.append(char)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def c_comment(text: str) -> str:
    """``text`` as the inside of a ``/* */`` comment: printable ASCII, with ``*``,
    ``\\``, ``?``, ``%`` and every other byte percent-encoded (no ``*/``, no line
    splice, no trigraph can form)."""
    out = []
    for byte in text.encode("utf-8"):
        char = chr(byte)
        out.append(char if 32 <= byte < 127 and char not in "*\\?%" else f"%{byte:02X}")
    return "".join(out)


def c_double(value: float) -> str:
    """A C double literal of exactly ``value`` (Python's shortest round-trip text)."""
    if math.isnan(value):
        return "SPRINGC_NAN"
    if math.isinf(value):
        return "SPRINGC_INF" if value > 0 else "-SPRINGC_INF"
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


class CWriter(FunctionWriter):
    """Prints one C function body; every local it assigns is a ``double`` declared at
    the top (:func:`c_function_body`)."""

    foreign_calls = False
    writes = "the C model"

    block_end = "}"

    def __init__(self, namer: Callable[[str], str], helpers: set[str],
                 indent: str = "    ") -> None:
        super().__init__(namer, helpers, indent)
        self.declared: dict[str, None] = {}

    def _emit(self, text: str, comment: str = "") -> None:
        line = self._indent + text
        if comment:
            line += "  /* " + c_comment(comment) + " */"
        self.lines.append(line)

    def _assign(self, target: str, text: str, comment: str = "") -> None:
        self._emit(f"{target} = {text};", comment)

    def _comment(self, text: str) -> None:
        self._emit("/* " + c_comment(text) + " */")

    def guard_header(self, cond: str) -> str:
        return f"if ({cond}) {{"

    def _reassigned(self, name: str) -> None:
        self.declared[self.name(name)] = None
        super()._reassigned(name)

    def _remember(self, cid: int, name: str, e: Expr) -> None:
        self.declared[name] = None
        super()._remember(cid, name, e)

    def _print_Const(self, e: Const) -> tuple[str, int]:
        v = e.value
        if isinstance(v, bool):
            return ("1.0" if v else "0.0"), 9
        if not isinstance(v, (int, float)):
            raise untranslatable(f"cannot generate C code for the constant {v!r}", e)
        text = c_double(float(v))
        return text, (7 if text.startswith("-") else 9)

    def _print_Time(self, e: Time) -> tuple[str, int]:
        return "t", 9

    def _print_Neg(self, e: Neg) -> tuple[str, int]:
        inner = self.expr(e.arg, 7)
        return ("-(" + inner + ")" if inner.startswith("-") else "-" + inner), 7

    def _print_Not(self, e: Not) -> tuple[str, int]:
        return "!" + self.expr(e.arg, 9), 7

    def _print_BinOp(self, e: BinOp) -> tuple[str, int]:
        op = e.op
        if op == "^":
            return f"pow({self.expr(e.left)}, {self.expr(e.right)})", 9
        prec = _c_precedence(op)
        if op in ("==", "<>") or prec == 4:  # equality binds looser than <, <=, >, >= in C
            left, right = self.expr(e.left, 5), self.expr(e.right, 5)
        elif op == "or":  # && inside || in parentheses (-Wparentheses)
            left, right = self.expr(e.left, 3), self.expr(e.right, 3)
        else:
            left, right = self.expr(e.left, prec), self.expr(e.right, prec + 1)
        return f"{left} {_C_PREC_OP.get(op, op)} {right}", prec

    def _print_Call(self, e: Call) -> tuple[str, int]:
        name = e.name
        if is_foreign(name):
            return self._foreign_output(e), 9  # refused: foreign_calls is False
        entry = BUILTINS.get(name)
        if entry is not None and entry.transparent is not None:
            return self._shared(e.args[entry.transparent])
        spelled = C_FUNCTIONS.get(name)
        if spelled is None or not e.args:
            raise untranslatable(f"cannot generate C code for the function '{name}'", e)
        if spelled in HELPERS:
            self.helpers.add(spelled)
        if name in ("min", "max") and len(e.args) != 2:
            text = self.expr(e.args[0])
            for a in e.args[1:]:
                text = f"{spelled}({text}, {self.expr(a)})"
            return text, 9
        return f"{spelled}({', '.join(self.expr(a) for a in e.args)})", 9

    def _print_If(self, e: If) -> tuple[str, int]:
        cond = self.expr(e.cond, 1)
        self._in_branch += 1
        try:
            then, other = self.expr(e.then, 1), self.expr(e.otherwise, 1)
        finally:
            self._in_branch -= 1
        return f"{cond} ? {then} : {other}", 0


def _c_precedence(op: str) -> int:
    # the Python writer's levels: or 1, and 2, relations 4, + - 5, * / 6
    return {"or": 1, "and": 2, "+": 5, "-": 5, "*": 6, "/": 6}.get(op, 4)


def c_function_body(namer: Callable[[str], str], helpers: set[str], stmts: Sequence[Stmt],
                    indent: str = "    ") -> list[str]:
    """The body of a C function computing ``stmts`` (after dead-code removal): the
    declarations of its ``double`` locals, then the statements."""
    writer = CWriter(namer, helpers, indent)
    kept = prune(stmts)
    writer.count(kept)
    writer.write(kept)
    names = list(writer.declared)
    decls = [indent + "double " + ", ".join(names[i:i + 8]) + ";"
             for i in range(0, len(names), 8)]
    return decls + writer.lines
