"""The hysteresis of a hybrid model's state relations: when a relation ``left op right``
switches, in the zero-crossing functions and in the passes of the event iteration.

A relation that an equation of the configuration it selects puts on its own boundary
(a friction element starting while another stuck one in series holds the
acceleration at 0: its path parameter is exactly its breakaway torque; a quenched
arc switch: ``i = Goff*v`` makes ``abs(i) <= abs(v)*Goff`` an identity) flips with
the rounding of the solution, and neither the event iteration nor the integration
after it can settle on it. As OpenModelica's relations (``LessZC`` and its
siblings: a band of about ``1e-10 (|a| + |b| + nominal)`` around the boundary, kept
towards the value the relation had at the start of the event), a relation here
switches only past a band around its boundary, on the side away from a reference
value (OpenModelica's reference is the value at the start of the event):

- in the zero-crossing functions and the first :data:`BAND_PASS` passes of an
  event the reference is the held value (after the last event; in a pass, the pass
  before) and the band is :data:`NARROW_BAND` ``* (|left| + |right|)``: none where
  one side is 0 (a ball's ``h <= 0`` switches at the floor, its bounces keep their
  Zeno limit) or, in the zero crossings and the first pass, where the sides are
  exactly equal (``reinit(s, smax)`` at a stop decides as the relation does), a
  few hundred rounding units where the two sides are equal and large. An iteration
  that settles in these passes is the exact one (Rotational.Friction,
  CoupledClutches, the LossyGearDemos 1 and 3 run as before);
- an iteration still moving after them (a relation on its own boundary, flipping
  with the configuration it selects) goes on with the band :data:`WIDE_BAND`
  ``* (1 + |left| + |right|)`` kept towards the value of pass :data:`BAND_PASS`
  (``_zb<k>``), and, as 8.6 writes the iteration, sets ``pre(v) := v`` in every
  pass also while relations move (``events.event_pass``);
- after the event, a relation whose held value the narrow band would not keep (the
  wide band kept it) goes on with the wide band in its zero-crossing function
  (``_zw<k>``) until the next event, so that the integration does not meet the
  same boundary again at once.

The specification leaves this open: 8.6 asks for an event iteration that stops
when nothing changes, and a relation on its boundary is either value within the
rounding of its sides.
"""

from __future__ import annotations

from ..ir import expr as x
from .event_layout import EventLayout
from .statements import Stmt, Store

NARROW_BAND = 1e-14
"""The band of the zero crossings and first passes, relative to ``|left| + |right|``."""
WIDE_BAND = 1e-10
"""The band of the later passes of an event, relative to ``1 + |left| + |right|``."""

BAND_PASS = 40
"""The passes of an event in which relations switch as their zero crossings do; an
iteration that has not settled by then (a relation on its own boundary flipping
with the configuration it selects) goes on with the wide band."""

_ONE, _ZERO = x.Const(1.0), x.Const(0.0)


def _truth(name: str) -> x.Expr:
    return x.BinOp("<>", x.Var(name), _ZERO)


def _size(left: x.Expr, right: x.Expr) -> x.Expr:
    return x.add(x.Call("abs", (left,)), x.Call("abs", (right,)))


def _kept(layout: EventLayout, k: int, side: x.Expr, width: x.Expr) -> x.Expr:
    """``left - right`` of relation ``k`` moved by ``width`` towards the side where
    the relation is ``side``: the relation's value with that band."""
    rel = layout.events.relations[k]
    left, right = layout.hold(rel.left), layout.hold(rel.right)
    towards = side if rel.op in (">", ">=") else x.Not(side)
    diff = x.sub(left, right)
    return x.add(diff, x.If(towards, width, x.Neg(width)))


def _narrowed(layout: EventLayout, k: int, side: x.Expr, width: x.Expr) -> x.Expr:
    """:func:`_kept`, but exactly ``left - right`` where that is 0: sides made
    equal on purpose (``reinit(s, smax)`` at a stop) decide as the relation does."""
    rel = layout.events.relations[k]
    diff = x.sub(layout.hold(rel.left), layout.hold(rel.right))
    return x.If(x.BinOp("==", diff, _ZERO), _ZERO, _kept(layout, k, side, width))


def _narrow(layout: EventLayout, k: int) -> x.Expr:
    rel = layout.events.relations[k]
    return x.mul(x.Const(NARROW_BAND), _size(layout.hold(rel.left), layout.hold(rel.right)))


def _wide(layout: EventLayout, k: int) -> x.Expr:
    rel = layout.events.relations[k]
    return x.mul(x.Const(WIDE_BAND),
                 x.add(_ONE, _size(layout.hold(rel.left), layout.hold(rel.right))))


def crossing(layout: EventLayout, k: int, exact_ties: bool = True) -> x.Expr:
    """The zero-crossing function of state relation ``k``: ``left - right`` moved
    towards its held value's side by the narrow band, or by the wide one where the
    last event kept the relation inside it (``_zw<k>``)."""
    wide = _kept(layout, k, _truth(layout.relations[k]), _wide(layout, k))
    narrow = (_narrowed if exact_ties else _kept)(
        layout, k, _truth(layout.relations[k]), _narrow(layout, k))
    return x.If(_truth(layout.wide[k]), wide, narrow)


def pass_value(layout: EventLayout, k: int) -> x.Expr:
    """The value of state relation ``k`` in a pass of the event iteration: as the
    zero crossings decide it (towards the value of the pass before) in the first
    :data:`BAND_PASS` passes, later with the wide band kept towards its value in
    the last of those (``_zb<k>``)."""
    op = layout.events.relations[k].op
    # the first pass decides as the zero crossing that located the event (exact ties);
    # the later ones keep a tie towards the pass before (a configuration that puts the
    # relation on its boundary: LossyGearDemo2's starting bearing friction)
    at_start = x.BinOp("==", x.Var("_zpass"), _ZERO)
    first = x.BinOp(op, x.If(at_start, crossing(layout, k),
                             crossing(layout, k, exact_ties=False)), _ZERO)
    later = x.BinOp(op, _kept(layout, k, _truth(layout.firsts[k]), _wide(layout, k)), _ZERO)
    return x.If(early_pass(), first, later)


def early_pass() -> x.Expr:
    """Whether the event iteration is in its first :data:`BAND_PASS` passes."""
    return x.BinOp("<", x.Var("_zpass"), x.Const(float(BAND_PASS)))


def first_values(layout: EventLayout, values: list[str]) -> list[Stmt]:
    """The stores of a pass that keep the relations' ``values`` (locals) while the
    passes are fewer than :data:`BAND_PASS`, and count the pass."""
    slot = layout.slot
    out: list[Stmt] = [Store(f"z[{slot[name]}]", x.If(early_pass(), x.Var(value), x.Var(name)))
                       for name, value in zip(layout.firsts, values)]
    out.append(Store(f"z[{slot['_zpass']}]", x.add(x.Var("_zpass"), _ONE)))
    return out


def after_event(layout: EventLayout) -> list[Stmt]:
    """The stores at the end of an event: which relations the narrow band would not
    keep at their held values (then their zero crossings take the wide band)."""
    out: list[Stmt] = []
    for k, rel in enumerate(layout.events.relations):
        narrow = x.BinOp(rel.op, _narrowed(layout, k, _truth(layout.relations[k]),
                                           _narrow(layout, k)), _ZERO)
        out.append(Store(f"z[{layout.slot[layout.wide[k]]}]",
                         x.If(x.BinOp("<>", x.If(narrow, _ONE, _ZERO),
                                        x.Var(layout.relations[k])), _ONE, _ZERO)))
    return out


def begin_event(layout: EventLayout) -> list[Stmt]:
    """The store at the start of an event: no pass yet."""
    return [Store(f"z[{layout.slot['_zpass']}]", _ZERO)]
