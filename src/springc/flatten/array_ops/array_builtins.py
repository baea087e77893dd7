"""Array built-ins of chapter 10 beyond the basic ones of :mod:`.builtins`: ``cat``
(10.4.2), ``matrix`` (10.3.1), ``outerProduct``, ``skew``, ``symmetric``,
``diagonal`` and ``linspace`` (10.3), and the scalar ``semiLinear`` (3.7.4), vectorised.

``semiLinear(x, k1, k2)`` is ``smooth(0, if x >= 0 then k1*x else k2*x)``: continuous
across ``x = 0``, so its switch generates no event (section 3.7.4.4 lets a tool skip
events under ``smooth``).
"""

from __future__ import annotations

import numpy as np

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import syntax as s
from .. import arrays as a
from ..scopes import ExpressionEvaluator, Handler, Scope


class ArrayBuiltins:
    def __init__(self, evaluator: ExpressionEvaluator) -> None:
        self.ev = evaluator

    def table(self) -> dict[str, Handler]:
        return {"cat": self.cat, "matrix": self.matrix, "outerProduct": self.outer_product,
                "skew": self.skew, "diagonal": self.diagonal, "symmetric": self.symmetric,
                "linspace": self.linspace, "semiLinear": self.semi_linear}

    def _args(self, call: s.Call, count: int, scope: Scope) -> list[a.Value]:
        name = call.func.dotted
        if call.named:
            raise FlattenError(f"'{name}' takes no named arguments", call.named[0].span)
        if len(call.args) != count:
            noun = "argument" if count == 1 else "arguments"
            raise FlattenError(f"'{name}' takes {count} {noun}, {len(call.args)} given",
                               call.span)
        values = [self.ev.value(arg, scope) for arg in call.args]
        for value, arg in zip(values, call.args):
            if isinstance(value, str):
                raise FlattenError(f"'{name}' needs numbers, found a string", arg.span)
        return values

    def _array(self, call: s.Call, value: a.Value, ndim: int, index: int) -> np.ndarray:
        if not isinstance(value, np.ndarray) or value.ndim != ndim:
            kind = "vector" if ndim == 1 else "matrix"
            raise FlattenError(f"'{call.func.dotted}' needs a {kind}, found "
                               f"{self.ev.describe(value)}", call.args[index].span)
        return value

    def cat(self, call: s.Call, scope: Scope) -> a.Value:
        if len(call.args) < 2 or call.named:
            raise FlattenError("'cat' needs a dimension and at least one array", call.span)
        k = self.ev.integer(call.args[0], scope, "the dimension of 'cat'")
        parts = [self.ev.value(arg, scope) for arg in call.args[1:]]
        arrays = []
        for part, arg in zip(parts, call.args[1:]):
            if not isinstance(part, np.ndarray):
                raise FlattenError(f"the arguments of 'cat' must be arrays, found "
                                   f"{self.ev.describe(part)}", arg.span)
            arrays.append(part)
        ndim = arrays[0].ndim
        if not 1 <= k <= ndim:
            raise FlattenError(f"dimension {k} does not exist: the arrays have {ndim}",
                               call.args[0].span)
        for part, arg in zip(arrays, call.args[1:]):
            if part.ndim != ndim or part.shape[:k - 1] + part.shape[k:] != \
                    arrays[0].shape[:k - 1] + arrays[0].shape[k:]:
                raise FlattenError(
                    f"the arrays of 'cat' differ in size outside dimension {k}: "
                    f"{a.describe_shape(arrays[0].shape)} and {a.describe_shape(part.shape)}",
                    arg.span)
        return np.concatenate(arrays, axis=k - 1)

    def matrix(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, 1, scope)
        if not isinstance(v, np.ndarray):
            return a.make_array([v], (1, 1))
        if v.ndim == 1:
            return v.reshape(-1, 1)
        if any(n != 1 for n in v.shape[2:]):
            raise FlattenError(f"'matrix' needs the dimensions after the second to be 1, "
                               f"found {a.describe_shape(v.shape)}", call.args[0].span)
        return v.reshape(v.shape[:2])

    def outer_product(self, call: s.Call, scope: Scope) -> a.Value:
        u, v = self._args(call, 2, scope)
        left, right = self._array(call, u, 1, 0), self._array(call, v, 1, 1)
        return a.make_array([x.mul(p, q) for p in left for q in right],
                            (len(left), len(right)))

    def skew(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, 1, scope)
        w = self._array(call, v, 1, 0)
        if w.shape != (3,):
            raise FlattenError("'skew' needs a vector of size 3", call.args[0].span)
        zero = x.ZERO
        return a.make_array([zero, x.neg(w[2]), w[1], w[2], zero, x.neg(w[0]),
                             x.neg(w[1]), w[0], zero], (3, 3))

    def symmetric(self, call: s.Call, scope: Scope) -> a.Value:
        """The upper triangle of a square matrix mirrored below the diagonal."""
        (v,) = self._args(call, 1, scope)
        m = self._array(call, v, 2, 0)
        n = m.shape[0]
        if m.shape != (n, n):
            raise FlattenError(f"'symmetric' needs a square matrix, found "
                               f"{a.describe_shape(m.shape)}", call.args[0].span)
        return a.make_array([m[min(i, j), max(i, j)] for i in range(n) for j in range(n)],
                            (n, n))

    def diagonal(self, call: s.Call, scope: Scope) -> a.Value:
        (v,) = self._args(call, 1, scope)
        d = self._array(call, v, 1, 0)
        n = len(d)
        self.ev.flattener.limits.check_size(n * n, "the result of 'diagonal'", call.span)
        return a.make_array([d[i] if i == j else x.ZERO for i in range(n) for j in range(n)],
                            (n, n))

    def linspace(self, call: s.Call, scope: Scope) -> a.Value:
        first, last, _ = self._args(call, 3, scope)
        n = self.ev.integer(call.args[2], scope, "the number of points of 'linspace'")
        if n < 2:
            raise FlattenError(f"'linspace' needs at least 2 points, found {n}",
                               call.args[2].span)
        for value, arg in ((first, call.args[0]), (last, call.args[1])):
            if isinstance(value, np.ndarray):
                raise FlattenError("the bounds of 'linspace' must be scalars", arg.span)
        assert not isinstance(first, (str, np.ndarray))
        assert not isinstance(last, (str, np.ndarray))
        self.ev.flattener.limits.check_size(n, "the result of 'linspace'", call.span)
        width = x.sub(last, first)
        return a.make_array([x.add(first, x.div(x.mul(x.Const(i), width), x.Const(n - 1)))
                             if 0 < i < n - 1 else (first if i == 0 else last)
                             for i in range(n)])

    def semi_linear(self, call: s.Call, scope: Scope) -> a.Value:
        args = self._args(call, 3, scope)

        def scalar(v: x.Expr, up: x.Expr, down: x.Expr) -> x.Expr:
            if isinstance(v, x.Const):
                return x.mul(up if v.value >= 0 else down, v)
            switch = x.If(x.BinOp(">=", v, x.ZERO), x.mul(up, v), x.mul(down, v))
            return x.Call("noEvent", (switch,))

        try:
            return a.elementwise(scalar, *args)
        except ValueError as err:
            raise FlattenError(str(err), call.span) from None
