"""ModelicaStandardTables evaluated natively while flattening.

Input: a component of an external-object class whose constructor is one of the table
functions of ``ir.native_externals`` (``parameter ExternalCombiTable1D tableID =
ExternalCombiTable1D(...)``), and calls of the functions whose external clause names a
table getter (``getTable1DValue(tableID, 1, u)``). Output: a :class:`Table` (the
component's member: the table's numbers, folded from its parameters) and, for every
getter call, a flat expression: the interpolant as nested ``if noEvent(u < b)``
(``interpolation``), so that differentiation, code generation and the event system
need nothing new. Time events come from the getter of the next event, which the
library's blocks call in a when-clause on ``time >= pre(nextTimeEvent)``.

Tables read from files (``tableOnFile = true``) and two-dimensional tables with other
than linear or constant segments are located errors naming the missing feature.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import FlattenError, Note, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ...ir.native_externals import NATIVE_EXTERNALS
from ...parse import ClassEntry
from .. import arrays as a
from ..scopes import ExpressionEvaluator, ObjectMember
from . import interpolation as ip

ALWAYS, AT_DISCONTINUITIES, NO_TIME_EVENTS = 1, 2, 3
"""``Modelica.Blocks.Types.TimeEvents``, by ordinal."""
INF = 1e60
"""``Modelica.Constants.inf``: no further time event."""
NO_NAME = "NoName"


@dataclass(frozen=True, eq=False)
class Table(ObjectMember):
    """A constructed table object: its kind (``table1D``, ``timeTable``, ``table2D``),
    the table matrix, the columns its outputs interpolate (1-based), and its options."""

    kind: str
    table: np.ndarray
    columns: tuple[int, ...]
    smoothness: int
    extrapolation: int
    start_time: float
    shift_time: float
    time_events: int
    span: Span


def native_call(ev: ExpressionEvaluator, entry: ClassEntry, names: dict[str, Any],
                call: s.Call) -> Any:
    """The value of a call of a native table function, its inputs bound in ``names``."""
    external = entry.defn.external
    assert external is not None
    operation, roles = NATIVE_EXTERNALS[external.name]
    given: dict[str, Any] = {}
    for role, arg in zip(roles, external.args):
        if role is not None and isinstance(arg, s.Ref) and arg.dotted in names:
            given[role] = names[arg.dotted]
    if operation in ("table1D", "timeTable", "table2D"):
        return _construct(ev, operation, given, call)
    table = given.get("tableID")
    if not isinstance(table, Table):
        raise FlattenError(f"'{entry.full_name}' needs a table object as its first "
                           "argument", call.span)
    if operation == "close":
        return x.ZERO
    return _getter(ev, operation, table, given, call)


def _construct(ev: ExpressionEvaluator, kind: str, given: dict[str, Any], call: s.Call
               ) -> Table:
    for name in ("fileName", "tableName"):
        text = _text(ev, given.get(name, NO_NAME), call)
        if text.strip() not in ("", NO_NAME):
            raise FlattenError(
                "tables read from files (tableOnFile = true) are not supported yet",
                call.span, hint="give the table inline: table = [...]")
    table = given.get("table")
    if not a.is_array(table) or table.ndim != 2:
        raise FlattenError("the table must be a matrix", call.span)
    rows, width = int(table.shape[0]), int(table.shape[1])
    numbers = np.array([[_number(ev, v, call, "the table") for v in row] for row in table],
                       dtype=float).reshape((rows, width))
    if numbers.size == 0:
        raise FlattenError("the table is an empty matrix", call.span,
                           hint="give the table rows: table = [0, 0; 1, 1]")
    columns: tuple[int, ...] = ()
    if kind != "table2D":
        raw = given.get("columns")
        values = list(raw.flat) if a.is_array(raw) else [raw]
        columns = tuple(int(_number(ev, v, call, "columns")) for v in values)
        for c in columns:
            if not 1 <= c <= width:
                raise FlattenError(f"column {c} is not a column of the table, which has "
                                   f"{width}", call.span)
    made = Table(kind, numbers, columns,
                 int(_number(ev, given.get("smoothness", x.ONE), call, "smoothness")),
                 int(_number(ev, given.get("extrapolation", x.Const(2)), call,
                             "extrapolation")),
                 _number(ev, given.get("startTime", x.ZERO), call, "startTime"),
                 _number(ev, given.get("shiftTime", x.ZERO), call, "shiftTime"),
                 int(_number(ev, given.get("timeEvents", x.ONE), call, "timeEvents")),
                 call.span)
    _check(made)
    return made


def _text(ev: ExpressionEvaluator, value: Any, call: s.Call) -> str:
    """A String argument: a string, or an if-expression on a parameter choosing one."""
    while isinstance(value, x.If):
        value = value.then if _number(ev, value.cond, call, "a condition") \
            else value.otherwise
    if not isinstance(value, str):
        raise FlattenError("a file or table name of a table must be a String", call.span)
    return value


def _number(ev: ExpressionEvaluator, value: Any, call: s.Call, what: str) -> float:
    if isinstance(value, str) or a.is_array(value):
        raise FlattenError(f"{what} of a table must be a number", call.span)
    try:
        return float(ev.fold(value))
    except KeyError as missing:
        raise FlattenError(f"{what} of a table must be known before the simulation, but "
                           f"it depends on {missing.args[0]}", call.span) from None


def _check(table: Table) -> None:
    """The documented conditions on the abscissae of a table."""
    if table.kind == "table2D":
        return
    xs = table.table[:, 0]
    steps = np.diff(xs)
    strict = table.smoothness in ip.SPLINES
    if (steps <= 0).any() if strict else (steps < 0).any():
        order = "strictly increasing" if strict else "increasing"
        raise FlattenError(f"the abscissae (first column) of the table must be {order}",
                           table.span)
    if len(xs) > 1 and not (steps > 0).any():
        raise FlattenError("the table's abscissae are all equal", table.span)


def _getter(ev: ExpressionEvaluator, operation: str, table: Table, given: dict[str, Any],
            call: s.Call) -> x.Expr:
    xs = table.table[:, 0]
    if operation in ("min1D", "minTime"):
        return x.Const(float(xs[0]))
    if operation in ("max1D", "maxTime"):
        return x.Const(float(xs[-1]))
    if operation == "value2D":
        return _value2d(table, given["u1"], given["u2"], call)
    if operation == "nextEvent":
        return next_event(table, given["t"])
    icol = int(_number(ev, given["icol"], call, "icol"))
    if not 1 <= icol <= len(table.columns):
        raise FlattenError(f"the table has {len(table.columns)} output column(s), "
                           f"{icol} is asked for", call.span)
    ys = table.table[:, table.columns[icol - 1] - 1]
    if operation == "value1D":
        _inside(ev, table, given["u"], "the input u", call)
        return _interpolated(table, xs, ys, given["u"])
    t = given["t"]
    shifted = x.sub(t, x.Const(table.shift_time)) if table.shift_time else t
    _inside(ev, table, shifted, "the time (less shiftTime)", call)
    value = _interpolated(table, xs, ys, shifted)
    if table.start_time <= -INF or not math.isfinite(table.start_time):
        return value
    before = x.Call("noEvent", (x.BinOp("<", t, x.Const(table.start_time)),))
    return x.If(before, x.ZERO, value)


def _inside(ev: ExpressionEvaluator, table: Table, u: x.Expr, what: str, call: s.Call
            ) -> None:
    """NoExtrapolation: an assertion that ``u`` stays in the table's range."""
    if table.extrapolation != ip.NO_EXTRAPOLATION:
        return
    low, high = float(table.table[0, 0]), float(table.table[-1, 0])
    inside = x.BinOp("and", x.BinOp(">=", u, x.Const(low)), x.BinOp("<=", u, x.Const(high)))
    message = (f"Extrapolation error: {what} of the table must lie in [{low:g}, {high:g}] "
               "(extrapolation = NoExtrapolation)")
    ev.flattener.assertions.append((flat.Assertion(
        x.Call("noEvent", (inside,)), message, "error", call.span,
        flat.Origin("equation", "", "table")), call.span))


def _interpolated(table: Table, xs: np.ndarray, ys: np.ndarray, u: x.Expr) -> x.Expr:
    if table.extrapolation == ip.PERIODIC and len(xs) > 1:
        u = ip.periodic(u, float(xs[0]), float(xs[-1]))
    return ip.piecewise(u, ip.pieces(xs, ys, table.smoothness, table.extrapolation))


def next_event(table: Table, t: x.Expr) -> x.Expr:
    """The next time event after ``t`` (scaled time): the start time, then the
    breakpoints (all of them, or the duplicated ones) shifted by ``shiftTime``."""
    xs = table.table[:, 0]
    if table.time_events == NO_TIME_EVENTS or len(xs) < 2:
        points: list[float] = []
    elif table.time_events == AT_DISCONTINUITIES:
        points = sorted({float(v) for v, w in itertools.pairwise(xs) if v == w})
    else:
        points = sorted({float(v) for v in xs})
    shift = table.shift_time
    if table.extrapolation == ip.PERIODIC and len(xs) > 1 and points:
        first, period = float(xs[0]), float(xs[-1] - xs[0])
        local = ip.periodic(x.sub(t, x.Const(shift)), first, first + period)
        base = x.sub(t, x.sub(local, x.Const(first)))  # the current period's start
        inner = [p - first for p in points if p > first] or [period]
        if inner[-1] != period:
            inner.append(period)
        inner += [p + period for p in inner]
        # a little ahead: t on an event may fold to just below a period's end
        ahead = x.add(x.sub(local, x.Const(first)), x.Const(1e-10 * period))
        found = _first_after(ahead, inner)
        event: x.Expr = x.add(base, found)
    else:
        event = _first_after(t, [p + shift for p in points])
    if math.isfinite(table.start_time):
        early = x.Call("noEvent", (x.BinOp("<", t, x.Const(table.start_time)),))
        later = x.Call("noEvent", (x.BinOp("<", x.Const(table.start_time), event),))
        event = x.If(early, x.If(later, x.Const(table.start_time), event), event)
    return event


def _first_after(t: x.Expr, points: list[float]) -> x.Expr:
    """The first of the sorted ``points`` above ``t`` (``INF`` past the last)."""
    segments = [ip.Piece(-math.inf, 0.0, (points[0] if points else INF,))]
    segments += [ip.Piece(p, 0.0, (points[i + 1] if i + 1 < len(points) else INF,))
                 for i, p in enumerate(points)]
    # a point equal to t is behind it: the search selects from the point on
    return ip.piecewise(t, segments)


def _value2d(table: Table, u1: x.Expr, u2: x.Expr, call: s.Call) -> x.Expr:
    """Bilinear (or constant-segment) interpolation of a 2-D table: the first column
    holds u1's grid, the first row u2's; outside, the edge segments continue."""
    if table.smoothness not in (ip.LINEAR, ip.CONSTANT) or \
            table.extrapolation not in (ip.HOLD, ip.LAST_TWO):
        raise FlattenError("CombiTable2D supports linear and constant segments with "
                           "HoldLastPoint or LastTwoPoints extrapolation so far", call.span,
                           notes=[Note("the table is constructed here", table.span)])
    grid1, grid2 = table.table[1:, 0], table.table[0, 1:]
    rows = [ip.piecewise(u2, ip.pieces(grid2, table.table[i + 1, 1:], table.smoothness,
                                       table.extrapolation)) for i in range(len(grid1))]
    # interpolate across the rows with the weights of a column of unit vectors
    result: x.Expr = x.ZERO
    for i, row in enumerate(rows):
        unit = np.zeros(len(grid1))
        unit[i] = 1.0
        weight = ip.piecewise(u1, ip.pieces(grid1, unit, table.smoothness,
                                            table.extrapolation))
        result = x.add(result, x.mul(weight, row))
    return result


def is_external_object(entry: ClassEntry) -> bool:
    """Whether the class extends the predefined ``ExternalObject`` (section 12.9.7)."""
    return any(isinstance(e, s.Extends) and e.base.dotted == "ExternalObject"
               for e in entry.defn.elements)


def table_object(ev: ExpressionEvaluator, entry: ClassEntry, value: Any, name: str,
                 span: Span) -> Table:
    """The table a component of an external-object class is bound to: its binding
    (``ExternalCombiTable1D(...)``, a call of the class's constructor) evaluated."""
    constructor = next((c for c in entry.defn.elements if isinstance(c, s.ClassDef)
                        and c.name == "constructor"), None)
    if constructor is None or constructor.external is None or \
            NATIVE_EXTERNALS.get(constructor.external.name, ("",))[0] not in (
                "table1D", "timeTable", "table2D"):
        raise FlattenError(f"'{name}' is an external object of '{entry.full_name}', "
                           "which springc does not implement", span,
                           hint="springc evaluates the tables of the Modelica Standard "
                           "Library (ModelicaStandardTables); other external objects are "
                           "not supported yet")
    if not isinstance(value, Table):
        raise FlattenError(f"the external object '{name}' must be bound to a call of "
                           f"'{entry.full_name}' (its constructor)", span)
    return value
