"""Array values of flattening and the Modelica array operators (chapter 10).

A value is a scalar :mod:`springc.expr` expression, a ``str`` (attributes such as
``unit``), or a numpy object array of scalar expressions. Operators check sizes as
the specification demands and raise :class:`ValueError` with a message; the caller
attaches the source location.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeGuard

import numpy as np

from ..ir import expr as x


@dataclass(frozen=True)
class RecordValue:
    """A record as a value (section 12.6): what a function returns or takes, a record
    constructor call, a record component named in an expression. ``name``: the
    record class's full name; ``fields``: each component's value (nested records
    as ``RecordValue``)."""

    name: str
    fields: dict[str, Any]


@dataclass(frozen=True)
class FunctionArgument:
    """A function passed as the argument of a function's functional input (section
    12.4.2: ``quadrature(0, 1, Parabola)``); a call of the input calls ``entry``."""

    entry: Any  # the ClassEntry of the function


#: A value; a record value (``RecordValue``) travels where a function returns or takes
#: one, typed as this alias only by the few places that make or read it.
Value = x.Expr | str | np.ndarray


def is_array(v: object) -> TypeGuard[np.ndarray]:
    return isinstance(v, np.ndarray)


def shape(v: object) -> tuple[int, ...]:
    return v.shape if isinstance(v, np.ndarray) else ()


def make_array(items: Sequence[Any], dims: tuple[int, ...] | None = None) -> np.ndarray:
    """An object array from a flat list of scalars (``dims`` defaults to 1-D)."""
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out.reshape(dims) if dims is not None else out


def stack(values: list[Value]) -> np.ndarray:
    """``{a, b, c}``: a new leading dimension; all elements must have one size."""
    if not values:
        return np.empty(0, dtype=object)
    first = shape(values[0])
    for v in values[1:]:
        if shape(v) != first:
            raise ValueError(f"array constructor elements differ in size: {_fmt(first)} "
                             f"and {_fmt(shape(v))}")
    out = np.empty((len(values), *first), dtype=object)
    for i, v in enumerate(values):
        out[i] = v
    return out


def _fmt(dims: tuple[int, ...]) -> str:
    return "scalar" if not dims else "[" + ", ".join(map(str, dims)) + "]"


def describe_shape(dims: tuple[int, ...]) -> str:
    return _fmt(dims)


def elementwise(f: Callable[..., x.Expr], *args: Value) -> Value:
    """Apply a scalar function element by element; scalars broadcast, arrays must agree."""
    dims = [a.shape for a in args if isinstance(a, np.ndarray)]
    if not dims:
        return f(*args)
    if len(args) == 1:
        (arg,) = args
        assert isinstance(arg, np.ndarray)
        return make_array([f(item) for item in arg.flat], arg.shape)
    if any(d != dims[0] for d in dims):
        raise ValueError("element-wise operation on arrays of different sizes: "
                         + " and ".join(_fmt(d) for d in dims))
    # Arrays here are small (a 2-D position, a row of masses): a Python loop over the
    # elements beats building a numpy ufunc per call.
    count = math.prod(dims[0])
    columns = [list(arg.flat) if isinstance(arg, np.ndarray) else [arg] * count
               for arg in args]
    return make_array([f(*items) for items in zip(*columns)], dims[0])


def _same_size(op: str, a: Value, b: Value) -> None:
    if shape(a) != shape(b):
        raise ValueError(f"operands of '{op}' differ in size: {_fmt(shape(a))} and "
                         f"{_fmt(shape(b))}")


def add(a: Value, b: Value) -> Value:
    _same_size("+", a, b)
    return elementwise(x.add, a, b)


def sub(a: Value, b: Value) -> Value:
    _same_size("-", a, b)
    return elementwise(x.sub, a, b)


def dot(a: np.ndarray, b: np.ndarray) -> x.Expr:
    """Scalar product of two vectors of equal length."""
    return fold(x.add, [x.mul(p, q) for p, q in zip(a, b)], x.ZERO)


def fold(op: Callable[[x.Expr, x.Expr], x.Expr], items: Sequence[x.Expr],
         identity: x.Expr) -> x.Expr:
    """``items`` combined with ``op`` (``sum``, ``product``, a scalar product), kept
    shallow for long runs (:func:`springc.ir.expr.fold_chunked`)."""
    return x.fold_chunked(items, op, op, identity)


def mul(a: Value, b: Value) -> Value:
    """``*``: scalar scaling, scalar product, matrix-vector and matrix products."""
    if not isinstance(a, np.ndarray) or not isinstance(b, np.ndarray):
        return elementwise(x.mul, a, b)
    sa, sb = a.shape, b.shape
    if sa[-1] != sb[0] or len(sa) > 2 or len(sb) > 2:
        raise ValueError(f"operands of '*' do not fit: {_fmt(sa)} and {_fmt(sb)}")
    if len(sa) == 1 and len(sb) == 1:
        return dot(a, b)
    a2 = a if len(sa) == 2 else a.reshape(1, -1)
    b2 = b if len(sb) == 2 else b.reshape(-1, 1)
    out = [dot(a2[i, :], b2[:, j]) for i in range(a2.shape[0]) for j in range(b2.shape[1])]
    dims = tuple(d for d, keep in ((a2.shape[0], len(sa) == 2), (b2.shape[1], len(sb) == 2))
                 if keep)
    return make_array(out, dims)


def div(a: Value, b: Value) -> Value:
    if is_array(b):
        raise ValueError("the divisor of '/' must be a scalar; use './' for element-wise "
                         "division")
    return elementwise(x.div, a, b)


def power(a: Value, b: Value) -> Value:
    """``^``: a scalar power, or ``A^n`` of a square matrix and an Integer ``n >= 0``
    (section 10.6.6: ``A*A*...*A``, the identity for ``n = 0``)."""
    if isinstance(a, np.ndarray) and not is_array(b):
        n = b.value if isinstance(b, x.Const) else None
        if a.ndim != 2 or a.shape[0] != a.shape[1]:
            raise ValueError(f"'^' of an array needs a square matrix, found {_fmt(a.shape)}; "
                             "use '.^' for element-wise powers")
        if not isinstance(n, int) or isinstance(n, bool) or n < 0:
            raise ValueError("the exponent of a matrix power must be a constant Integer >= 0")
        result: Value = make_array([x.Const(int(i == j)) for i in range(a.shape[0])
                                    for j in range(a.shape[0])], a.shape)
        for _ in range(n):
            result = mul(result, a) if _ else a
        return result
    if is_array(a) or is_array(b):
        raise ValueError("'^' needs scalar operands here; use '.^' for element-wise powers")
    return x.power(a, b)  # type: ignore[arg-type]


def scalar_op(op: str) -> Callable[[x.Expr, x.Expr], x.Expr]:
    """The scalar builder for a binary operator symbol (element-wise forms included)."""
    table: dict[str, Callable[[x.Expr, x.Expr], x.Expr]] = {
        "+": x.add, "-": x.sub, "*": x.mul, "/": x.div, "^": x.power,
    }
    if op in table:
        return table[op]
    return lambda a, b: _fold(op, a, b)


def _fold(op: str, a: x.Expr, b: x.Expr) -> x.Expr:
    if isinstance(a, x.Const) and isinstance(b, x.Const):
        value = x.evaluate(x.BinOp(op, a, b), {})
        assert isinstance(value, (bool, int, float))
        return x.Const(value)
    return x.BinOp(op, a, b)


def scalars(v: Value) -> list[x.Expr]:
    """All elements of ``v`` in row-major order (a scalar gives a one-element list)."""
    if isinstance(v, np.ndarray):
        return list(v.flat)
    assert not isinstance(v, str), "a string has no scalar elements"
    return [v]
