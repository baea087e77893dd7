"""flat.FlatModel -> unit mismatches (:class:`springc.errors.UnitError`), one per place.

Every equation, initial equation, when-clause assignment and ``reinit``, every
parameter binding and every ``start`` value is checked: both sides of ``=``, the
operands of ``+``, ``-`` and the relations, the branches of an ``if`` and the arguments
of ``min``/``max``/``atan2``/... must have the same unit; ``sin``/``exp``/``log``/...
take dimensionless arguments. Units combine through ``*``, ``/``, ``^`` with a literal
exponent, ``sqrt`` and ``der`` (unit/s); ``time`` is in seconds (but ``sin(time)``
passes: an argument in which no variable has a unit is not checked).

An expression whose unit is not known (a literal, which takes whatever unit it is
needed in, as OpenModelica and Dymola treat literals; a variable without a ``unit``;
the result of a function springc does not know) constrains nothing: a product with
such a factor is not known either. So a model whose units are consistent never
warns. The first mismatch of each equation is reported, once per place in the source.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from fractions import Fraction
from functools import partial

from ..errors import Note, Span, UnitError
from ..ir import expr as x
from ..ir.builtins import BUILTINS
from ..ir.flat import Equation, FlatModel, quote
from ..ir.when import When
from ..native.foreign_calls import is_foreign
from .algebra import ONE, SECOND, Unit, UnitSyntaxError, parse_unit


class Mismatch(Exception):
    """A unit mismatch inside an expression: its message."""


class UnitChecker:
    """The units of the expressions of one flat model."""

    def __init__(self, model: FlatModel) -> None:
        self.units: dict[str, Unit | None] = {}
        self.shared: dict[int, tuple[x.Expr, Unit | None]] = {}
        for v in model.variables:
            self.units[v.name] = _declared(v.attributes.unit) if v.type == "Real" else None

    def unit(self, e: x.Expr) -> Unit | None:
        """The unit of ``e`` (``None``: not known); :class:`Mismatch` at the first
        disagreement inside it."""
        if isinstance(e, x.Var):
            return self.units.get(e.name)
        if isinstance(e, x.Time):
            return SECOND
        if isinstance(e, x.Der):
            inner = self.unit(e.arg)
            return None if inner is None else inner / SECOND
        if isinstance(e, x.Neg):
            return self.unit(e.arg)
        if isinstance(e, x.Not):
            self.unit(e.arg)
            return None
        if isinstance(e, (x.BinOp, x.If, x.Call)):
            found = self.shared.get(id(e))  # a node shared by several parents: once
            if found is not None and found[0] is e:
                return found[1]
            unit = self.binop(e) if isinstance(e, x.BinOp) else \
                self.call(e) if isinstance(e, x.Call) else self.branches(e)
            self.shared[id(e)] = (e, unit)
            return unit
        return None  # a literal takes the unit it is needed in

    def branches(self, e: x.If) -> Unit | None:
        self.unit(e.cond)
        return agree(self.unit(e.then), self.unit(e.otherwise), "if-branches", "and")

    def declared(self, e: x.Expr) -> bool:
        """Whether a variable with a known unit occurs in ``e``."""
        return any(isinstance(sub, x.Var) and self.units.get(sub.name) is not None
                   for sub in x.walk(e))

    def binop(self, e: x.BinOp) -> Unit | None:
        a, b = self.unit(e.left), self.unit(e.right)
        if e.op in ("+", "-") or e.op in x.RELATIONS:
            same = agree(a, b, "", e.op)
            return same if e.op in ("+", "-") else None
        if e.op in ("and", "or") or a is None:
            return None
        if e.op == "^":
            if a.dimensionless and a.same(ONE):
                return ONE
            exponent = _literal(e.right)
            return None if exponent is None else _named(a.power(exponent))
        if b is None:
            return None
        return _named(a * b if e.op == "*" else a / b)

    def call(self, e: x.Call) -> Unit | None:
        if is_foreign(e.name):  # a C function's outputs: no unit (and its many inputs
            return None  # are read once per element: not walked)
        args = [self.unit(a) for a in e.args]
        name = e.name
        builtin = BUILTINS.get(name)
        rule = "" if builtin is None else builtin.unit  # the registry's unit rule
        if rule == "atan2" and len(args) == 2:  # an angle from two lengths, say
            agree(args[0], args[1], "atan2's arguments", "and")
            return ONE
        if rule == "dimensionless":  # angles in rad are dimensionless
            given = args[0]
            # sin(time) is how one writes sin(w*time) with w = 1 rad/s: an argument
            # with no variable of declared unit in it is not checked
            if given is not None and not given.dimensionless and self.declared(e.args[0]):
                raise Mismatch(f"'{given}' given to {name}, which takes a dimensionless "
                               "argument ('1' or 'rad')")
            return ONE
        if rule == "sqrt":
            return None if args[0] is None else _named(args[0].power(Fraction(1, 2)))
        if rule == "one":
            return ONE
        if rule == "quotient" and len(args) == 2:
            return None if args[0] is None or args[1] is None else _named(args[0] / args[1])
        if rule == "last" and len(args) == 2:
            return args[1]
        if rule in ("same", "first") and args:  # the arguments' unit (delay: the first's)
            if rule == "first":
                return args[0]
            result = args[0]
            for other in args[1:]:
                result = agree(result, other, f"{name}'s arguments", "and")
            return result
        return None  # a function springc knows no unit rule for


def agree(a: Unit | None, b: Unit | None, what: str, op: str) -> Unit | None:
    """The common unit of two operands (either may be unknown); :class:`Mismatch`
    when both are known and differ."""
    if a is None:
        return b
    if b is None or a.same(b):
        return a
    head = f"{what} " if what else ""
    raise Mismatch(f"{head}'{a}' {op} '{b}'")


def _declared(text: str | None) -> Unit | None:
    try:
        return parse_unit(text or "")
    except UnitSyntaxError:
        return None  # a unit springc cannot read: left unchecked


def _literal(e: x.Expr) -> Fraction | None:
    """A literal exponent as a fraction (``2``, ``-1``, ``0.5``), else ``None``."""
    if isinstance(e, x.Neg):
        inner = _literal(e.arg)
        return None if inner is None else -inner
    if isinstance(e, x.Const) and not isinstance(e.value, bool):
        value = Fraction(e.value).limit_denominator(12)
        return value if abs(float(value) - float(e.value)) < 1e-12 else None
    return None


def _named(unit: Unit | None) -> Unit | None:
    """A computed unit, shown in SI base units."""
    return None if unit is None else Unit(unit.dims, unit.scale)


def check_units(model: FlatModel) -> tuple[UnitError, ...]:
    """The unit mismatches of ``model``, in source order, one per place and message."""
    checker = UnitChecker(model)
    found: dict[tuple[Span | None, str], UnitError] = {}
    for error in _mismatches(checker, model):
        found.setdefault((error.span, error.message), error)
    return tuple(sorted(found.values(), key=_order))


def _order(error: UnitError) -> tuple[str, int, int]:
    span = error.span
    return (span.file, span.line, span.column) if span else ("", 0, 0)


def _mismatches(checker: UnitChecker, model: FlatModel) -> Iterator[UnitError]:
    for v in model.variables:
        unit = checker.units.get(v.name)
        sides = [("binding", v.binding)] if v.variability in ("parameter", "constant") \
            else []
        sides.append(("start value", v.attributes.start))
        for what, value in sides:
            if value is not None:
                yield from _pair(checker, x.Var(v.name), value, v.span,
                                 partial(_text, f"the {what} of {v.name}"), unit)
    for eq in model.equations + model.initial_equations:
        yield from _equation(checker, eq)
    for when in model.whens:
        yield from _when(checker, when)


def _equation(checker: UnitChecker, eq: Equation) -> Iterator[UnitError]:
    yield from _pair(checker, eq.lhs, eq.rhs, eq.span,
                     lambda: f"`{x.to_text(eq.lhs, quote)} = {x.to_text(eq.rhs, quote)}`")


def _when(checker: UnitChecker, when: When) -> Iterator[UnitError]:
    for branch in when.branches:
        for condition in branch.conditions:
            try:
                checker.unit(condition)
            except Mismatch as err:
                yield _error(str(err), branch.span, "in the when-condition "
                             f"`{x.to_text(condition, quote)}`")
        for item in branch.assignments + branch.reinits:
            yield from _pair(checker, x.Var(item.name), item.value, item.span,
                             partial(_assignment, item.name, item.value))


def _text(text: str) -> str:
    return text


def _assignment(name: str, value: x.Expr) -> str:
    return f"`{quote(name)} = {x.to_text(value, quote)}`"


def _pair(checker: UnitChecker, left: x.Expr, right: x.Expr, span: Span,
          where: Callable[[], str], left_unit: Unit | None = None) -> Iterator[UnitError]:
    """The mismatch of ``left = right`` (inside either side first), if any; ``where``
    words the place (only written for a mismatch)."""
    try:
        a = left_unit if left_unit is not None else checker.unit(left)
        b = checker.unit(right)
        agree(a, b, "", "=")
    except Mismatch as err:
        yield _error(str(err), span, f"in {where()}")
    except RecursionError:  # nested deeper than Python's stack: left unchecked
        return


def _error(message: str, span: Span, note: str) -> UnitError:
    return UnitError(f"unit mismatch: {message}", span, [Note(note)])
