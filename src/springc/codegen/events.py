"""The event functions of a hybrid model's generated module: ode.ODE with events ->
statement lists (printed like ``rhs``) and the module text around them.

Every function has the model-function signature ``f(t, x, p, z)``:

- ``zero_crossings(t, x, p, z)``: the zero-crossing function ``left - right`` of
  each state relation (``ZERO_CROSSINGS``; the relation's held value in ``z`` is the
  relation ``RELATION_OPS[k]`` of that value with 0 at the last event);
- ``next_time_event(t, x, p, z)``: the first time event after ``t`` (inf if none);
- ``event_update(t, x, p, z)``: the event at ``t``: ``event_begin`` (left limits for
  ``pre``, sample flags), ``event_pass`` until nothing changes (at most
  ``EVENT_ITERATIONS``; ``z[Z_STATUS]`` is 1.0 if it did not settle), ``event_end``
  (conditions as they hold after the event); returns the states after the event.

The layout of ``z`` is :mod:`.event_layout`'s.
"""

from __future__ import annotations

import dataclasses

from ..ir import expr as x
from ..ir import ode
from ..ir.hybrid import EventSystem
from .context import CodegenContext
from .encoding import encode_strings
from .event_layout import EventLayout
from .hysteresis import (
    after_event,
    begin_event,
    crossing,
    early_pass,
    first_values,
    pass_value,
)
from .statements import Let, Load, Raw, Stmt, Store, guarded

EVENT_ITERATIONS = 100
SIMULTANEOUS_PASSES = 20
"""Passes of the event iteration that switch every moved relation at once; the
later ones switch one relation at a time (see :func:`_relations_now`)."""
_ONE, _ZERO = x.Const(1.0), x.Const(0.0)


def held_system(system: ode.ODE, layout: EventLayout) -> ode.ODE:
    """``system`` whose steps and aliases read held relations and event slots."""
    h = layout.hold

    return dataclasses.replace(
        system, steps=tuple(ode.map_step(s, h) for s in system.steps),
        observed=tuple(ode.Assign(a.name, h(a.expr), a.span) for a in system.observed))


def _flag(cond: x.Expr) -> x.Expr:
    return x.If(cond, _ONE, _ZERO)


def _truth(name: str) -> x.Expr:
    return x.BinOp("<>", x.Var(name), _ZERO)


def _any(items: list[x.Expr]) -> x.Expr:
    """``items[0] or items[1] or ...``, joined pairwise (``RealFFT``'s 4,800 changed
    discrete values: a left fold that deep passes Python's recursion limit when
    printed), evaluated left to right as the fold."""
    level = [item for item in items if item != x.Const(False)]
    if not level:
        return x.Const(False)
    while len(level) > 1:
        level = [x.BinOp("or", level[k], level[k + 1]) for k in range(0, len(level) - 1, 2)
                 ] + level[len(level) - len(level) % 2:]
    return level[0]


def _eps(t: x.Expr) -> x.Expr:
    """1e-12 * max(1, |t|): times closer than this are the same event time."""
    return x.mul(x.Const(1e-12), x.Call("max", (_ONE, x.Call("abs", (t,)))))


def _base(m: CodegenContext) -> list[Stmt]:
    steps, _ = m.step_stmts()
    return m.loads() + steps + m.alias_stmts(sorted(m.aliases))


def zero_crossings(m: CodegenContext, layout: EventLayout) -> list[Stmt]:
    out = [*_base(m), Raw(f"g = np.empty({len(layout.relations)})")]
    for k, rel in enumerate(layout.events.relations):
        out.append(Store(f"g[{k}]", crossing(layout, k), x.to_text(rel)))
    return out


def next_time_event(m: CodegenContext, layout: EventLayout) -> list[Stmt]:
    out: list[Stmt] = [*m.loads()[:len(m.params)], *_state_loads(m, layout),
                       Let("_zq", x.Const(float("inf")))]
    later = x.add(x.TIME, _eps(x.TIME))
    for tr in layout.events.time_relations:
        at = tr.at
        out.append(Let("_zq", x.If(x.BinOp("and", x.BinOp(">", at, later),
                                           x.BinOp("<", at, x.Var("_zq"))), at, x.Var("_zq"))))
    for call, name, rate in zip(layout.events.floors, layout.floors, layout.floor_rates):
        if rate is None:
            continue
        out.append(Load(name, f"z[{layout.slot[name]}]", name))
        u0 = _at_time_zero(call.args[0])  # u = rate * time + u0
        held = x.Var(name)
        up = x.div(x.sub(x.add(held, _ONE), u0), rate)
        down = x.div(x.sub(held, u0), rate)
        at = x.If(x.BinOp(">", rate, _ZERO), up,
                  x.If(x.BinOp("<", rate, _ZERO), down, x.Const(float("inf"))))
        out.append(Let("_zq", x.If(x.BinOp("and", x.BinOp(">", at, later),
                                           x.BinOp("<", at, x.Var("_zq"))), at, x.Var("_zq"))))
    for start, interval in layout.events.samples:
        k = x.add(x.Call("floor", (x.div(x.sub(later, start), interval),)), _ONE)
        nxt = x.If(x.BinOp("<", later, start), start, x.add(start, x.mul(k, interval)))
        out.append(Let("_zq", x.Call("min", (x.Var("_zq"), nxt))))
    return [*out, Raw("_zo = np.empty(1)"), Store("_zo[0]", x.Var("_zq"))]


def _state_loads(m: CodegenContext, layout: EventLayout) -> list[Stmt]:
    """The loads of the states a time event reads: a ``fixed = false`` parameter
    the initial equations determine is a constant state (``simplify.free_parameters``),
    and ``sample(t0 + 1/f, 1/f)`` may start at one (``Blocks.Math.Mean``)."""
    read: set[str] = set()
    for tr in layout.events.time_relations:
        read |= x.variables(tr.at)
    for start, interval in layout.events.samples:
        read |= x.variables(start) | x.variables(interval)
    return [Load(n, f"x[{i}]", n) for i, n in enumerate(m.states) if n in read]


def _at_time_zero(e: x.Expr) -> x.Expr:
    """``e`` with ``time`` = 0."""
    if isinstance(e, x.Time):
        return _ZERO
    if isinstance(e, (x.Const, x.Var)):
        return e
    if isinstance(e, x.Call):
        return x.Call(e.name, tuple(_at_time_zero(a) for a in e.args))
    if isinstance(e, x.BinOp):
        return x.BinOp(e.op, _at_time_zero(e.left), _at_time_zero(e.right))
    if isinstance(e, (x.Neg, x.Not, x.Der)):
        return type(e)(_at_time_zero(e.arg))
    if isinstance(e, x.If):
        return x.If(*(_at_time_zero(a) for a in (e.cond, e.then, e.otherwise)))
    raise TypeError(f"not an expression: {e!r}")


def _sample_hit(t: x.Expr, start: x.Expr, interval: x.Expr) -> x.Expr:
    k = x.Call("floor", (x.add(x.div(x.sub(t, start), interval), x.Const(0.5)),))
    near = x.BinOp("<=", x.Call("abs", (x.sub(x.add(start, x.mul(k, interval)), t),)),
                   _eps(t))
    return x.BinOp("and", x.BinOp(">=", k, _ZERO), near)


def event_begin(m: CodegenContext, layout: EventLayout) -> list[Stmt]:
    out = _base(m)
    held = set(layout.discrete)
    for name, slot_name in layout.pre.items():
        if name not in held:
            now: x.Expr = x.Var(name)
            u = m.unknowns.get(name)
            if u is not None and u.start is not None:  # at the initialization pre(v)
                now = x.If(_truth("_zinit"), x.Var(slot_name), now)  # is its start
            out.append(Store(f"z[{layout.slot[slot_name]}]", now, f"pre({name})"))
    for (start, interval), name in zip(layout.events.samples, layout.samples):
        # false during the initialization (3.7.5): a sample at the start time is true at
        # the event after it (after_initial)
        hit = x.BinOp("and", _sample_hit(x.TIME, start, interval), x.Not(_truth("_zinit")))
        out.append(Store(f"z[{layout.slot[name]}]", _flag(hit)))
    out += begin_event(layout)
    out.append(Raw("_zdone = 1.0"))
    return out


def _relations_now(layout: EventLayout, out: list[Stmt]
                   ) -> tuple[dict[x.Expr, x.Expr], list[x.Expr]]:
    """The relations, time relations and floor values at the end of a pass (appended
    to ``out``): their new values by expression and whether each moved. When the
    event iteration has gone on for :data:`SIMULTANEOUS_PASSES` passes
    (``z[Z_STATUS]`` is 2.0), a pass switches only one state relation: the first
    that turns false, else the first that turns true. A mixed system whose
    simultaneous update cycles (a light body stopping under friction: the path
    parameter of one sliding direction points to the other and back) then walks to
    its consistent configuration one switch at a time, giving up a start condition
    before taking another (so that sticking is found before a reversal)."""
    ev = layout.events
    new: dict[x.Expr, x.Expr] = {}
    changed: list[x.Expr] = []
    one_at_a_time = x.BinOp("==", x.Var("_zstatus"), x.Const(2.0))
    out.append(Let("_zdown", _ZERO))  # whether a relation turns false
    for k, rel in enumerate(ev.relations):
        held = x.Var(layout.relations[k])
        out.append(Let(f"_zn{k}", _flag(pass_value(layout, k)), x.to_text(rel)))
        changed.append(x.BinOp("<>", x.Var(f"_zn{k}"), held))
        falls = x.BinOp("and", _truth(layout.relations[k]), x.Not(_truth(f"_zn{k}")))
        out.append(Let("_zdown", _flag(x.BinOp("or", _truth("_zdown"), falls))))
    out.append(Let("_zm", _ZERO))  # whether a relation has switched in this pass
    for k, rel in enumerate(ev.relations):
        held = x.Var(layout.relations[k])
        # one at a time: the first relation that turns false, else the first that
        # turns true (a start condition is given up before another is taken)
        flips = x.BinOp("and", changed[k], x.BinOp(
            "or", x.Not(_truth("_zdown")), _truth(layout.relations[k])))
        out.append(Let(f"_zh{k}", x.If(
            one_at_a_time, x.If(x.BinOp("and", flips, x.Not(_truth("_zm"))),
                                x.Var(f"_zn{k}"), held), x.Var(f"_zn{k}"))))
        out.append(Let("_zm", _flag(x.BinOp("or", _truth("_zm"), flips))))
        new[rel] = _truth(f"_zh{k}")
    for k, tr in enumerate(ev.time_relations):
        now = x.BinOp(">=", x.TIME, x.sub(tr.at, _eps(x.TIME)))
        out.append(Let(f"_zu{k}", _flag(now if tr.after else x.Not(now))))
        new[tr.relation] = _truth(f"_zu{k}")
        changed.append(x.BinOp("<>", x.Var(f"_zu{k}"), x.Var(layout.times[k])))
    # the held floor values: floor of their arguments now (3.7.2)
    for k, (call, rate) in enumerate(zip(ev.floors, layout.floor_rates)):
        u = layout.hold(call.args[0])
        if rate is not None:  # a time event: the value just after it
            u = x.add(u, x.mul(rate, _eps(x.TIME)))
        out.append(Let(f"_zk{k}", x.Call("floor", (u,)), x.to_text(call)))
        changed.append(x.BinOp("<>", x.Var(f"_zk{k}"), x.Var(layout.floors[k])))
    return new, changed


def event_pass(m: CodegenContext, layout: EventLayout) -> list[Stmt]:
    ev = layout.events
    out = _base(m)
    slot = layout.slot
    changed: list[x.Expr] = []
    # pre of the discrete variables: their values before this pass
    for name in layout.discrete:
        if name in layout.pre:
            out.append(Let(layout.pre[name], x.Var(name)))
    new, moves = _relations_now(layout, out)
    changed += moves
    # the relations settle first (pre held), then pre(v) := v of the iterated variables
    relations_moved = _any(list(changed))
    # clause by clause (sorted: a clause reading what another assigns comes after
    # it): the conditions with the new relations and the values assigned so far (a
    # branch fires when one of its conditions becomes true; at initialization only
    # conditions using initial() fire), then the branch's assignments
    by_clause: dict[int, list[tuple[int, int, x.Expr]]] = {}
    for k, (i, j, cond) in enumerate(layout.conditions):
        by_clause.setdefault(i, []).append((k, j, cond))
    active: dict[tuple[int, int], x.Expr] = {}
    reinits: dict[str, x.Expr] = {}
    stop: x.Expr = x.Var("_zstop")
    for i, clause in enumerate(ev.whens):
        fires: dict[int, list[x.Expr]] = {}
        for k, j, cond in by_clause.get(i, []):
            out.append(Let(f"_zd{k}", _flag(layout.hold(cond, new)), x.to_text(cond)))
            edge = x.BinOp("and", _truth(f"_zd{k}"),
                           x.Not(_truth(layout.condition_names[k])))
            if not any(isinstance(n, x.Call) and n.name == "initial" for n in x.walk(cond)):
                edge = x.BinOp("and", edge, x.Not(_truth("_zinit")))
            fires.setdefault(j, []).append(edge)
            changed.append(x.BinOp("<>", x.Var(f"_zd{k}"), x.Var(layout.condition_names[k])))
        earlier: list[x.Expr] = []
        for j in range(len(clause.branches)):
            fire = _any(fires.get(j, []))
            if earlier:
                fire = x.BinOp("and", fire, x.Not(_any(earlier)))
            out.append(Let(f"_za{i}_{j}", _flag(fire)))
            active[i, j] = _truth(f"_za{i}_{j}")
            earlier.append(active[i, j])
        for j, branch in enumerate(clause.branches):
            # one guard per branch: its values computed only where it fires, the
            # subexpressions they share (an FFT's outputs, a buffer's sum) once
            if branch.assignments:
                out.append(guarded(active[i, j], [
                    Let(a.name, layout.hold(a.value, new), a.name)
                    for a in branch.assignments]))
            for r in branch.reinits:  # from the values before any reinit
                reinits[r.name] = x.If(active[i, j], layout.hold(r.value, new),
                                       reinits.get(r.name, x.Var(r.name)))
            for t in branch.terminates:
                code = x.Const(float(layout.messages.index(t.message) + 1))
                stop = x.If(active[i, j], code, stop)
    for n, (name, value) in enumerate(reinits.items()):
        out.append(Let(f"_zx{n}", value, f"reinit({name})"))
        changed.append(x.BinOp("<>", x.Var(f"_zx{n}"), x.Var(name)))
    for name in layout.discrete:
        if name in layout.pre:
            changed.append(x.BinOp("<>", x.Var(name), x.Var(layout.pre[name])))
        else:
            changed.append(active_for(ev, name, active))
    for name in ev.iterated:  # equation-defined discrete variables: pre(v) := v (8.6)
        changed.append(x.BinOp("<>", x.Var(name), x.Var(layout.pre[name])))
    out.append(Store(f"z[{slot['_zchanged']}]", _flag(_any(changed))))
    out.append(Store(f"z[{slot['_zstop']}]", stop))
    for k, name in enumerate(layout.relations):
        out.append(Store(f"z[{slot[name]}]", x.Var(f"_zh{k}")))
    out += first_values(layout, [f"_zh{k}" for k in range(len(layout.relations))])
    for k, name in enumerate(layout.times):
        out.append(Store(f"z[{slot[name]}]", x.Var(f"_zu{k}")))
    for k, name in enumerate(layout.condition_names):
        out.append(Store(f"z[{slot[name]}]", x.Var(f"_zd{k}")))
    for k, name in enumerate(layout.floors):
        out.append(Store(f"z[{slot[name]}]", x.Var(f"_zk{k}")))
    for name in layout.discrete:
        out.append(Store(f"z[{slot[name]}]", x.Var(name), name))
        if name in layout.pre:
            out.append(Store(f"z[{slot[layout.pre[name]]}]", x.Var(layout.pre[name])))
    # from pass BAND_PASS on, pre(v) := v also while relations move (8.6 as written):
    # a start condition whose relation holds in the configuration before it and not
    # in the one it selects (OneWayClutch's 'sa > tau0_max') is then kept by its own
    # 'pre(startForward) and sa > tau0'
    out.append(Let("_zmoved", _flag(x.BinOp("and", relations_moved, early_pass()))))
    for name in ev.iterated:
        pre = x.Var(layout.pre[name])
        out.append(Store(f"z[{slot[layout.pre[name]]}]",
                         x.If(_truth("_zmoved"), pre, x.Var(name)), f"pre({name})"))
    out.append(Raw(f"xn = np.empty({len(m.states)})"))
    index = {name: n for n, name in enumerate(reinits)}
    for k, state in enumerate(m.states):
        value = x.Var(f"_zx{index[state]}") if state in index else x.Var(state)
        out.append(Store(f"xn[{k}]", value, state))
    return out


def active_for(ev: EventSystem, name: str, active: dict[tuple[int, int], x.Expr]) -> x.Expr:
    """Whether a branch assigning ``name`` is active (then it may have changed)."""
    items = [active[i, j] for i, clause in enumerate(ev.whens)
             for j, branch in enumerate(clause.branches)
             if any(a.name == name for a in branch.assignments)]
    return _any(items)


def event_end(m: CodegenContext, layout: EventLayout) -> list[Stmt]:
    slot = layout.slot
    loads = m.loads()
    cleared: list[Stmt] = [Let(name, _ZERO) for name in [*layout.samples, "_zinit"]]
    steps, _ = m.step_stmts()
    out = [*loads, Let("_zinit_was", x.Var("_zinit")), *cleared, *steps,
           *m.alias_stmts(sorted(m.aliases))]
    for k, (_, _, cond) in enumerate(layout.conditions):
        # a condition on initial() keeps its value at the event: 'not initial()'
        # becomes true at the event right after the initialization (after_initial)
        now = x.substitute(layout.hold(cond), {"_zinit": x.Var("_zinit_was")})
        out.append(Store(f"z[{slot[layout.condition_names[k]]}]", _flag(now),
                         x.to_text(cond)))
    for name in layout.samples:
        out.append(Store(f"z[{slot[name]}]", _ZERO))
    out += after_event(layout)
    out.append(Store(f"z[{slot['_zinit']}]", _ZERO))
    held = set(layout.discrete)
    for name, slot_name in layout.pre.items():  # between events pre(v) is v
        if name not in held:
            out.append(Store(f"z[{slot[slot_name]}]", x.Var(name), f"pre({name})"))
    out.append(Raw("_zdone = 1.0"))
    return out


FUNCTIONS = (
    ("zero_crossings", "Zero-crossing functions of the state relations (ZERO_CROSSINGS).",
     zero_crossings, "g"),
    ("next_time_event", "The first time event after t (inf: none).", next_time_event, "_zo[0]"),
    ("event_begin", "Start of an event: pre() of continuous variables, sample flags.",
     event_begin, "_zdone"),
    ("event_pass", "One pass of the event iteration: the states after it; writes z.",
     event_pass, "xn"),
    ("event_end", "End of an event: conditions as they hold after it.", event_end, "_zdone"),
)


def constants(m: CodegenContext, layout: EventLayout) -> list[str]:
    """The module constants of the events (names as escaped literals)."""
    ev = layout.events
    s = layout.slot
    return [
        "# Events (see event_update): the event slots of z start at Z_EVENTS.",
        "EVENTS = True",
        f"Z_EVENTS = {layout.base}",
        f"Z_SIZE = {layout.base + layout.size + 1}",
        f"ZERO_CROSSINGS = {encode_strings(layout.texts)}",
        f"RELATION_OPS = {tuple(r.op for r in ev.relations)!r}",
        f"Z_RELATIONS = {s[layout.relations[0]] if layout.relations else layout.base}",
        f"TIME_EVENTS = {encode_strings([x.to_text(t.relation) for t in ev.time_relations])}",
        f"SAMPLES = {len(ev.samples)}",
        f"DISCRETE = {encode_strings(layout.discrete)}",
        f"Z_DISCRETE = {[s[d] for d in layout.discrete]!r}",
        f"TERMINATE_MESSAGES = {encode_strings(layout.messages)}",
        f"Z_INITIAL = {s['_zinit']}",
        f"Z_TERMINAL = {s['_zterm']}",
        f"Z_TERMINATE = {s['_zstop']}",
        f"Z_CHANGED = {s['_zchanged']}",
        f"Z_STATUS = {s['_zstatus']}",
        f"EVENT_ITERATIONS = {EVENT_ITERATIONS}",
        f"SIMULTANEOUS_PASSES = {SIMULTANEOUS_PASSES}",
        f"USES_TERMINAL = {layout.uses_terminal}",
        f"AFTER_INITIAL = {after_initial(layout)}",
    ]


def after_initial(layout: EventLayout) -> bool:
    """Whether an event follows the initialization at the start time: where a
    ``sample`` may start then (3.7.5: "the first event iteration occurs after the
    initialization even if the start argument is identical to the start time"), or a
    when-condition reads ``initial()`` other than as the whole condition (``not
    initial()``), which may become true there."""
    return bool(layout.samples) or any(cond != x.Call("initial", ()) and any(
        isinstance(n, x.Call) and n.name == "initial" for n in x.walk(cond))
        for _, _, cond in layout.conditions)


EVENT_UPDATE = '''def event_update(t, x, p, z):
    """The event at time t (Modelica 3.6, 8.6): returns the states after it and
    leaves the discrete values in z. Set z[Z_INITIAL] = 1.0 first for the event at
    the start; z[Z_STATUS] is 1.0 if the event iteration did not settle in
    EVENT_ITERATIONS passes, z[Z_TERMINATE] > 0 if terminate() was called."""
    event_begin(t, x, p, z)
    z[Z_STATUS] = 1.0
    for _k in range(EVENT_ITERATIONS):
        if _k == SIMULTANEOUS_PASSES:
            z[Z_STATUS] = 2.0
        x = event_pass(t, x, p, z)
        if z[Z_CHANGED] == 0.0:
            z[Z_STATUS] = 0.0
            break
    event_end(t, x, p, z)
    return x'''

NO_EVENTS = [
    "EVENTS = False",
]
