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
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

from ..ir import expr as x
from ..ir import flat, ode
from ..ir import when as w
from ..ir.builtins import names
from ..ir.hybrid import Discrete, EventSystem, TimeRelation

STATE_RELATIONS = frozenset({"<", "<=", ">", ">="})
_QUIET = names(lambda b: b.quiet)
_PHASES = names(lambda b: b.phase)
_READS_PRE = names(lambda b: b.reads_pre)


def continuous_part(model: flat.FlatModel) -> flat.FlatModel:
    """``model`` without the variables its when-clauses assign (they are discrete:
    the when-equations determine them, at events), nor the initial equations that
    give them their start values (:func:`discrete_starts`)."""
    if not model.whens:
        return model
    held = set(w.assigned(model.whens))
    starts = discrete_starts(model)
    return dataclasses.replace(
        model, variables=tuple(v for v in model.variables if v.name not in held),
        initial_equations=tuple(eq for eq in model.initial_equations
                                if id(eq) not in starts.equations))


@dataclass(frozen=True)
class DiscreteStarts:
    """Start values of when-assigned variables from initial equations ``v = e`` (or
    ``pre(v) = e``) with ``e`` an expression of parameters: by name, and the ids of
    those equations (taken out of the initial problem of the continuous part)."""

    values: dict[str, x.Expr]
    equations: frozenset[int]


def discrete_starts(model: flat.FlatModel) -> DiscreteStarts:
    held = set(w.assigned(model.whens))
    # parameters with known values (fixed = false ones are what initial equations find)
    params = {v.name for v in model.parameters if v.attributes.fixed is not False}
    values: dict[str, x.Expr] = {}
    used: set[int] = set()
    for eq in model.initial_equations:
        for side, value in ((eq.lhs, eq.rhs), (eq.rhs, eq.lhs)):
            if isinstance(side, x.Call) and side.name == "pre" and side.args:
                side = side.args[0]
            if (isinstance(side, x.Var) and side.name in held and side.name not in values
                    and x.variables(value) <= params
                    and not any(isinstance(n, (x.Der, x.Call)) and not (
                        isinstance(n, x.Call) and n.name in x.MATH) for n in x.walk(value))):
                # time is the start time during the initialization (the MSL's Pulse
                # and Trapezoid set their period count from it)
                values[side.name] = at_time(value, x.Const(model.experiment.start or 0.0))
                used.add(id(eq))
                break
    return DiscreteStarts(values, frozenset(used))


def at_time(e: x.Expr, t: x.Expr) -> x.Expr:
    """``e`` with ``time`` replaced by ``t``."""
    if isinstance(e, x.Time):
        return t
    return x.map_children(e, lambda c: at_time(c, t))


def when_exprs(whens: Iterable[w.When]) -> Iterator[x.Expr]:
    for clause in whens:
        for b in clause.branches:
            yield from b.conditions
            yield from (a.value for a in b.assignments)
            yield from (r.value for r in b.reinits)


def switching(e: x.Expr, seen: set[int] | None = None) -> Iterator[x.Expr]:
    """The nodes of ``e`` outside ``noEvent(...)`` and ``smooth(...)``; those whose
    ids are in ``seen`` (given: shared by the expressions of one search) not again."""
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, x.Call) and node.name in _QUIET:
            continue
        if seen is not None:
            if id(node) in seen:
                continue
            seen.add(id(node))
        yield node
        stack.extend(x.children(node))


def _plain(e: x.Expr) -> bool:
    """Whether ``e`` has neither a call nor a relation (no event, ``pre`` or phase)."""
    return not any(type(n) is x.Call or (type(n) is x.BinOp and n.op in x.RELATIONS)
                   for n in x.walk(e))


def event_system(model: flat.FlatModel, system: ode.ODE) -> EventSystem | None:
    """The events of ``system`` (None for a purely continuous model)."""
    params = {q.name for q in system.parameters}
    held = w.assigned(model.whens)
    held_set = set(held)
    exprs = [e for step in system.steps for e in ode.step_expressions(step)]
    exprs += [a.expr for a in system.observed]
    exprs += list(when_exprs(model.whens))
    # Only expressions with a call or a relation can hold anything found below
    # (one walk of each, instead of three, for the plain sums of a large scene).
    exprs = [e for e in exprs if not _plain(e)]
    relations: dict[x.BinOp, None] = {}
    timed: dict[x.BinOp, TimeRelation] = {}
    samples: dict[tuple[x.Expr, x.Expr], None] = {}
    pre: dict[str, None] = {}
    floors: dict[x.Call, None] = {}
    visited: set[int] = set()  # nodes shared by several expressions: once
    read: set[int] = set()
    for e in exprs:
        for node in switching(e, visited):
            if isinstance(node, x.BinOp) and node.op in STATE_RELATIONS:
                kind = _time_relation(node, params)
                if kind is not None:
                    timed.setdefault(node, kind)
                elif _continuous(node, params | held_set):
                    relations.setdefault(node, None)
            elif isinstance(node, x.Call) and node.name == "sample":
                samples.setdefault((node.args[0], node.args[1]), None)
            elif (isinstance(node, x.Call) and node.name == "floor"
                  and _continuous(node, params | held_set)):
                floors.setdefault(node, None)
        for node in x.walk(e, read):
            if isinstance(node, x.Call) and node.name in _READS_PRE:
                arg = node.args[0]
                if isinstance(arg, x.Var):
                    pre.setdefault(arg.name, None)
    walked: set[int] = set()
    phases = {n.name for e in [*exprs, *(a.condition for a in model.assertions)]
              for n in x.walk(e, walked) if isinstance(n, x.Call) and n.name in _PHASES}
    if not (held or relations or timed or samples or model.whens or floors or phases):
        return None
    by_name = {v.name: v for v in model.variables}
    starts = discrete_starts(model).values  # initial equations v = e come first
    discrete = tuple(Discrete(n, by_name[n].type,
                              starts.get(n, by_name[n].attributes.start), by_name[n].span)
                     for n in held)
    iterated = tuple(n for n in pre if n not in held_set and n in by_name and (
        by_name[n].type != "Real" or by_name[n].variability == "discrete"))
    return EventSystem(discrete, tuple(relations), tuple(timed.values()), tuple(samples),
                       tuple(pre), _sorted_whens(model.whens), tuple(floors),
                       tuple(_time_rate(c.args[0], params) for c in floors),
                       "initial" in phases, "terminal" in phases, iterated)


def with_events(model: flat.FlatModel, system: ode.ODE) -> ode.ODE:
    """``system`` with its events (``ODE.events``; unchanged for a continuous model).
    ``sign``, ``min`` and ``max`` outside ``noEvent`` become if-expressions
    on relations first, and ``ceil``, ``integer``, ``div``, ``mod`` and ``rem`` of
    continuous arguments expressions of ``floor`` (held between events), so that
    their switches are events too."""
    known = frozenset({q.name for q in system.parameters} | set(w.assigned(model.whens)))

    def f(e: x.Expr) -> x.Expr:
        return switched_builtins(e, known)

    steps = tuple(ode.map_step(s, f) for s in system.steps)
    observed = tuple(ode.Assign(a.name, f(a.expr), a.span) for a in system.observed)
    rewritten = dataclasses.replace(system, steps=steps, observed=observed)
    whens = tuple(_rewrite_when(c, f) for c in model.whens)
    events = event_system(dataclasses.replace(model, whens=whens), rewritten)
    if events is None:
        return system
    return dataclasses.replace(rewritten, events=events)


def _rewrite_when(clause: w.When, f: Callable[[x.Expr], x.Expr]) -> w.When:
    return dataclasses.replace(clause, branches=tuple(dataclasses.replace(
        b, conditions=tuple(f(c) for c in b.conditions),
        assignments=tuple(dataclasses.replace(a, value=f(a.value)) for a in b.assignments),
        reinits=tuple(dataclasses.replace(r, value=f(r.value)) for r in b.reinits))
        for b in clause.branches))


def switched_builtins(e: x.Expr, known: frozenset[str] | None = None) -> x.Expr:
    """``e`` with ``sign(a)`` as ``if a > 0 then 1 else if a < 0 then -1 else 0``,
    ``min(a, b)`` as ``if a < b then a else b`` and ``max(a, b)`` as ``if a > b then a
    else b``, outside ``noEvent``/``smooth`` (unchanged subtrees are shared). ``abs``
    stays a call: it expands into ``noEvent(if v >= 0 then v else -v)`` (3.7.1), and
    as a held branch it would be negative wherever the integrator tries a step past
    the relation's zero (the MSL's Stribeck friction ``exp(-fexp*abs(v))`` overflowed,
    an arc's ``abs(i) <= abs(v)*Goff`` never settled). With ``known`` (the parameters
    and discrete variables), the integer-valued built-ins of arguments that read
    anything else become expressions of ``floor`` (see :func:`_through_floor`)."""
    if isinstance(e, (x.Const, x.Var, x.Time)):
        return e
    if isinstance(e, x.Call):
        if e.name in _QUIET:
            return e
        args = tuple(switched_builtins(a, known) for a in e.args)
        if e.name == "sign":
            return x.If(x.BinOp(">", args[0], x.ZERO), x.ONE,
                        x.If(x.BinOp("<", args[0], x.ZERO), x.Const(-1), x.ZERO))
        if e.name in ("min", "max") and len(args) == 2:
            op = "<" if e.name == "min" else ">"
            return x.If(x.BinOp(op, args[0], args[1]), args[0], args[1])
        if (known is not None and e.name in _FLOORED
                and any(_continuous(a, set(known)) for a in args)):
            return _through_floor(e.name, args)
        return e if all(a is b for a, b in zip(args, e.args)) else x.Call(e.name, args)
    if isinstance(e, x.BinOp):
        left, right = switched_builtins(e.left, known), switched_builtins(e.right, known)
        return e if left is e.left and right is e.right else x.BinOp(e.op, left, right)
    if isinstance(e, (x.Neg, x.Not, x.Der)):
        arg = switched_builtins(e.arg, known)
        return e if arg is e.arg else type(e)(arg)
    if isinstance(e, x.If):
        c, t, o = (switched_builtins(a, known) for a in (e.cond, e.then, e.otherwise))
        return e if (c is e.cond and t is e.then and o is e.otherwise) else x.If(c, t, o)
    raise TypeError(f"not an expression: {e!r}")


_FLOORED = names(lambda b: b.floored)


def _floor(u: x.Expr) -> x.Expr:
    return x.Call("floor", (u,))


def _through_floor(name: str, args: tuple[x.Expr, ...]) -> x.Expr:
    """The integer-valued built-in ``name(args)`` through ``floor`` (3.7.2):
    ``ceil(u) = -floor(-u)``, ``integer(u) = floor(u)``, ``div(a, b)`` the
    truncation of ``a/b`` (``if floor(a/b) >= 0 then floor(a/b) else -floor(-a/b)``:
    the condition changes only where ``floor`` does, so at its events),
    ``mod(a, b) = a - floor(a/b)*b``, ``rem(a, b) = a - div(a, b)*b``."""
    if name in ("floor", "integer"):
        return _floor(args[0])
    if name == "ceil":
        return x.Neg(_floor(x.Neg(args[0])))
    q = x.BinOp("/", args[0], args[1])
    if name == "mod":
        return x.BinOp("-", args[0], x.BinOp("*", _floor(q), args[1]))
    trunc = x.If(x.BinOp(">=", _floor(q), x.ZERO), _floor(q), x.Neg(_floor(x.Neg(q))))
    if name == "div":
        return trunc
    return x.BinOp("-", args[0], x.BinOp("*", trunc, args[1]))


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


def _time_rate(u: x.Expr, params: set[str]) -> x.Expr | None:
    """``der(u)`` if ``u`` is affine in ``time`` with parameter coefficients, else None."""
    def plain(e: x.Expr) -> bool:
        return x.variables(e) <= params and not any(
            isinstance(n, x.Der) or (isinstance(n, x.Call) and (
                n.name not in x.MATH or n.name in _FLOORED)) for n in x.walk(e))

    if not plain(u):
        return None
    rate = x.time_derivative(u, lambda _: False)
    if not plain(rate) or any(isinstance(n, x.Time) for n in x.walk(rate)):
        return None
    return rate


def _continuous(node: x.Expr, known: set[str]) -> bool:
    """Whether a relation (or a built-in call) reads a continuous variable or ``time``
    (so it can change between events and needs a zero-crossing function)."""
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
        seen: set[int] = set()  # a node shared by the clause's expressions: once
        for e in when_exprs((c,)):
            names |= _reads(e, seen)
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


def _reads(e: x.Expr, seen: set[int]) -> set[str]:
    """Variables ``e`` reads, except through ``pre``; the nodes in ``seen`` (ids) are
    not visited again."""
    out: set[str] = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if (isinstance(node, x.Call) and node.name == "pre") or id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, x.Var):
            out.add(node.name)
        stack.extend(x.children(node))
    return out
