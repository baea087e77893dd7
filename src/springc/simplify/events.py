"""The event part of a hybrid model: flat.FlatModel + ode.ODE -> hybrid.EventSystem.

Finds what switches during a simulation (Modelica 3.6, 8.5): the variables assigned
in when-clauses (held between events), the relations on continuous variables outside
``noEvent``/``smooth`` (state events: each is held between events and watched
through its zero-crossing function), the relations of ``time`` with parameter
expressions and the ``sample`` calls (time events, hit exactly), and the variables
read by ``pre``/``edge``/``change``. :func:`continuous_part` is the flat model
without the when-assigned variables, which the balance check and lowering see.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Iterator

from ..ir import expr as x
from ..ir import flat, ode
from ..ir import when as w
from ..ir.hybrid import Discrete, EventSystem, TimeRelation

STATE_RELATIONS = frozenset({"<", "<=", ">", ">="})
_QUIET = frozenset({"noEvent", "smooth"})


def continuous_part(model: flat.FlatModel) -> flat.FlatModel:
    """``model`` without the variables its when-clauses assign (they are discrete:
    the when-equations determine them, at events)."""
    if not model.whens:
        return model
    held = set(w.assigned(model.whens))
    return dataclasses.replace(model, variables=tuple(
        v for v in model.variables if v.name not in held))


def step_exprs(step: ode.Step) -> list[x.Expr]:
    """Every expression a solve step evaluates."""
    if isinstance(step, ode.Assign):
        return [step.expr]
    if isinstance(step, ode.LinearBlock):
        return [e for _, _, e in step.matrix] + list(step.rhs)
    return ([a.expr for a in step.inner] + list(step.residuals)
            + [a.expr for a in step.sensitivities] + [e for _, _, e in step.jacobian])


def when_exprs(whens: Iterable[w.When]) -> Iterator[x.Expr]:
    for clause in whens:
        for b in clause.branches:
            yield from b.conditions
            yield from (a.value for a in b.assignments)
            yield from (r.value for r in b.reinits)


def switching(e: x.Expr) -> Iterator[x.Expr]:
    """The nodes of ``e`` outside ``noEvent(...)`` and ``smooth(...)``."""
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, x.Call) and node.name in _QUIET:
            continue
        yield node
        stack.extend(x.children(node))


def event_system(model: flat.FlatModel, system: ode.ODE) -> EventSystem | None:
    """The events of ``system`` (None for a purely continuous model)."""
    params = {q.name for q in system.parameters}
    held = w.assigned(model.whens)
    held_set = set(held)
    exprs = [e for step in system.steps for e in step_exprs(step)]
    exprs += [a.expr for a in system.observed]
    exprs += list(when_exprs(model.whens))
    relations: dict[x.BinOp, None] = {}
    timed: dict[x.BinOp, TimeRelation] = {}
    samples: dict[tuple[x.Expr, x.Expr], None] = {}
    pre: dict[str, None] = {}
    for e in exprs:
        for node in switching(e):
            if isinstance(node, x.BinOp) and node.op in STATE_RELATIONS:
                kind = _time_relation(node, params)
                if kind is not None:
                    timed.setdefault(node, kind)
                elif _continuous(node, params | held_set):
                    relations.setdefault(node, None)
            elif isinstance(node, x.Call) and node.name == "sample":
                samples.setdefault((node.args[0], node.args[1]), None)
        for node in x.walk(e):
            if isinstance(node, x.Call) and node.name in ("pre", "edge", "change"):
                arg = node.args[0]
                if isinstance(arg, x.Var):
                    pre.setdefault(arg.name, None)
    if not (held or relations or timed or samples or model.whens):
        return None
    by_name = {v.name: v for v in model.variables}
    discrete = tuple(Discrete(n, by_name[n].type, by_name[n].attributes.start,
                              by_name[n].span) for n in held)
    return EventSystem(discrete, tuple(relations), tuple(timed.values()), tuple(samples),
                       tuple(pre), _sorted_whens(model.whens))


def _time_relation(node: x.BinOp, params: set[str]) -> TimeRelation | None:
    """``time OP t0`` or ``t0 OP time`` with ``t0`` a parameter expression."""
    def constant(e: x.Expr) -> bool:
        return x.variables(e) <= params and not any(
            isinstance(n, (x.Time, x.Der, x.Call)) and not (
                isinstance(n, x.Call) and n.name in x.MATH) for n in x.walk(e))

    if isinstance(node.left, x.Time) and constant(node.right):
        return TimeRelation(node, node.right, node.op in (">", ">="))
    if isinstance(node.right, x.Time) and constant(node.left):
        return TimeRelation(node, node.left, node.op in ("<", "<="))
    return None


def _continuous(node: x.BinOp, known: set[str]) -> bool:
    """Whether a relation reads a continuous variable or ``time`` (so it can change
    between events and needs a zero-crossing function)."""
    return any(isinstance(n, (x.Time, x.Der)) or (isinstance(n, x.Var) and n.name not in known)
               for n in switching(node))


def _sorted_whens(whens: tuple[w.When, ...]) -> tuple[w.When, ...]:
    """When-clauses ordered so that a clause reading a variable another assigns comes
    after it (reads through ``pre`` do not count); a cycle keeps the written order
    (the event iteration settles it)."""
    writes = [set(w.assigned((c,))) for c in whens]
    reads = []
    for c in whens:
        names: set[str] = set()
        for e in when_exprs((c,)):
            names |= _reads(e)
        reads.append(names)
    order: list[int] = []
    state = [0] * len(whens)

    def visit(i: int) -> None:
        if state[i]:
            return
        state[i] = 1
        for j in range(len(whens)):
            if j != i and writes[j] & reads[i] and not state[j]:
                visit(j)
        state[i] = 2
        order.append(i)

    for i in range(len(whens)):
        visit(i)
    return tuple(whens[i] for i in order)


def _reads(e: x.Expr) -> set[str]:
    """Variables ``e`` reads, except through ``pre``."""
    out: set[str] = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, x.Call) and node.name == "pre":
            continue
        if isinstance(node, x.Var):
            out.add(node.name)
        stack.extend(x.children(node))
    return out
