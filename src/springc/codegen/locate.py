"""Where in the model an expression that the code generator cannot translate comes from;
``initial()`` in the values computed in initialization.

The printers meet expressions one node at a time, far from the equations they belong to;
an error they raise carries the node (:func:`untranslatable`). :func:`locate` finds the
first model element whose expression holds that node (an equation, a when-clause, a
binding, a start value, an assertion) and gives the error its span and name, so that
every error of this stage points at the model text.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

from ..errors import CodegenError, Span
from ..ir import dae, ode
from ..ir import expr as x


def untranslatable(message: str, node: x.Expr) -> CodegenError:
    """The error of a printer that cannot translate ``node`` (located later)."""
    error = CodegenError(message)
    error.node = node  # type: ignore[attr-defined]
    return error


def locate(error: CodegenError, system: ode.ODE) -> CodegenError | None:
    """``error`` with the span and name of the model element whose expression holds its
    node; None if it has a span already, no node, or the node is not found."""
    node = getattr(error, "node", None)
    if error.span is not None or not isinstance(node, x.Expr):
        return None
    for expr, span, what in _sources(system):
        if any(n == node for n in x.walk(expr)):
            return CodegenError(f"{error.message}: {x.to_text(node)} in {what}", span,
                                error.notes, error.hint or "springc cannot compute this "
                                "expression there; rewrite it (see \"Not supported yet\" "
                                "in docs/language.md)")
    return None


def _sources(system: ode.ODE) -> Iterator[tuple[x.Expr, Span, str]]:
    """Every expression of ``system`` with its span and a name for its element."""
    for step in system.steps:
        if isinstance(step, ode.Assign):
            yield step.expr, step.span, f"the equation of '{step.name}'"
        elif isinstance(step, ode.LinearBlock):
            for e in (*step.rhs, *(e for _, _, e in step.matrix)):
                yield e, step.spans[0], f"the linear system of {', '.join(step.names[:3])}"
        else:
            for a in step.inner:
                yield a.expr, a.span, f"the equation of '{a.name}'"
            for e in step.residuals:
                yield e, step.spans[0], f"the system of {', '.join(step.tearing[:3])}"
    for a in system.observed:
        yield a.expr, a.span, f"the equation of '{a.name}'"
    for p in system.parameters:
        for value in (p.binding, p.start):
            if value is not None:
                yield value, p.span, f"the value of '{p.name}'"
    for s in system.states:
        if s.start is not None:
            yield s.start, s.span, f"the start value of '{s.name}'"
    for assertion in system.assertions:
        yield assertion.condition, assertion.span, "an assertion"
    yield from _event_sources(system)


def _event_sources(system: ode.ODE) -> Iterator[tuple[x.Expr, Span, str]]:
    events = system.events
    if events is None:
        return
    for d in events.discrete:
        if d.start is not None:
            yield d.start, d.span, f"the start value of '{d.name}'"
    for when in events.whens:
        for branch in when.branches:
            for c in branch.conditions:
                yield c, branch.span, "the condition of a when-clause"
            for a in branch.assignments:
                yield a.value, a.span, f"the when-equation of '{a.name}'"
            for r in branch.reinits:
                yield r.value, r.span, f"the reinit of '{r.name}'"


def at_initialization(system: ode.ODE) -> ode.ODE:
    """``system`` with ``initial()`` made true in the values computed in initialization
    (parameter bindings, start values), where it holds (Modelica 3.6, section 3.7.4)."""
    def fixed(e: x.Expr | None) -> x.Expr | None:
        if e is None or not any(_is_initial(n) for n in x.walk(e)):
            return e
        return _replace_initial(e)

    def parameter(p: dae.Parameter) -> dae.Parameter:
        binding, start = fixed(p.binding), fixed(p.start)
        if binding is p.binding and start is p.start:
            return p  # (no copy of the 100,000 parameters of a large scene)
        return replace(p, binding=binding, start=start)

    def state(s: ode.State) -> ode.State:
        start = fixed(s.start)
        return s if start is s.start else replace(s, start=start)

    parameters = tuple(map(parameter, system.parameters))
    states = tuple(map(state, system.states))
    events = system.events
    if events is not None:
        events = replace(events, discrete=tuple(replace(d, start=fixed(d.start))
                                                for d in events.discrete))
    return replace(system, parameters=parameters, states=states, events=events)


def _is_initial(e: x.Expr) -> bool:
    return isinstance(e, x.Call) and e.name == "initial" and not e.args


def _replace_initial(e: x.Expr) -> x.Expr:
    return x.Const(True) if _is_initial(e) else x.map_children(e, _replace_initial)
