"""Built-in functions and constants of the language (docs/language.md, "Built-ins").

Each handler takes the call's syntax and scope and returns a value; scalar math
functions are vectorised over arrays as Modelica specifies (chapter 12.4.6).
"""

from __future__ import annotations

import math
from functools import reduce

import numpy as np

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import syntax as s
from ...ir.builtins import BUILTINS, MATH, NUMBER, names
from .. import arrays as a
from ..array_ops import ArrayBuiltins
from ..checks import check_der_argument, check_numeric_arguments
from ..scopes import EnumLiteral, ExpressionEvaluator, Handler, Scope
from .strings import string_call

SCALAR_FUNCTIONS = {name: b.arity[0] for name, b in BUILTINS.items()
                    if b.kind == MATH and b.arguments == NUMBER}
"""The scalar math built-ins of numbers and their arity (from the registry)."""

CONSTANTS = {
    "pi": math.pi, "Modelica.Constants.pi": math.pi, "Modelica.Constants.e": math.e,
    "Modelica.Constants.g_n": 9.80665, "Modelica.Constants.eps": 2.220446049250313e-16,
    "Modelica.Constants.small": 1e-60, "Modelica.Constants.inf": 1e60,
}

_ALIASES = {f"Modelica.Math.{n}": n for n in SCALAR_FUNCTIONS} | {
    "Modelica.Math.Vectors.norm": "norm",
}


class Builtins:
    def __init__(self, evaluator: ExpressionEvaluator) -> None:
        self.ev = evaluator
        self.table: dict[str, Handler] = {
            "der": self.der, "noEvent": self.no_event, "smooth": self.smooth,
            "homotopy": self.homotopy, "sum": self.sum, "product": self.product,
            "min": self.min_max, "max": self.min_max, "size": self.size, "ndims": self.ndims,
            "zeros": self.fill_value(0), "ones": self.fill_value(1), "fill": self.fill,
            "identity": self.identity, "cross": self.cross, "transpose": self.transpose,
            "norm": self.norm, "scalar": self.scalar, "vector": self.vector,
            "Integer": self.enum_ordinal,
            "String": lambda call, scope: string_call(self.ev, call, scope),
        }
        for name in SCALAR_FUNCTIONS:
            self.table[name] = self.math
        self.table.update(ArrayBuiltins(evaluator).table())

    def lookup(self, name: str, scope: Scope) -> Handler | None:
        name = _ALIASES.get(name, name)
        handler = self.table.get(name)
        if handler is None or name != "norm":
            return handler
        user = self.ev.flattener.find_function(name, scope)
        return None if user is not None else handler

    # ------------------------------------------------------------------ helpers

    def _args(self, call: s.Call, scope: Scope, count: int | tuple[int, int]) -> list[a.Value]:
        lo, hi = (count, count) if isinstance(count, int) else count
        name = call.func.dotted
        if call.named:
            raise FlattenError(f"'{name}' takes no named arguments", call.named[0].span)
        if not lo <= len(call.args) <= hi:
            expected = str(lo) if lo == hi else f"{lo} to {hi}"
            noun = "argument" if expected == "1" else "arguments"
            raise FlattenError(f"'{name}' takes {expected} {noun}, "
                               f"{len(call.args)} given", call.span)
        return [self.ev.value(arg, scope) for arg in call.args]

    def _elements(self, call: s.Call, scope: Scope) -> list[x.Expr]:
        """The elements reduced by ``sum``/``product``/``min``/``max`` of one argument."""
        if len(call.args) == 1 and isinstance(call.args[0], s.Comprehension):
            comp = call.args[0]
            values = list(self.ev.iterate(comp.body, comp.indices, scope))
            return [e for v in values for e in a.scalars(v)]
        (v,) = self._args(call, scope, 1)
        return a.scalars(v)

    # ---------------------------------------------------------------- handlers

    def der(self, call: s.Call, scope: Scope) -> a.Value:
        check_der_argument(call, scope)
        (v,) = self._args(call, scope, 1)
        return a.elementwise(lambda e: x.ZERO if isinstance(e, x.Const) else x.Der(e), v)

    def math(self, call: s.Call, scope: Scope) -> a.Value:
        name = _ALIASES.get(call.func.dotted, call.func.dotted)
        check_numeric_arguments(name, call, scope)
        args = self._args(call, scope, SCALAR_FUNCTIONS[name])
        try:
            return a.elementwise(lambda *xs: _call(name, xs), *args)
        except ValueError as err:
            raise FlattenError(str(err), call.span) from None

    def no_event(self, call: s.Call, scope: Scope) -> a.Value:
        self.ev.no_event += 1
        try:
            (v,) = self._args(call, scope, 1)
        finally:
            self.ev.no_event -= 1
        return a.elementwise(without_events, v)

    def smooth(self, call: s.Call, scope: Scope) -> a.Value:
        self.ev.no_event += 1
        try:
            _, v = self._args(call, scope, 2)
        finally:
            self.ev.no_event -= 1
        return a.elementwise(without_events, v)

    def homotopy(self, call: s.Call, scope: Scope) -> a.Value:
        actual = next((n.value for n in call.named if n.name == "actual"), None)
        if actual is not None:
            return self.ev.value(actual, scope)
        if not call.args:
            raise FlattenError("'homotopy' needs the argument 'actual'", call.span)
        return self.ev.value(call.args[0], scope)

    def sum(self, call: s.Call, scope: Scope) -> a.Value:
        return a.fold(x.add, list(self._elements(call, scope)), x.ZERO)

    def product(self, call: s.Call, scope: Scope) -> a.Value:
        return a.fold(x.mul, list(self._elements(call, scope)), x.ONE)

    def min_max(self, call: s.Call, scope: Scope) -> a.Value:
        name = call.func.dotted
        if len(call.args) == 2:
            args = self._args(call, scope, 2)
            return a.elementwise(lambda p, q: _call(name, (p, q)), *args)
        items = self._elements(call, scope)
        if not items:
            raise FlattenError(f"'{name}' of an empty array", call.span)
        return reduce(lambda p, q: _call(name, (p, q)), items)

    def size(self, call: s.Call, scope: Scope) -> a.Value:
        if len(call.args) == 1:
            (v,) = self._args(call, scope, 1)
            return a.make_array([x.Const(d) for d in a.shape(v)])
        if len(call.args) != 2 or call.named:
            self._args(call, scope, 2)  # reports the wrong arguments
        v = self.ev.value(call.args[0], scope)
        k = self.ev.integer(call.args[1], scope, "the dimension of 'size'")
        dims = a.shape(v)
        if not 1 <= k <= len(dims):
            raise FlattenError(f"dimension {k} does not exist: the array has {len(dims)}",
                               call.args[1].span)
        return x.Const(dims[k - 1])

    def ndims(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, scope, 1)
        return x.Const(len(a.shape(v)))

    def _dims(self, call: s.Call, scope: Scope, args: list[s.Expr], square: bool = False
              ) -> tuple[int, ...]:
        dims = tuple(self.ev.integer(arg, scope, "an array size") for arg in args)
        for n in dims:
            if n < 0:
                raise FlattenError(f"array size must not be negative, found {n}", call.span)
        count = math.prod(dims) ** (2 if square else 1)
        self.ev.flattener.limits.check_size(count, f"the result of '{call.func.dotted}'",
                                            call.span)
        return dims

    def fill_value(self, value: int) -> Handler:
        def handler(call: s.Call, scope: Scope) -> a.Value:
            dims = self._dims(call, scope, list(call.args))
            return a.make_array([x.Const(value)] * math.prod(dims), dims)
        return handler

    def fill(self, call: s.Call, scope: Scope) -> a.Value:
        if not call.args:
            raise FlattenError("'fill' needs a value and sizes", call.span)
        v = self.ev.value(call.args[0], scope)
        dims = self._dims(call, scope, list(call.args[1:]))
        out = np.empty(dims + a.shape(v), dtype=object)
        for idx in np.ndindex(dims):
            out[idx] = v
        return out

    def identity(self, call: s.Call, scope: Scope) -> a.Value:
        if len(call.args) != 1:
            raise FlattenError(f"'identity' takes 1 argument, {len(call.args)} given",
                               call.span)
        (n,) = self._dims(call, scope, list(call.args), square=True)
        return a.make_array([x.Const(int(i == j)) for i in range(n) for j in range(n)], (n, n))

    def cross(self, call: s.Call, scope: Scope) -> a.Value:
        u, v = self._args(call, scope, 2)
        if not isinstance(u, np.ndarray) or not isinstance(v, np.ndarray) \
                or u.shape != (3,) or v.shape != (3,):
            raise FlattenError("'cross' needs two vectors of size 3", call.span)
        comps = [x.sub(x.mul(u[(i + 1) % 3], v[(i + 2) % 3]),
                       x.mul(u[(i + 2) % 3], v[(i + 1) % 3])) for i in range(3)]
        return a.make_array(comps)

    def transpose(self, call: s.Call, scope: Scope) -> a.Value:
        (m,) = self._args(call, scope, 1)
        if not isinstance(m, np.ndarray) or m.ndim < 2:
            raise FlattenError("'transpose' needs a matrix", call.span)
        return np.swapaxes(m, 0, 1)

    def norm(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, scope, 1)
        if not isinstance(v, np.ndarray) or v.ndim != 1:
            raise FlattenError("'norm' needs a vector", call.span)
        return _call("sqrt", (a.dot(v, v),))

    def scalar(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, scope, 1)
        items = a.scalars(v)
        if len(items) != 1:
            raise FlattenError("'scalar' needs an array with one element", call.span)
        return items[0]

    def enum_ordinal(self, call: s.Call, scope: Scope) -> a.Value:
        """``Integer(E.b)``: the ordinal of an enumeration value (enumeration values are
        their ordinals already, Modelica 4.9.5.2)."""
        (v,) = self._args(call, scope, 1)
        return a.elementwise(lambda e: x.Const(int(e.value)) if isinstance(e, x.Const)
                             and isinstance(e.value, EnumLiteral) else e, v)

    def vector(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, scope, 1)
        return a.make_array(a.scalars(v))


def _call(name: str, args: tuple[x.Expr, ...]) -> x.Expr:
    """A scalar built-in call, folded when every argument is a constant."""
    if all(isinstance(arg, x.Const) for arg in args):
        try:
            return x.Const(x.MATH[name](*(arg.value for arg in args)))  # type: ignore[union-attr]
        except (ValueError, ZeroDivisionError, OverflowError) as err:
            text = f"{name}({', '.join(repr(arg.value) for arg in args)})"  # type: ignore[union-attr]
            reason = "overflows" if isinstance(err, OverflowError) else f"is undefined ({err})"
            raise ValueError(f"{text} {reason}") from None
    return x.Call(name, args)


_SWITCHING_CALLS = names(lambda b: b.switching)


def switches(name: str) -> bool:
    """Whether the built-in called ``name`` (``abs``, ``Modelica.Math.floor``...) jumps
    where its arguments cross a switch: an event outside ``noEvent``."""
    return _ALIASES.get(name, name) in _SWITCHING_CALLS


def without_events(e: x.Expr) -> x.Expr:
    """``noEvent(e)``: ``noEvent`` only matters around relations and the built-ins that
    would switch at events (3.7.2); elsewhere it is dropped."""
    has_switch = any(isinstance(n, x.If) or (isinstance(n, x.BinOp) and n.op in x.RELATIONS)
                     or (isinstance(n, x.Call) and n.name in _SWITCHING_CALLS)
                     for n in x.walk(e))
    return x.Call("noEvent", (e,)) if has_switch else e
