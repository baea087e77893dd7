"""The event part of the simplified system (Modelica 3.6, 8.5 and 8.6).

Produced by :mod:`springc.simplify.events` next to the ODE (``ODE.events``):

- ``discrete``: the variables assigned in when-clauses; they keep their value
  between events (the generated code holds them in ``z``);
- ``relations``: the relations on continuous variables outside ``noEvent``: each
  keeps its value from the last event; its zero-crossing function is
  ``left - right``, compared with 0 by its operator;
- ``time_relations``: relations of ``time`` with a parameter expression
  (``time >= t0``): time events at ``at``, hit exactly without root finding;
- ``samples``: the ``sample(start, interval)`` calls (time events too);
- ``pre``: the variables read by ``pre``, ``edge`` or ``change``;
- ``iterated``: those of them that equations (not when-clauses) determine and that
  are discrete-time (Boolean, Integer, enumeration, ``discrete Real``): the event
  iteration sets ``pre(v) := v`` after each pass until none changes (8.6), which
  the mixed systems of friction and switches (``pre(mode)``, ``pre(startForward)``)
  need to settle;
- ``floors``: the ``floor(u)`` calls on continuous arguments outside ``noEvent``
  (``ceil``, ``integer``, ``div``, ``mod`` and ``rem`` are rewritten into them):
  each keeps its value from the last event; an event occurs when ``u`` leaves
  ``[k, k + 1)`` (3.7.2); ``floor_rates``: for each, ``der(u)`` when ``u`` is
  ``time`` times a parameter expression plus one (a time event at each integer,
  hit exactly), else None (state events on ``u``);
- ``whens``: the when-clauses, assignments sorted so that each reads the values
  assigned before it at the same event;
- ``reads_initial``, ``reads_terminal``: whether equations or assertions read
  ``initial()`` or ``terminal()`` (an if-equation on them): true during the
  initialization and at the event at the end of the run.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from ..errors import Span
from .expr import BinOp, Call, Expr
from .when import When


@dataclass(frozen=True, slots=True)
class Discrete:
    """A variable assigned in when-clauses: held between events."""

    name: str
    type: str  # Real, Integer or Boolean
    start: Expr | None
    span: Span


@dataclass(frozen=True, slots=True)
class TimeRelation:
    """``relation`` compares ``time`` with the parameter expression ``at``; after
    the event at ``at`` its value is ``after`` (true for ``time >= at``)."""

    relation: BinOp
    at: Expr
    after: bool


@dataclass(frozen=True)
class EventSystem:
    discrete: tuple[Discrete, ...]
    relations: tuple[BinOp, ...]
    time_relations: tuple[TimeRelation, ...]
    samples: tuple[tuple[Expr, Expr], ...]
    pre: tuple[str, ...]
    whens: tuple[When, ...]
    floors: tuple[Call, ...] = ()
    floor_rates: tuple[Expr | None, ...] = ()
    # initial() / terminal() read by equations or assertions (an if-equation on them)
    reads_initial: bool = False
    reads_terminal: bool = False
    iterated: tuple[str, ...] = ()

    @property
    def empty(self) -> bool:
        return not (self.discrete or self.relations or self.time_relations
                    or self.samples or self.whens or self.floors or self.reads_initial
                    or self.reads_terminal)


def event_expressions(events: EventSystem) -> Iterator[Expr]:
    """Every expression the event code evaluates: relations, time-event instants,
    samples, floors, discrete starts and the when-clauses' conditions, assigned values
    and reinit values (what a parameter must be read by to be changeable at run time)."""
    yield from events.relations
    yield from (r.at for r in events.time_relations)
    for start, interval in events.samples:
        yield start
        yield interval
    yield from events.floors
    yield from (d.start for d in events.discrete if d.start is not None)
    for w in events.whens:
        for b in w.branches:
            yield from b.conditions
            yield from (a.value for a in b.assignments)
            yield from (r.value for r in b.reinits)
