"""Where a hybrid model's discrete values live in the generated code: the layout of
the event slots of ``z`` and the substitution that makes the continuous functions
read them.

``z`` = [Newton warm starts | event slots | failure flag]. The event slots, in
order: the held value (1.0 true, 0.0 false) of every state relation (``_zr<k>``) and
time relation (``_zt<k>``), the ``sample`` flags (``_zs<k>``, true only during the
event at a sample time), the discrete variables (their flat names), the held value
of every ``floor(u)`` (``_zf<k>``; unless ``u`` is affine in time, its two state
relations ``u < _zf<k>`` and ``u >= _zf<k> + 1`` come last among the relations),
the ``pre``
values (``_zp<k>``), the when-condition values at the last event (``_zc<k>``), per
state relation its value after the first pass of the event (``_zb<k>``, the side its
hysteresis keeps in the later passes) and whether its held value sits inside its wide
band (``_zw<k>``, see :mod:`.hysteresis`), then ``initial()`` (``_zinit``),
``terminal()`` (``_zterm``), the terminate code (0, or 1 + the index of the
``terminate`` message), the changed flag of the last event pass, the event-iteration
status (1.0: did not converge) and the passes of the event so far (``_zpass``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from ..ir import expr as x
from ..ir.builtins import names
from ..ir.hybrid import EventSystem
from .statements import Load, Stmt

_QUIET = names(lambda b: b.quiet)
FLAGS = ("_zinit", "_zterm", "_zstop", "_zchanged", "_zstatus", "_zpass")


class EventLayout:
    """The event slots of ``z`` for ``events``, starting at ``base``."""

    def __init__(self, events: EventSystem, base: int) -> None:
        self.floors = [f"_zf{k}" for k in range(len(events.floors))]
        self.floor_rates = list(events.floor_rates) or [None] * len(events.floors)
        bounds = []
        self.texts = [x.to_text(r) for r in events.relations]  # what each relation is
        for call, name, rate in zip(events.floors, self.floors, self.floor_rates):
            if rate is not None:  # a time event at each integer (next_time_event)
                continue
            u, k = call.args[0], x.Var(name)
            bounds += [x.BinOp("<", u, k), x.BinOp(">=", u, x.BinOp("+", k, x.Const(1.0)))]
            self.texts += [f"{x.to_text(call)} decreases", f"{x.to_text(call)} increases"]
        events = dataclasses.replace(events, relations=events.relations + tuple(bounds))
        self.events = events
        self.base = base
        self.relations = [f"_zr{k}" for k in range(len(events.relations))]
        self.times = [f"_zt{k}" for k in range(len(events.time_relations))]
        self.samples = [f"_zs{k}" for k in range(len(events.samples))]
        self.discrete = [d.name for d in events.discrete]
        self.pre = {name: f"_zp{k}" for k, name in enumerate(events.pre)}
        self.conditions: list[tuple[int, int, x.Expr]] = []  # (when, branch, condition)
        for i, clause in enumerate(events.whens):
            for j, branch in enumerate(clause.branches):
                self.conditions += [(i, j, c) for c in branch.conditions]
        self.condition_names = [f"_zc{k}" for k in range(len(self.conditions))]
        self.firsts = [f"_zb{k}" for k in range(len(self.relations))]
        self.wide = [f"_zw{k}" for k in range(len(self.relations))]
        names = (self.relations + self.times + self.samples + self.discrete + self.floors
                 + list(self.pre.values()) + self.condition_names + self.firsts
                 + self.wide + list(FLAGS))
        self.slot = {name: base + i for i, name in enumerate(names)}
        self.size = len(names)
        self.held = self._held()
        self._hold: _Hold | None = None
        self._other: _Hold | None = None  # the last other mapping's walk
        self.uses_terminal = events.reads_terminal or any(
            isinstance(n, x.Call) and n.name == "terminal"
            for _, _, c in self.conditions for n in x.walk(c))
        self.messages = list(dict.fromkeys(
            t.message for clause in events.whens for b in clause.branches
            for t in b.terminates))

    def loads(self) -> list[Stmt]:
        """Every event slot as a local of the generated functions."""
        return [Load(name, f"z[{slot}]", name) for name, slot in self.slot.items()]

    def _held(self) -> dict[x.Expr, x.Expr]:
        mapping: dict[x.Expr, x.Expr] = {}
        for rel, name in zip(self.events.relations, self.relations):
            mapping[rel] = x.Var(name)
        for tr, name in zip(self.events.time_relations, self.times):
            mapping[tr.relation] = x.Var(name)
        for call, name in zip(self.events.floors, self.floors):
            mapping[call] = x.Var(name)
        return mapping

    def hold(self, e: x.Expr, held: Mapping[x.Expr, x.Expr] | None = None) -> x.Expr:
        """``e`` as the generated code computes it: event relations read their held
        values (``held``: another mapping, e.g. the new values during an event pass),
        ``floor`` calls their held values, ``sample``/``initial``/``terminal`` their
        flags, ``pre(v)`` its slot,
        ``edge(b)`` is ``b and not pre(b)``, ``change(v)`` is ``v <> pre(v)``.

        One walk per mapping (``held`` the same object again, not changed since):
        the expressions share nodes (a when-clause's values, the sum of a buffer
        that each of an FFT's outputs reads), and a shared node held once stays one
        node, which the printer then computes once."""
        if held is None:  # one walk for every expression of the system: they share nodes
            if self._hold is None:
                self._hold = _Hold(self.held, {_head(k) for k in self.held}, self, {})
            return _replace(e, self._hold, False)
        if self._other is None or self._other.held is not held:
            self._other = _Hold(held, {_head(k) for k in held}, self, {})
        return _replace(e, self._other, False)

    def sample_name(self, call: x.Call) -> str:
        return self.samples[self.events.samples.index((call.args[0], call.args[1]))]


@dataclasses.dataclass(frozen=True)
class _Hold:
    """One :meth:`EventLayout.hold`: the mapping, the heads of its keys (an operator or
    a function name: only a node with such a head is looked up, so that a large
    arithmetic node is never hashed) and the nodes done, by identity (the expressions
    of index reduction share subtrees: a walk of the tree would be exponential)."""

    held: Mapping[x.Expr, x.Expr]
    heads: set[str]
    layout: EventLayout
    memo: dict[tuple[int, bool], tuple[x.Expr, x.Expr]]


def _head(e: x.Expr) -> str:
    return e.op if isinstance(e, x.BinOp) else e.name if isinstance(e, x.Call) else ""


def _replace(e: x.Expr, h: _Hold, quiet: bool) -> x.Expr:
    if isinstance(e, (x.Const, x.Var, x.Time)):
        return e
    key = (id(e), quiet)
    found = h.memo.get(key)
    if found is not None and found[0] is e:
        return found[1]
    out = _replace_node(e, h, quiet)
    h.memo[key] = (e, out)
    return out


def _replace_node(e: x.Expr, h: _Hold, quiet: bool) -> x.Expr:
    held, layout = h.held, h.layout
    if not quiet and isinstance(e, (x.BinOp, x.Call)) and _head(e) in h.heads \
            and e in held:
        return held[e]
    if isinstance(e, x.Call):
        if e.name == "pre":
            return x.Var(layout.pre[e.args[0].name])  # type: ignore[union-attr]
        if e.name == "edge":
            return x.BinOp("and", e.args[0], x.Not(x.Var(layout.pre[e.args[0].name])))  # type: ignore[union-attr]
        if e.name == "change":
            return x.BinOp("<>", e.args[0], x.Var(layout.pre[e.args[0].name]))  # type: ignore[union-attr]
        if e.name == "initial":
            return x.Var("_zinit")
        if e.name == "terminal":
            return x.Var("_zterm")
        if e.name == "sample":
            return x.Var(layout.sample_name(e))
        inner = quiet or e.name in _QUIET
        return x.Call(e.name, tuple(_replace(a, h, inner) for a in e.args))
    if isinstance(e, x.BinOp):
        return x.BinOp(e.op, _replace(e.left, h, quiet),
                       _replace(e.right, h, quiet))
    if isinstance(e, (x.Neg, x.Not, x.Der)):
        return type(e)(_replace(e.arg, h, quiet))
    if isinstance(e, x.If):
        return x.If(_replace(e.cond, h, quiet), _replace(e.then, h, quiet),
                    _replace(e.otherwise, h, quiet))
    raise TypeError(f"not an expression: {e!r}")
