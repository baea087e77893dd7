"""The one registry of springc's built-in functions and event operators.

Every stage reads :data:`BUILTINS` instead of a name set of its own: flattening its
arity, argument and result types (``flatten/calls/builtins``, ``checks/type_rules``,
``checks/enum_rules``, ``events/event_calls``, ``events/when``), :mod:`springc.ir.expr`
its constant evaluation and
derivative, :mod:`springc.ir.latex` its sympy function, ``codegen`` its Python (numba)
and numpy spellings, ``simplify/events`` and ``codegen/event_layout`` the event
properties, ``units`` the unit rule; a C printer its C99 ``<math.h>`` spelling.

Adding a built-in is one :class:`Builtin` entry here (plus its flattening handler where
it is evaluated away while flattening, and a line in ``docs/language.md``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from . import nodes as n

__all__ = [
    "ANY", "ARRAY", "BOOLEAN", "BUILTINS", "C_HELPERS", "EQUATION", "EVENT", "INTEGER",
    "MATH", "NUMBER", "OPERATOR", "PARAMETER", "PYTHON_HELPERS", "REAL", "SAME", "STRING",
    "VARIABLE", "Builtin", "Derivative", "lookup", "names",
]

# The types of arguments and results.
REAL = "Real"
INTEGER = "Integer"
BOOLEAN = "Boolean"
STRING = "String"
NUMBER = "number"
"""Integer or Real (as the arguments): never Boolean, String or an enumeration."""
SAME = "same"
"""The type of the argument (the last one for ``smooth``): may be Boolean or an
enumeration."""
ANY = "any"
VARIABLE = "variable"
"""A variable (element-wise over an array of them): ``pre(v)``, ``edge(b)``."""
PARAMETER = "parameter"
"""Parameter expressions: ``sample(start, interval)``."""

# The kinds of built-ins.
MATH = "math"
"""A scalar function that stays in the flat model (element-wise over arrays)."""
OPERATOR = "operator"
"""An operator that stays in the flat model and is no plain function (``noEvent``,
``smooth``, ``homotopy``, ``delay``, ``der``)."""
EVENT = "event"
"""An event operator (Modelica 3.6, 3.7.5): its value depends on the instant."""
EQUATION = "equation"
"""Stands only as an equation or statement (``reinit``, ``terminate``, ``print``)."""
ARRAY = "array"
"""Evaluated while flattening: array constructors and reductions, sizes, conversions."""

Derivative = Callable[[n.Call, Callable[[n.Expr], n.Expr]], n.Expr]
"""``(call, d)`` -> the derivative of ``call``, with ``d`` differentiating an argument."""
SympyForm = Callable[[Any, tuple[Any, ...]], Any]
"""``(sympy, args)`` -> the sympy expression of a call (LaTeX goes through sympy)."""


@dataclass(frozen=True)
class Builtin:
    """Everything springc knows about one built-in name."""

    name: str
    kind: str
    arity: tuple[int, int]
    """Fewest and most positional arguments."""
    arguments: str
    result: str
    doc: str
    evaluate: Callable[..., Any] | None = None
    """The value for constant arguments (None: it has none, e.g. an event operator)."""
    derivative: Derivative | None = None
    python: str | None = None
    """Spelling in generated Python (CPython and numba): ``math.sqrt`` (called with the
    arguments), or a ``{}`` template for them; None: not printable (or transparent)."""
    numpy: str | None = None
    """Spelling over numpy arrays, as :attr:`python`."""
    c: str | None = None
    """The C99 ``<math.h>`` function (``abs`` -> ``fabs``); None where C99 has none of
    the same values (:data:`C_HELPERS` defines those of the math built-ins, see
    :attr:`c_call`)."""
    sympy: SympyForm | None = None
    transparent: int | None = None
    """The argument whose value this is (``noEvent(x)`` is ``x``, ``smooth(p, x)`` is
    ``x``): printed as that argument."""
    quiet: bool = False
    """Relations inside generate no events (``noEvent``, ``smooth``)."""
    switching: bool = False
    """Its value jumps where its arguments cross a switch: an event outside ``noEvent``
    (Modelica 3.7.2)."""
    floored: bool = False
    """Integer-valued: written with ``floor`` when its arguments vary continuously."""
    discrete: bool = False
    """A discrete-time value whatever its arguments (3.8.4)."""
    reads_pre: bool = False
    """Reads the left limit of its variable (``pre``, ``edge``, ``change``)."""
    phase: bool = False
    """True during one phase of a run (``initial()``, ``terminal()``)."""
    at_events: bool = False
    """An event operator, or an equation that acts at events (``reinit``,
    ``terminate``): its value or effect depends on the instant."""
    unit: str = ""
    """The unit rule (units/check.py): ``dimensionless`` (argument 1, result 1),
    ``same`` (arguments agree, result theirs), ``first`` (the first argument's),
    ``last``, ``sqrt``, ``quotient``, ``one`` (result 1), ``atan2``; empty: none."""

    @property
    def c_call(self) -> str | None:
        """The C function a call is printed with: :attr:`c`, else the helper
        ``springc_<name>`` of :data:`C_HELPERS` (None: neither, not a math built-in)."""
        helper = f"springc_{self.name}"
        return self.c if self.c is not None else (helper if helper in C_HELPERS else None)

    @property
    def boolean(self) -> bool:
        """Whether its value is a Boolean (never an operand of arithmetic)."""
        return self.result == BOOLEAN


# ------------------------------------------------------------------ derivatives


def _chain(outer: Callable[[n.Expr, n.Call], n.Expr]) -> Derivative:
    """The chain rule ``f'(x) dx`` for a function of one argument."""
    def rule(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
        return n.mul(outer(call.args[0], call), d(call.args[0]))
    return rule


def _between_events(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    """An event operator's value is constant between events (section 3.7.5)."""
    return n.ZERO


def _zero(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    d(call.args[0])  # refused where its argument cannot be differentiated
    return n.ZERO  # piecewise constant


def _first(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return d(call.args[0])


def _mod(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    a, b = call.args  # mod(a, b) = a - floor(a/b)*b, floor piecewise constant
    return n.sub(d(a), n.mul(n.Call("floor", (n.div(a, b),)), d(b)))


def _rem(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    a, b = call.args  # rem(a, b) = a - div(a, b)*b, div piecewise constant
    return n.sub(d(a), n.mul(n.Call("div", (a, b)), d(b)))


def _sqrt(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.div(d(call.args[0]), n.mul(n.Const(2), call))


def _cos(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.neg(n.mul(n.Call("sin", call.args), d(call.args[0])))


def _tan(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.div(d(call.args[0]), n.power(n.Call("cos", call.args), n.Const(2)))


def _asin(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    x = call.args[0]
    return n.div(d(x), n.Call("sqrt", (n.sub(n.ONE, n.mul(x, x)),)))


def _acos(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.neg(_asin(call, d))


def _atan(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    x = call.args[0]
    return n.div(d(x), n.add(n.ONE, n.mul(x, x)))


def _log(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.div(d(call.args[0]), call.args[0])


def _log10(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    x = call.args[0]
    return n.div(d(x), n.mul(x, n.Const(math.log(10))))


def _atan2(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    y, x = call.args
    return n.div(n.sub(n.mul(x, d(y)), n.mul(y, d(x))), n.add(n.mul(x, x), n.mul(y, y)))


def _min_max(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    a, b = call.args
    cond = n.BinOp("<" if call.name == "min" else ">", a, b)
    return n.If(n.Call("noEvent", (cond,)), d(a), d(b))


def _no_event(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.Call("noEvent", (d(call.args[0]),))


def _smooth(call: n.Call, d: Callable[[n.Expr], n.Expr]) -> n.Expr:
    return n.Call("smooth", (call.args[0], d(call.args[1])))


# ------------------------------------------------------------------ the table


def _sp(name: str) -> SympyForm:
    """The sympy function ``name`` applied to the arguments."""
    return lambda sp, args: getattr(sp, name)(*args)


def _math(name: str, arity: int, doc: str, evaluate: Callable[..., Any],
          derivative: Derivative, *, python: str | None = None, numpy: str | None = None,
          c: str | None, sympy: SympyForm | None = None, result: str = REAL,
          unit: str = "dimensionless", switching: bool = False,
          floored: bool = False, in_sympy: bool = True) -> Builtin:
    """A math built-in; its Python spelling defaults to ``math.<name>``, numpy's to
    ``np.<name>``, sympy's to the sympy function of that name (``in_sympy=False``:
    none, an undefined function is shown)."""
    return Builtin(name, MATH, (arity, arity), NUMBER, result, doc, evaluate, derivative,
                   python or f"math.{name}", numpy or f"np.{name}", c,
                   (sympy or _sp(name)) if in_sympy else None, switching=switching, floored=floored,
                   discrete=floored, unit=unit)


def _sign(v: float) -> int:
    return int(v > 0) - int(v < 0)


def _modulus(a: Any, b: Any) -> Any:
    return a - math.floor(a / b) * b


def _remainder(a: Any, b: Any) -> float:
    return math.fmod(a, b)


def _div(a: float, b: float) -> int:
    return math.trunc(a / b)


_MATH_ENTRIES = (
    _math("sqrt", 1, "square root", math.sqrt, _sqrt, c="sqrt", unit="sqrt"),
    _math("sin", 1, "sine", math.sin, _chain(lambda x, e: n.Call("cos", (x,))), c="sin"),
    _math("cos", 1, "cosine", math.cos, _cos, c="cos"),
    _math("tan", 1, "tangent", math.tan, _tan, c="tan"),
    _math("asin", 1, "inverse sine", math.asin, _asin, numpy="np.arcsin", c="asin"),
    _math("acos", 1, "inverse cosine", math.acos, _acos, numpy="np.arccos", c="acos"),
    _math("atan", 1, "inverse tangent", math.atan, _atan, numpy="np.arctan", c="atan"),
    _math("atan2", 2, "four-quadrant inverse tangent of y/x", math.atan2, _atan2,
          numpy="np.arctan2", c="atan2", unit="atan2"),
    _math("sinh", 1, "hyperbolic sine", math.sinh,
          _chain(lambda x, e: n.Call("cosh", (x,))), c="sinh"),
    _math("cosh", 1, "hyperbolic cosine", math.cosh,
          _chain(lambda x, e: n.Call("sinh", (x,))), c="cosh"),
    _math("tanh", 1, "hyperbolic tangent", math.tanh,
          _chain(lambda x, e: n.sub(n.ONE, n.mul(e, e))), c="tanh"),
    _math("exp", 1, "exponential", math.exp, _chain(lambda x, e: e), c="exp"),
    _math("log", 1, "natural logarithm", math.log, _log, c="log"),
    _math("log10", 1, "base-10 logarithm", math.log10, _log10, c="log10",
          sympy=lambda sp, args: sp.log(args[0], 10)),
    _math("abs", 1, "absolute value", abs, _chain(lambda x, e: n.Call("sign", (x,))),
          python="abs", c="fabs", sympy=_sp("Abs"), result=NUMBER, unit="same",
          switching=True),
    _math("sign", 1, "-1, 0 or 1", _sign, _zero, python="_sign", c=None,
          result=INTEGER, unit="one", switching=True),
    _math("floor", 1, "largest integral value not above", math.floor, _zero, c="floor",
          result=NUMBER, unit="same", switching=True, floored=True),
    _math("ceil", 1, "smallest integral value not below", math.ceil, _zero, c="ceil",
          sympy=_sp("ceiling"), result=NUMBER, unit="same", switching=True, floored=True),
    _math("integer", 1, "largest Integer not above", math.floor, _zero,
          python="math.floor", numpy="np.floor", c="floor", sympy=_sp("floor"),
          result=INTEGER, unit="same", switching=True, floored=True),
    _math("mod", 2, "modulus, x - floor(x/y)*y", _modulus, _mod, python="_mod", c=None,
          sympy=_sp("Mod"), result=NUMBER, unit="same", switching=True, floored=True),
    _math("rem", 2, "remainder, x - div(x, y)*y", _remainder, _rem, python="math.fmod",
          numpy="np.fmod", c="fmod", in_sympy=False, result=NUMBER, unit="same",
          switching=True, floored=True),
    _math("div", 2, "quotient truncated toward zero", _div, _zero, python="_div",
          numpy="np.trunc(np.divide({}))", c=None, in_sympy=False, result=NUMBER,
          unit="quotient", switching=True, floored=True),
)

_MIN_MAX = tuple(
    Builtin(name, MATH, (1, 2), ANY, SAME,
            f"the {'smaller' if name == 'min' else 'larger'} of two values, or the "
            f"{'least' if name == 'min' else 'greatest'} element of an array",
            fn, _min_max, name, f"np.{name}imum", None, _sp(name.capitalize()),
            switching=True, unit="same")
    for name, fn in (("min", min), ("max", max)))

_OPERATORS = (
    Builtin("noEvent", OPERATOR, (1, 1), ANY, SAME,
            "its argument, without events from the relations inside",
            lambda v: v, _no_event, transparent=0, quiet=True, unit="same"),
    Builtin("smooth", OPERATOR, (2, 2), ANY, SAME,
            "its second argument, continuous to the order of the first: no events",
            lambda p, v: v, _smooth, transparent=1, quiet=True, unit="last"),
    Builtin("homotopy", OPERATOR, (1, 2), ANY, SAME,
            "its argument 'actual' (springc does not use the simplified model)",
            lambda actual, simplified: actual, _first, transparent=0, unit="same"),
    Builtin("delay", OPERATOR, (2, 3), ANY, SAME,
            "the value of an expression delayTime ago, from its history", unit="first"),
    Builtin("der", OPERATOR, (1, 1), REAL, REAL, "the time derivative"),
)

_EVENTS = (
    Builtin("pre", EVENT, (1, 1), VARIABLE, SAME,
            "the left limit of a variable at an event", discrete=True, reads_pre=True,
            unit="same", at_events=True, derivative=_between_events),
    Builtin("edge", EVENT, (1, 1), VARIABLE, BOOLEAN, "b and not pre(b)", discrete=True,
            reads_pre=True, at_events=True, derivative=_between_events),
    Builtin("change", EVENT, (1, 1), VARIABLE, BOOLEAN, "v <> pre(v)", discrete=True,
            reads_pre=True, at_events=True, derivative=_between_events),
    Builtin("initial", EVENT, (0, 0), ANY, BOOLEAN, "true during initialization",
            discrete=True, phase=True, at_events=True, derivative=_between_events),
    Builtin("terminal", EVENT, (0, 0), ANY, BOOLEAN, "true at the end of the run",
            discrete=True, phase=True, at_events=True, derivative=_between_events),
    Builtin("sample", EVENT, (2, 2), PARAMETER, BOOLEAN,
            "true at start + k*interval (time events)", discrete=True, at_events=True,
            derivative=_between_events),
    Builtin("reinit", EQUATION, (2, 2), ANY, ANY,
            "reinit(x, value): a state takes a new value at an event", at_events=True),
    Builtin("terminate", EQUATION, (1, 1), STRING, ANY, "ends the run at an event",
            at_events=True),
    Builtin("print", EQUATION, (1, 1), STRING, ANY, "prints a String (not supported yet)"),
)


def _array(name: str, arity: tuple[int, int], arguments: str, result: str, doc: str,
           discrete: bool = False, unit: str = "") -> Builtin:
    return Builtin(name, ARRAY, arity, arguments, result, doc, discrete=discrete, unit=unit)


_MANY = 1 << 16
_ARRAYS = (
    _array("sum", (1, 1), NUMBER, NUMBER, "sum of the elements", unit="same"),
    _array("product", (1, 1), NUMBER, NUMBER, "product of the elements"),
    _array("size", (1, 2), ANY, INTEGER, "sizes of an array, or size along a dimension",
           discrete=True),
    _array("ndims", (1, 1), ANY, INTEGER, "number of dimensions", discrete=True),
    _array("zeros", (0, _MANY), INTEGER, INTEGER, "an array of zeros"),
    _array("ones", (0, _MANY), INTEGER, INTEGER, "an array of ones"),
    _array("fill", (1, _MANY), ANY, SAME, "an array filled with a value"),
    _array("identity", (1, 1), INTEGER, INTEGER, "identity matrix"),
    _array("cross", (2, 2), NUMBER, NUMBER, "cross product of two 3-vectors"),
    _array("transpose", (1, 1), ANY, SAME, "matrix transpose"),
    _array("norm", (1, 1), NUMBER, REAL, "Euclidean norm of a vector"),
    _array("scalar", (1, 1), ANY, SAME, "the element of a one-element array"),
    _array("vector", (1, 1), ANY, SAME, "an array as a vector"),
    _array("cat", (1, _MANY), ANY, SAME, "concatenation along a dimension"),
    _array("matrix", (1, 1), ANY, SAME, "an array as a matrix"),
    _array("outerProduct", (2, 2), NUMBER, NUMBER, "outer product of two vectors"),
    _array("skew", (1, 1), NUMBER, NUMBER, "skew-symmetric matrix of a 3-vector"),
    _array("diagonal", (1, 1), ANY, SAME, "diagonal matrix of a vector"),
    _array("symmetric", (1, 1), ANY, SAME, "symmetric matrix from the upper triangle"),
    _array("linspace", (3, 3), NUMBER, REAL, "n equally spaced values"),
    _array("semiLinear", (3, 3), NUMBER, NUMBER, "if x >= 0 then k1*x else k2*x"),
    _array("Integer", (1, 1), ANY, INTEGER, "ordinal of an enumeration value"),
    _array("String", (1, 3), ANY, STRING, "text of a value"),
    _array("cardinality", (1, 1), ANY, INTEGER, "number of connections of a connector",
           discrete=True),
)

BUILTINS: Mapping[str, Builtin] = {
    b.name: b for b in (*_MATH_ENTRIES, *_MIN_MAX, *_OPERATORS, *_EVENTS, *_ARRAYS)}
"""Every built-in name springc knows, by name."""


def lookup(name: str) -> Builtin | None:
    """The built-in ``name`` (None: not a built-in)."""
    return BUILTINS.get(name)


def names(test: Callable[[Builtin], bool]) -> frozenset[str]:
    """The names of the built-ins for which ``test`` holds, e.g.
    ``names(lambda b: b.quiet)``."""
    return frozenset(name for name, b in BUILTINS.items() if test(b))


PYTHON_HELPERS: Mapping[str, str] = {
    "_sign": "def _sign(a):\n    return 1.0 if a > 0 else (-1.0 if a < 0 else 0.0)\n",
    "_mod": "def _mod(a, b):\n    return a - math.floor(a / b) * b\n",
    "_div": "def _div(a, b):\n    return float(math.trunc(a / b))\n",
}
"""The functions of generated Python that :attr:`Builtin.python` names ``_<name>``."""

C_HELPERS: Mapping[str, str] = {
    # Python's min and max: the first argument unless the second is smaller (larger);
    # C99's fmin and fmax differ where an argument is NaN
    "springc_min": "SPRINGC_FN double springc_min(double a, double b)\n"
                   "{\n    return b < a ? b : a;\n}",
    "springc_max": "SPRINGC_FN double springc_max(double a, double b)\n"
                   "{\n    return b > a ? b : a;\n}",
    "springc_sign": "SPRINGC_FN double springc_sign(double a)\n"
                    "{\n    return a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : 0.0);\n}",
    "springc_mod": "SPRINGC_FN double springc_mod(double a, double b)\n"
                   "{\n    return a - floor(a / b) * b;\n}",
    "springc_div": "SPRINGC_FN double springc_div(double a, double b)\n"
                   "{\n    return trunc(a / b);\n}",
}
"""C99 definitions of the math built-ins C99 has no function of the same values for,
by name (``springc_<built-in>``, :attr:`Builtin.c_call`); ``SPRINGC_FN`` is the C
printer's qualifier macro (``static inline``, or ``__device__`` for CUDA)."""
