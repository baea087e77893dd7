"""``assert(condition, message, level)`` while flattening (section 8.3.7).

Input: the call of an assert equation or statement and its scope. Output: a
:class:`~springc.ir.flat.Assertion` whose condition is a scalar expression of the flat
variables and whose message is the evaluated text. Relations in the condition generate
no events: the simulator checks the condition after every accepted step. Whether the
condition is Boolean is checked once the variables' types are known
(:func:`check_conditions`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ...ir.builtins import names
from .. import arrays as a
from ..scopes import ExpressionEvaluator, Scope
from .strings import real_text

LEVELS = {"AssertionLevel.error": "error", "AssertionLevel.warning": "warning"}
_PARAMETERS = ("condition", "message", "level")


#: An assertion and the span of its condition, for the Boolean check.
Pending = tuple[flat.Assertion, Span]
#: Maps an evaluated value to the one an algorithm section reads (its assignments so far).
Read = Callable[[a.Value], a.Value]


_QUIET_CALLS = names(lambda b: b.quiet)


def assertion(ev: ExpressionEvaluator, call: s.Call, scope: Scope, origin: flat.Origin,
              guard: x.Expr | None = None, read: Read | None = None) -> Pending:
    """The assertion of ``call`` evaluated in ``scope``; ``guard`` (the condition of
    the branches it sits in, inside an inlined function) makes it ``not guard or c``;
    ``read`` maps values to those an algorithm section has assigned so far."""
    args = _arguments(call)
    cond_expr = args.get("condition")
    message_expr = args.get("message")
    if cond_expr is None or message_expr is None:
        missing = "condition" if cond_expr is None else "message"
        raise FlattenError(f"'assert' needs a {missing}", call.span,
                           hint="write assert(condition, \"message\") or add "
                                "AssertionLevel.warning as a third argument")
    # a condition is checked, never switched: inside a function body too it stays as
    # written (no noEvent around its relations)
    ev.no_event += 1
    literal, ev.literal = ev.literal, 0
    try:
        value = ev.value(cond_expr, scope)
    finally:
        ev.no_event -= 1
        ev.literal = literal
    if isinstance(value, str) or a.is_array(value):
        raise FlattenError(f"the condition of 'assert' must be a scalar Boolean, found "
                           f"{ev.describe(value)}", cond_expr.span)
    condition: x.Expr = value  # type: ignore[assignment]
    if guard is not None:
        condition = x.If(guard, condition, x.Const(True))
    # the message is evaluated only where the condition fails (8.3.7): the
    # assertions of functions it calls are not the model's
    recorded = list(ev.flattener.assertions)
    message = message_text(ev, message_expr, scope, read)
    ev.flattener.assertions[:] = recorded
    level = _level(args.get("level"))
    return flat.Assertion(condition, message, level, call.span, origin), cond_expr.span


def _arguments(call: s.Call) -> dict[str, s.Expr]:
    if len(call.args) > len(_PARAMETERS):
        raise FlattenError(f"'assert' takes at most 3 arguments, {len(call.args)} given",
                           call.span)
    args = dict(zip(_PARAMETERS, call.args))
    for named in call.named:
        if named.name not in _PARAMETERS:
            raise FlattenError(f"'assert' has no argument '{named.name}'", named.span,
                               hint="its arguments are condition, message and level")
        if named.name in args:
            raise FlattenError(f"argument '{named.name}' of 'assert' is given twice",
                               named.span)
        args[named.name] = named.value
    return args


def _level(e: s.Expr | None) -> str:
    if e is None:
        return "error"
    name = e.dotted if isinstance(e, s.Ref) else ""
    level = LEVELS.get(name.removeprefix("."))
    if level is None:
        raise FlattenError("the level of 'assert' must be AssertionLevel.error or "
                           "AssertionLevel.warning", e.span)
    return level


def guard_assertions(assertions: list[Pending], start: int, guard: x.Expr) -> None:
    """Make the assertions of inlined functions recorded since ``start`` hold where
    ``guard`` is false (the function is evaluated only where it is true)."""
    for i in range(start, len(assertions)):
        item, span = assertions[i]
        if item.origin.kind == "function":
            condition = x.If(guard, item.condition, x.Const(True))
            assertions[i] = (flat.Assertion(condition, item.message, item.level, item.span,
                                            item.origin), span)


def message_text(ev: ExpressionEvaluator, e: s.Expr, scope: Scope,
                 read: Read | None = None) -> str:
    """The text of a String expression: literals, ``+`` and ``String(e)``: the value
    of a constant or parameter, else ``String(<flat expression>)``."""
    if isinstance(e, s.String):
        return e.value
    if isinstance(e, s.Binary) and e.op == "+":
        return message_text(ev, e.left, scope, read) + message_text(ev, e.right, scope, read)
    if isinstance(e, s.Call) and e.func.dotted == "String":
        return _string_of(ev, e, scope, read)
    value = ev.value(e, scope)
    if isinstance(value, str):
        return value
    raise FlattenError(f"the message of 'assert' must be a String, found "
                       f"{ev.describe(value)}", e.span,
                       hint="write a string literal, e.g. \"x must be positive\"")


def _string_of(ev: ExpressionEvaluator, call: s.Call, scope: Scope,
               read: Read | None) -> str:
    """``String(e)`` (section 3.7.5) of a value known before the simulation."""
    if len(call.args) != 1:
        raise FlattenError(f"'String' takes 1 positional argument, {len(call.args)} given",
                           call.span)
    options = {n.name: ev.constant(n.value, scope, f"'{n.name}'") for n in call.named}
    arg = ev.value(call.args[0], scope)
    source = read(arg) if read is not None else arg
    try:
        value = ev.fold(source)
    except KeyError:
        if isinstance(source, (np.ndarray, str)):
            raise FlattenError("'String' of an array is not defined",
                               call.args[0].span) from None
        # a value known only while simulating: the message names it (its flat
        # expression) instead of showing it (not supported yet, docs/language.md)
        return f"String({x.to_text(source)})"
    if isinstance(value, np.ndarray):
        raise FlattenError("'String' of an array is not defined", call.args[0].span)
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        text = "true" if value else "false"
    elif isinstance(value, (int, np.integer)):
        text = str(int(value))
    else:
        text = real_text(float(value), int(options.get("significantDigits", 6)))
    width = int(options.get("minimumLength", 0))
    return text.ljust(width) if options.get("leftJustified", True) else text.rjust(width)


def is_boolean(e: x.Expr, types: dict[str, str]) -> bool:
    """Whether ``e`` may have type Boolean (``types``: flat variable name -> type);
    false for numbers, numeric variables and numeric built-ins."""
    if isinstance(e, x.Const):
        return isinstance(e.value, (bool, np.bool_))
    if isinstance(e, x.Var):
        return types.get(e.name, "Boolean") == "Boolean"
    if isinstance(e, x.Not):
        return True
    if isinstance(e, x.BinOp):
        return e.op in x.RELATIONS or e.op in ("and", "or")
    if isinstance(e, x.If):
        return is_boolean(e.then, types) and is_boolean(e.otherwise, types)
    if isinstance(e, x.Call):
        if e.name in _QUIET_CALLS and e.args:
            return is_boolean(e.args[-1], types)
        return e.name not in x.MATH  # the numeric built-ins; others (pre, edge) may be
    return False


def check_conditions(pending: list[Pending], variables: tuple[flat.Variable, ...],
                     conditions: Sequence[tuple[x.Expr, Span]] = ()
                     ) -> list[FlattenError]:
    """The errors of assertion and if-statement ``conditions`` that are not Boolean,
    and of error-level assertions that fail whatever the values."""
    types = {v.name: v.type for v in variables}
    errors = [FlattenError("the condition of 'assert' must be a Boolean expression",
                           span, hint="write a comparison, e.g. assert(x > 0, "
                           "\"x must be positive\")")
              for item, span in pending if not is_boolean(item.condition, types)]
    errors += [FlattenError("the condition of an if-statement must be a Boolean "
                            "expression", span, hint="write a comparison, e.g. if i > 0")
               for condition, span in conditions if not is_boolean(condition, types)]
    errors += [FlattenError(f"this assertion always fails: {item.message}", item.span,
                            hint="its condition is false whatever the values; use "
                            "AssertionLevel.warning to only report it")
               for item, _span in pending
               if item.level == "error" and isinstance(item.condition, x.Const)
               and not item.condition.value]
    return errors


def unique(pending: list[Pending]) -> tuple[flat.Assertion, ...]:
    """The assertions in order, each once (an inlined function may be evaluated
    twice), without those of functions that hold trivially."""
    seen: set[tuple[object, ...]] = set()
    out: list[flat.Assertion] = []
    numbering = _Numbering()
    for item, _span in pending:
        key = (numbering.number(item.condition), item.message, item.level, item.span)
        if key in seen or (item.origin.kind == "function" and item.condition == x.Const(True)):
            continue
        seen.add(key)
        out.append(item)
    return tuple(out)


class _Numbering:
    """The same number for equal expressions, each node object numbered once: hashing a
    condition as a tree hashes a sub-expression its parents share once per path (the
    assertions of ``Blocks.Examples.Filter``'s loops: 98 s)."""

    def __init__(self) -> None:
        self.by_id: dict[int, int] = {}
        self.table: dict[tuple[object, ...], int] = {}
        self.kept: list[x.Expr] = []  # the numbered nodes stay alive: their ids stay theirs

    def number(self, root: x.Expr) -> int:
        stack = [root]
        while stack:
            node = stack[-1]
            if id(node) in self.by_id:
                stack.pop()
                continue
            kids = x.children(node)
            missing = [k for k in kids if id(k) not in self.by_id]
            if missing:
                stack.extend(missing)
                continue
            stack.pop()
            label = (type(node), _label(node), tuple(self.by_id[id(k)] for k in kids))
            self.by_id[id(node)] = self.table.setdefault(label, len(self.table))
            self.kept.append(node)
        return self.by_id[id(root)]


def _label(node: x.Expr) -> object:
    """What tells ``node`` from another of its type with the same children."""
    if isinstance(node, x.BinOp):
        return node.op
    if isinstance(node, x.Call):
        return node.name
    if isinstance(node, x.Const):
        return node.value
    if isinstance(node, x.Var):
        return node.name
    return None
