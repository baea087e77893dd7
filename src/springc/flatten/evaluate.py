"""Evaluate syntax expressions in an instance scope: syntax.Expr -> arrays.Value.

Variables and parameters become :class:`~springc.expr.Var` of their flat names,
constants and loop indices are folded, arrays follow Modelica semantics. Structural
values (array sizes, ranges, subscripts, ``if``-equation conditions) are reduced to
numbers through the parameters' bindings with :meth:`Evaluator.constant`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator, Sequence
from typing import Any, cast

import numpy as np

from ..errors import FlattenError, Span, SpringcError
from ..ir import expr as x
from ..ir import syntax as s
from ..parse import ClassEntry
from . import arrays as a
from .array_ops import type_range, typed_range, typed_range_bounds, with_range
from .calls import (
    Builtins,
    argument_value,
    call_function,
    function_of,
    guard_assertions,
    short_defaults,
    string_binary,
    switches,
    without_events,
)
from .checks import check_enum_relation, check_stream_argument
from .connect import (
    CARDINALITY,
    GRAPH_FUNCTIONS,
    ConnectionGraph,
    cardinality_call,
    graph_value,
)
from .events import (
    DELAY,
    EVENT_CALLS,
    check_arithmetic_operands,
    check_unary_operand,
    delay_call,
    event_call,
)
from .names import ReferenceResolver
from .scopes import (
    ClassScope,
    EventUses,
    FlattenContext,
    Ident,
    LocalScope,
    Scope,
    check_powers,
)

UNSUPPORTED_CALLS = {
    "hold",
    "Clock", "previous", "subSample", "superSample", "shiftSample", "backSample",
    "spatialDistribution", "inStream", "actualStream", "getInstanceName", "assert",
}


# Scalar expression types, and the builders that arrays.add & co. apply to two scalars.
_SCALARS = frozenset({x.Const, x.Var, x.Time, x.Der, x.Neg, x.Not, x.BinOp, x.Call, x.If})
_ARITHMETIC = {"+": x.add, "-": x.sub, "*": x.mul, "/": x.div, "^": x.power}


class Evaluator(ReferenceResolver):
    """Evaluates expressions for one flattening run (it shares the flattener's caches)."""

    def __init__(self, flattener: FlattenContext) -> None:
        self.flattener = flattener
        self.no_event = 0  # > 0 inside noEvent(...) and smooth(...)
        # > 0 while inlining the body of a function without GenerateEvents = true: its
        # relations and switching built-ins are literal, as inside noEvent (12.8)
        self.literal = 0
        self.eventful = 0  # > 0 in a when-condition: its functions generate events
        self.call_depth = 0  # nesting of user-defined function calls being inlined
        self.events = EventUses()  # pre/edge/change uses, when-clause nesting
        self.builtins = Builtins(self)
        # Whether a subscript contains `end`, by syntax node (its identity: equal
        # subscripts written in two places are two entries).
        self.uses_end: dict[Ident[s.Expr], bool] = {}
        self.graph = ConnectionGraph()  # the flattener's, once it has connections
        self.record_values: dict[tuple[Ident[s.Expr], Ident[Scope]], a.Value] = {}
        self.cardinality_used = False  # placeholders to replace (flatten/connect/cardinality.py)

    # ------------------------------------------------------------ entry points

    def value(self, e: s.Expr, scope: Scope) -> a.Value:
        method: Callable[[s.Expr, Scope], a.Value] = getattr(self, "_" + type(e).__name__)
        return method(e, scope)

    def scalar(self, e: s.Expr, scope: Scope) -> x.Expr:
        v = self.value(e, scope)
        if a.is_array(v) or isinstance(v, str | a.RecordValue):
            raise FlattenError(f"expected a scalar, found {self.describe(v)}", e.span)
        return v  # type: ignore[return-value]

    def constant(self, e: s.Expr, scope: Scope, what: str,
                 hint: str = "use parameters and constants with values here") -> Any:
        """Numeric value (number or numpy array) of a parameter expression."""
        v = self.value(e, scope)
        try:
            return self.fold(v)
        except KeyError as missing:
            raise FlattenError(
                f"{what} must be a parameter expression, but it depends on "
                f"{missing.args[0]}", e.span, hint=hint) from None
        except (ArithmeticError, ValueError, TypeError) as err:
            raise FlattenError(f"cannot evaluate {what}: {err}", e.span) from None

    def integer(self, e: s.Expr, scope: Scope, what: str) -> int:
        v = self.constant(e, scope, what)
        if isinstance(v, (np.ndarray, bool, str)) or not math.isfinite(v) or v != int(v):
            raise FlattenError(f"{what} must be an integer, found {_shown(v)}", e.span)
        return int(v)

    def fold(self, v: a.Value) -> Any:
        """Evaluate a value numerically through parameter bindings (KeyError if not)."""
        if isinstance(v, str):
            return v
        if a.is_array(v):
            out = np.empty(v.shape, dtype=object)
            for idx, item in np.ndenumerate(v):
                out[idx] = self.fold(item)
            return out
        assert not isinstance(v, np.ndarray)
        if type(v) is x.Const:
            return v.value
        if any(type(n) is x.Time for n in x.walk(v)):  # not a parameter (x.evaluate: 0)
            raise KeyError("time")
        check_powers(v, self.flattener.parameter_values)
        return x.evaluate(v, self.flattener.parameter_values)

    def describe(self, v: Any) -> str:
        if isinstance(v, str):
            return "a string"
        if isinstance(v, a.RecordValue):
            return f"a record '{v.name}'"
        if isinstance(v, (ClassScope, ClassEntry)) or (a.is_array(v) and v.size and
                                                     isinstance(v.flat[0], ClassScope)):
            return "a component"
        return f"an array of size {a.describe_shape(a.shape(v))}" if a.is_array(v) \
            else "a scalar"

    # ----------------------------------------------------------------- literals

    def _Number(self, e: s.Number, scope: Scope) -> a.Value:
        return x.Const(e.value)

    def _Bool(self, e: s.Bool, scope: Scope) -> a.Value:
        return x.Const(e.value)

    def _String(self, e: s.String, scope: Scope) -> a.Value:
        return e.value

    def _ArrayLit(self, e: s.ArrayLit, scope: Scope) -> a.Value:
        return self._stack([self.value(i, scope) for i in e.items], e.span)

    def _stack(self, values: list[a.Value], span: Span) -> a.Value:
        try:
            return a.stack(values)
        except ValueError as err:
            raise FlattenError(str(err), span) from None

    def _MatrixLit(self, e: s.MatrixLit, scope: Scope) -> a.Value:
        rows = []
        for row in e.rows:
            parts = [self._as_matrix(self.value(i, scope)) for i in row]
            if len({p.shape[0] for p in parts}) > 1:
                raise FlattenError("rows of a matrix constructor differ in size", e.span)
            rows.append(np.concatenate(parts, axis=1))
        if len({r.shape[1] for r in rows}) > 1:
            raise FlattenError("columns of a matrix constructor differ in size", e.span)
        return np.concatenate(rows, axis=0)

    @staticmethod
    def _as_matrix(v: a.Value) -> np.ndarray:
        if not a.is_array(v):
            return a.make_array([v], (1, 1))
        return v.reshape(-1, 1) if v.ndim == 1 else v

    def _Range(self, e: s.Range, scope: Scope) -> a.Value:
        start = self.constant(e.start, scope, "a range bound")
        stop = self.constant(e.stop, scope, "a range bound")
        step = self.constant(e.step, scope, "a range step") if e.step else 1
        if typed_range_bounds(start, stop, e):  # false:true, E.a:E.c (section 10.4.3)
            return a.make_array(typed_range(start, stop))
        for bound in (start, stop, step):
            if isinstance(bound, (np.ndarray, str)) or not math.isfinite(bound):
                raise FlattenError(f"the bounds and step of a range must be finite numbers, "
                                   f"found {_shown(bound)}", e.span)
        if step == 0:
            raise FlattenError("the step of a range must not be zero", e.span)
        count = max(0, math.floor((stop - start) / step + 1e-10) + 1)
        self.flattener.limits.check_size(count, "this range", e.span)
        values = [start + i * step for i in range(count)]
        if all(isinstance(v, int) for v in (start, step)):
            values = [int(v) for v in values]
        return a.make_array([x.Const(v) for v in values])

    def _Colon(self, e: s.Colon, scope: Scope) -> a.Value:
        raise FlattenError("':' is only allowed as a subscript", e.span)

    def _Tuple(self, e: s.Tuple, scope: Scope) -> a.Value:
        raise FlattenError("an output list (`(a, b)`) is only allowed on the left of "
                           "`(a, b) = f(x)` or `(a, b) := f(x)`", e.span)

    def _End(self, e: s.End, scope: Scope) -> a.Value:
        end = scope.end_value if isinstance(scope, LocalScope) else None
        if end is None:
            raise FlattenError("'end' is only allowed inside a subscript", e.span)
        return x.Const(end)

    # ------------------------------------------------------------------ operators

    def _Unary(self, e: s.Unary, scope: Scope) -> a.Value:
        v = self.value(e.operand, scope)
        self._numeric(v, e.operand.span)
        check_unary_operand(e.op, v, e.operand.span)
        if e.op == "-":
            return a.elementwise(x.neg, v)
        if e.op == "+":
            return v
        return a.elementwise(lambda b: x.Const(not b.value) if isinstance(b, x.Const)
                             else x.Not(b), v)

    def _numeric(self, v: Any, span: Span) -> None:
        if isinstance(v, (str, ClassScope)) or (
                a.is_array(v) and v.size and isinstance(v.flat[0], ClassScope)):
            raise FlattenError(f"expected a number, found {self.describe(v)}", span)

    def _Binary(self, e: s.Binary, scope: Scope) -> a.Value:
        left = self.value(e.left, scope)
        try:
            right = self.value(e.right, scope)
        except SpringcError:
            # `false and f(...)`: the result is known without the right operand, as
            # the MSL's tables write `tableOnFile and not Strings.isEmpty(fileName)`
            decided = self._folded(left) if e.op in ("and", "or") and isinstance(
                left, x.Expr) else None
            if decided is None or decided != (e.op == "or"):
                raise
            return x.Const(decided)
        scalar = _ARITHMETIC.get(e.op)
        if scalar is not None:
            check_arithmetic_operands(e.op, (left, right), e)
        if scalar is not None and type(left) in _SCALARS and type(right) in _SCALARS:
            # the common case: no sizes to check
            return scalar(cast(x.Expr, left), cast(x.Expr, right))
        if type(left) is str and type(right) is str and e.op == "+":
            self.flattener.limits.check_size(len(left) + len(right), "this String", e.span,
                                             "characters")
        text = string_binary(e.op, left, right, e.span)
        if text is not None:
            return text
        self._numeric(left, e.left.span)
        self._numeric(right, e.right.span)
        op = e.op
        try:
            if op == "+":
                return a.add(left, right)
            if op == "-":
                return a.sub(left, right)
            if op == "*":
                return a.mul(left, right)
            if op == "/":
                return a.div(left, right)
            if op == "^":
                return a.power(left, right)
            if op.startswith("."):
                return a.elementwise(a.scalar_op(op[1:]), left, right)
            if op in ("and", "or") and (a.is_array(left) or a.is_array(right)):
                return a.elementwise(a.scalar_op(op), left, right)  # section 10.6.9
            if a.is_array(left) or a.is_array(right):
                raise ValueError(f"'{op}' needs scalar operands")
        except ValueError as err:
            raise FlattenError(str(err), e.span,
                               hint="check the sizes of both operands") from None
        check_enum_relation(e, left, right, scope, self)
        result: a.Value = a.scalar_op(op)(left, right)  # type: ignore[arg-type]
        if self.literal and op in x.RELATIONS:
            return self._quiet(result)  # in a function body (12.8)
        return result  # a relation on variables generates events (simplify/events.py)

    def _IfExpr(self, e: s.IfExpr, scope: Scope) -> a.Value:
        # In order: the assertions of functions a branch calls hold where it is not
        # taken (guarded), and nothing after a constant-true condition is evaluated. A
        # branch that cannot be evaluated (an index out of range, say) is an error only
        # if it may be selected: not when a parameter expression rules it out (Modelica
        # 3.6: the branch not selected is not evaluated).
        branches: list[tuple[x.Expr, a.Value]] = []
        guard: x.Expr | None = None  # all earlier conditions false
        result: a.Value | None = None
        settled = False  # an earlier condition is a parameter expression that holds
        for cond_expr, then_expr in e.branches:
            cond = self._guarded(cond_expr, scope, guard, scalar=True)
            if isinstance(cond, x.Const):
                if cond.value:
                    result = self._guarded(then_expr, scope, guard)
                    break
                continue
            try:
                then = self._guarded(then_expr, scope,
                                     cond if guard is None else x.BinOp("and", guard, cond))
            except FlattenError:
                if settled or self._folded(cond) is False:
                    continue
                raise
            branches.append((cond, then))
            guard = x.Not(cond) if guard is None else x.BinOp("and", guard, x.Not(cond))
            settled = settled or self._folded(cond) is True
        if result is None:
            try:
                result = self._guarded(e.otherwise, scope, guard)
            except FlattenError:
                if not settled:
                    raise
                result = branches.pop()[1]
        for cond, then in reversed(branches):
            if a.shape(then) != a.shape(result):
                # under a parameter condition only the selected branch counts (the
                # MSL BooleanTable sizes its table so)
                chosen = self._folded(cond)
                if chosen is None:
                    raise FlattenError("branches of an if-expression differ in size",
                                       e.span, hint="sizes may differ only where the "
                                       "condition is a parameter expression")
                result = then if chosen else result
                continue
            result = a.elementwise(lambda t, o, c=cond: x.If(c, t, o), then, result)
        return result

    def _guarded(self, e: s.Expr, scope: Scope, guard: x.Expr | None, scalar: bool = False
                 ) -> Any:
        """The value of ``e``; the assertions of the functions it inlines hold where
        ``guard`` is false."""
        start = len(self.flattener.assertions)
        value = self.scalar(e, scope) if scalar else self.value(e, scope)
        if guard is not None:
            guard_assertions(self.flattener.assertions, start, guard)
        return value

    def _folded(self, cond: x.Expr) -> bool | None:
        """The value of a condition that is a parameter expression, else None."""
        if not self.flattener.is_parameter_expression(cond):
            return None
        try:
            return bool(self.fold(cond))
        except (KeyError, ArithmeticError, ValueError, TypeError):
            return None

    # ------------------------------------------------------------------ calls

    def _Call(self, e: s.Call, scope: Scope) -> a.Value:
        name = e.func.dotted
        if name in GRAPH_FUNCTIONS:
            return graph_value(self, self.graph, e, scope)
        if name in UNSUPPORTED_CALLS:
            check_stream_argument(self, e, scope)  # inStream(v) of a v that is no stream
            raise FlattenError(f"`{name}` is not supported yet", e.func.span,
                               hint="springc supports a subset of Modelica; see "
                               "\"Not supported yet\" in docs/language.md")
        if name in EVENT_CALLS:
            return event_call(self, self.events, e, scope)
        if name == CARDINALITY:
            self.cardinality_used = True
            return cardinality_call(self, e, scope)
        if name == DELAY:
            return delay_call(self, e, scope)
        handler = self.builtins.lookup(name, scope)
        if handler is not None:
            value = handler(e, scope)
            if self.literal and switches(name):
                return self._quiet(value)  # abs, div, integer... in a function body
            return value
        entry, named = short_defaults(self, function_of(self, e.func, scope), e.func, scope)
        args = [argument_value(self, arg, scope) for arg in e.args]
        named.update({n.name: (argument_value(self, n.value, scope), n.span)
                      for n in e.named})
        return call_function(self, entry, args, named, e)

    def _quiet(self, v: a.Value) -> a.Value:
        """``v`` taken literally, as inside ``noEvent``: a relation or switching
        built-in of a function body without ``GenerateEvents = true`` (12.8); one on
        parameters only switches at no event anyway and stays as it is."""
        return a.elementwise(lambda e: e if self.flattener.is_parameter_expression(e)
                             else without_events(e), v)

    def _FieldOf(self, e: s.FieldOf, scope: Scope) -> a.Value:
        key = (Ident(e.record), Ident(scope))  # one evaluation for all the fields
        record = self.record_values.get(key)
        if record is None:
            record = self.record_values[key] = self.value(e.record, scope)
        if not isinstance(record, a.RecordValue):
            raise FlattenError(f"a record is expected here, found {self.describe(record)}",
                               e.record.span)
        value = record.fields.get(e.name)
        if value is None:
            raise FlattenError(f"field '{e.name}' of this record value is never assigned",
                               e.record.span)
        field: a.Value = value
        return field

    def _Comprehension(self, e: s.Comprehension, scope: Scope) -> a.Value:
        return self._stack(list(self.iterate(e.body, e.indices, scope)), e.span)

    def iterate(self, body: s.Expr, indices: tuple[s.ForIndex, ...], scope: Scope
                ) -> Iterator[a.Value]:
        """Values of ``body`` for every combination of the iterators (first outermost)."""
        indices = tuple(with_range(self, i, body, scope) for i in indices)
        ranges = [self.range_values(i, scope) for i in indices]
        self.flattener.limits.add_iterations(math.prod(len(r) for r in ranges),
                                             indices[0].span)
        for combo in itertools.product(*ranges):
            local = LocalScope({i.name: v for i, v in zip(indices, combo)}, scope)
            yield self.value(body, local)

    def range_values(self, index: s.ForIndex, scope: Scope) -> Sequence[x.Expr | str]:
        if index.range is None:
            raise FlattenError(f"the range of '{index.name}' must be given "
                               f"('for {index.name} in 1:N')", index.span)
        if isinstance(index.range, s.Ref):  # Boolean or an enumeration type (11.2.2.2)
            typed = type_range(self.flattener, index.range, scope)
            if typed is not None:
                return typed
        v = self.value(index.range, scope)
        if not a.is_array(v) or v.ndim != 1:
            raise FlattenError("a for-loop range must be a vector", index.range.span)
        values = [self.fold_at(item, index.range) for item in v]
        return [item if isinstance(item, str) else x.Const(self._plain(item))
                for item in values]  # a String range: the strings themselves

    def fold_at(self, v: a.Value, e: s.Expr) -> Any:
        try:
            return self.fold(v)
        except KeyError as missing:
            raise FlattenError(f"a for-loop range must be a parameter expression, but it "
                               f"depends on {missing.args[0]}", e.span) from None

    @staticmethod
    def _plain(v: Any) -> Any:
        return int(v) if isinstance(v, float) and v.is_integer() else v


def _shown(value: object) -> str:
    """A value for a message: ``'a'``, ``1.5``, or ``an array`` (not numpy's repr)."""
    return "an array" if isinstance(value, np.ndarray) else repr(value)
