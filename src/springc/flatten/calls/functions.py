"""User-defined functions, inlined by executing their algorithm symbolically.

Input: a function class and argument values. Output: the value of its first output.
Assignments update an environment of values; ``for`` loops over parameter ranges are
unrolled; an ``if`` whose condition is not a constant runs both branches and merges
the assigned values with ``if``-expressions. The flat model therefore contains no
function calls besides the scalar built-ins.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any, cast

import numpy as np

from ...errors import FlattenError, Note, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ...ir.builtins import EQUATION, names
from ...parse import ClassEntry, lookup_class, member_class
from .. import arrays as a
from ..array_ops import check_loop_nest, with_range
from ..checks import check_access_class
from ..natives import external_value, is_external
from ..redeclare import redeclared_class
from ..scopes import (
    ClassScope,
    ClassView,
    ExpressionEvaluator,
    FunctionScope,
    LocalScope,
    Scope,
    ViewComponent,
)
from .assertions import assertion, guard_assertions
from .control import (
    Jumped,
    branch_jumps,
    check_jumps,
    folded,
    run_loop_body,
    run_while,
    stray,
)
from .counted import run_counted
from .jumps import flags, is_flag, lowered, merged_flag
from .parameter_calls import parameter_call
from .record_values import construct, empty_record, record_class, store_field
from .short_functions import short_defaults

MAX_DEPTH = 50


def call_function(ev: ExpressionEvaluator, entry: ClassEntry, args: list[a.Value],
                  named: dict[str, tuple[a.Value, Span]], call: s.Call,
                  count: int = 1) -> a.Value:
    """The value of the call's first output (``count`` > 1: a list of the first
    ``count`` outputs, for ``(a, b) := f(x)``)."""
    if entry.defn.kind == "record":
        record: a.Value = construct(ev, entry, args, named, call)
        return record
    if is_external(entry):
        return _execute(ev, entry, args, named, call, count)
    return parameter_call(ev, args, named,
                          lambda given, by_name: _execute(ev, entry, given, by_name, call, count))


def _execute(ev: ExpressionEvaluator, entry: ClassEntry, args: list[a.Value],
             named: dict[str, tuple[a.Value, Span]], call: s.Call, count: int) -> a.Value:
    """The call's outputs by executing the function's algorithm symbolically."""
    depth = ev.call_depth
    if depth > MAX_DEPTH:
        raise FlattenError(f"'{entry.full_name}' calls itself too deeply to be inlined",
                           call.span, hint="recursive functions are not supported")
    view = ev.flattener.view(entry)
    comps = [_with_inherited(ev, c, view) for c in view.components.values()]
    inputs = [c for c in comps if c.causality == "input"]
    outputs = [c for c in comps if c.causality == "output"]
    if not outputs and count:
        raise FlattenError(f"function '{entry.full_name}' has no output", call.span)
    if len(args) > len(inputs):
        raise FlattenError(f"'{entry.full_name}' takes {len(inputs)} input(s), "
                           f"{len(args)} given", call.span,
                           [Note("function defined here", entry.defn.span)])
    package = ev.flattener.package_scope(entry.parent or entry)
    scope = FunctionScope({}, package, entry)
    given = dict(zip((c.name for c in inputs), args))
    for name, (value, span) in named.items():
        if name not in {c.name for c in inputs}:
            raise FlattenError(f"'{entry.full_name}' has no input '{name}'", span)
        if name in given:
            raise FlattenError(f"input '{name}' is given twice", span)
        given[name] = value
    _check_functional_inputs(ev, entry, inputs, given, call)
    if count > 1:
        for comp in inputs:
            arg = given.get(comp.name)
            if a.is_array(arg) and not comp.dims and not comp.type_dims:
                raise FlattenError(f"'{entry.full_name}' has several outputs and cannot be "
                                   f"called element-wise: its input '{comp.name}' is a "
                                   f"scalar, given {ev.describe(arg)} (section 12.4.6)",
                                   call.span, [Note("declared here", comp.span)])
    ev.call_depth = depth + 1
    quiet = not (generates_events(entry) or ev.eventful)
    ev.literal += quiet
    try:
        for comp in comps:
            _declare(ev, scope, comp, given, call)
        if is_external(entry):
            native: a.Value = external_value(ev, entry, scope.names, call, comps, count)
            return native
        check_jumps(entry.defn.algorithm, in_function=True)
        for stmt in entry.defn.algorithm:
            if isinstance(stmt, s.ForStatement):
                check_loop_nest(ev, stmt, scope)
        algorithm = lowered(entry.defn.algorithm)
        if algorithm is not entry.defn.algorithm:
            scope.names.update((flag, x.Const(False)) for flag in flags(algorithm))
        try:
            _run(ev, algorithm, scope)
        except Jumped as jumped:
            if jumped.jump.kind != "return":
                raise stray(jumped) from None
    finally:
        ev.call_depth = depth
        ev.literal -= quiet
    if count > len(outputs):
        raise FlattenError(f"'{entry.full_name}' has {len(outputs)} output(s), "
                           f"{count} are used", call.span,
                           [Note("function defined here", entry.defn.span)])
    results: list[a.Value] = []
    for output in outputs[:count]:
        result: a.Value | None = scope.names[output.name]
        if result is None:
            raise FlattenError(f"output '{output.name}' of '{entry.full_name}' is never "
                               "assigned", call.span, [Note("declared here", output.span)])
        results.append(result)
    if count == 1:
        return results[0]
    return results  # type: ignore[return-value]  # a list only for count != 1


def _check_functional_inputs(ev: ExpressionEvaluator, entry: ClassEntry,
                             inputs: list[s.Component], given: dict[str, a.Value],
                             call: s.Call) -> None:
    """A function passed as an argument goes to an input of a function type (12.4.2)."""
    for comp in inputs:
        value = given.get(comp.name)
        if not isinstance(value, a.FunctionArgument):
            continue
        try:
            kind = ev.flattener.resolve_class(comp.type_name, entry).defn.kind
        except FlattenError:
            kind = ""
        if kind != "function":
            raise FlattenError(f"the input '{comp.name}' of '{entry.full_name}' is given "
                               f"the function '{value.entry.full_name}', but it is not a "
                               "functional input", call.span,
                               [Note("declared here", comp.span)],
                               "only an input declared with a function type takes a "
                               "function (Modelica 3.6, section 12.4.2)")


def generates_events(entry: ClassEntry) -> bool:
    """Whether the function has ``annotation(GenerateEvents = true)``: without it, the
    relations and switching built-ins of its body generate no events, "similar to
    inlining the function body while wrapping all expressions in noEvent" (Modelica
    3.6, section 12.8; 8.5: "all assignment statements within function classes are
    implicitly treated with noEvent"). A body inlined inside such a body stays literal."""
    annotation = entry.defn.annotation
    return annotation is not None and any(
        arg.path == ("GenerateEvents",) and arg.modification is not None
        and isinstance(arg.modification.value, s.Bool) and arg.modification.value.value
        for arg in annotation.arguments)


def condition_value(ev: ExpressionEvaluator, cond: s.Expr, scope: Scope) -> a.Value:
    """The value of a when-clause's condition. The functions it calls generate events
    as if they had ``GenerateEvents = true``: a condition of the form ``f(x)``
    (a Boolean of a function of continuous variables, not a discrete-time expression,
    3.8.3) fires its clause where ``f``'s relations switch, as before 12.8 was kept,
    instead of never (a literal condition is read at events only)."""
    ev.eventful += 1
    try:
        return ev.value(cond, scope)
    finally:
        ev.eventful -= 1


def function_of(ev: ExpressionEvaluator, ref: s.Ref, scope: Scope) -> ClassEntry:
    """The function a call names: a class, or ``a.f`` with ``a`` a scalar component
    whose class declares the function ``f`` (section 5.3.2), or the function passed to
    a functional input of the function being run (section 12.4.2)."""
    if len(ref.parts) == 1:
        passed = _passed_function(ref.parts[0].name, scope)
        if passed is not None:
            return passed
    if len(ref.parts) > 1 and lookup_class(ref.parts[0].name, scope.entry) is None:
        owner: object = None
        k = len(ref.parts) - 1
        while k > 0:  # the longest prefix that is a component: a.B.C.f
            try:
                owner = ev.reference(s.Ref(ref.parts[:k], ref.span), scope)
                break
            except FlattenError:
                k -= 1
        if isinstance(owner, ClassScope):
            replaced = _redeclared_function(ev, owner, ref.parts[k:])
            if replaced is not None:
                return replaced
            found: ClassEntry | None = owner.entry
            for part in ref.parts[k:]:
                container = found
                found = member_class(found, part.name) if found is not None else None
                if container is not None and found is not None:
                    check_access_class(container, found, ref)
            if found is None or found.defn.kind != "function":
                raise FlattenError(f"'{owner.entry.full_name}' (the class of "
                                   f"'{owner.prefix}') has no function "
                                   f"'{'.'.join(p.name for p in ref.parts[k:])}'", ref.span)
            return found
    return ev.flattener.resolve_function(ref, scope)


def _passed_function(name: str, scope: Scope) -> ClassEntry | None:
    """The function held by the functional input ``name`` of the running function."""
    where: Any = scope
    while isinstance(where, LocalScope):
        if name in where.names:
            return None
        where = where.parent
    if isinstance(where, FunctionScope):
        held = where.names.get(name)
        if isinstance(held, a.FunctionArgument):
            entry: ClassEntry = held.entry
            return entry
    return None


def argument_value(ev: ExpressionEvaluator, arg: s.Expr, scope: Scope) -> a.Value:
    """An argument of a user function: a value, or a function passed by its name to a
    functional input (section 12.4.2: ``quadrature(0, 1, Parabola)``)."""
    try:
        return ev.value(arg, scope)
    except FlattenError:
        if not isinstance(arg, s.Ref):
            raise
        try:
            entry = function_of(ev, arg, scope)
        except FlattenError:
            entry = None
        if entry is None or entry.defn.kind != "function":
            raise
        return cast(a.Value, a.FunctionArgument(entry))


def _redeclared_function(ev: ExpressionEvaluator, owner: ClassScope,
                         parts: tuple[s.RefPart, ...]) -> ClassEntry | None:
    """``b.f()`` where ``b``'s class was given ``redeclare function f = g`` (in an
    extends clause or a modification): the function ``g``, looked up where the
    redeclaration is written (section 7.3)."""
    if len(parts) != 1:
        return None
    found = redeclared_class(owner, s.Ref(parts, parts[0].span))
    short = found[0].short if found is not None else None
    if found is None or short is None:
        return None
    entry = ev.flattener.resolve_class(short.base, found[1].entry)
    return entry if entry.defn.kind == "function" else None


def call_outputs(ev: ExpressionEvaluator, call: s.Call, scope: Scope, count: int
                 ) -> list[a.Value]:
    """The first ``count`` outputs of a call of a user-defined function."""
    entry, named = short_defaults(ev, function_of(ev, call.func, scope), call.func, scope)
    args = [argument_value(ev, arg, scope) for arg in call.args]
    named.update({n.name: (argument_value(ev, n.value, scope), n.span) for n in call.named})
    values = call_function(ev, entry, args, named, call, count)
    return values if count > 1 else [values]  # type: ignore[return-value]


#: Built-in calls that may stand alone but are not supported yet (events).
STANDALONE_BUILTINS = names(lambda b: b.kind == EQUATION)


def call_for_effect(ev: ExpressionEvaluator, call: s.Call, scope: Scope, what: str) -> None:
    """A call standing as an equation or statement (``f(x);``, section 12.4.7): its
    results are dropped, the assertions of the inlined function are kept."""
    name = call.func.dotted
    if ev.builtins.lookup(name, scope) is not None or name in STANDALONE_BUILTINS:
        raise FlattenError(f"`{name}` is not supported yet as {what}",
                           call.span, hint="springc supports a subset of Modelica; see "
                           "\"Not supported yet\" in docs/language.md")
    call_outputs(ev, call, scope, 0)


def multiple_outputs(ev: ExpressionEvaluator, targets: Sequence[object], value: s.Expr,
                     scope: Scope) -> list[a.Value]:
    """The outputs of ``value`` for ``(a, b) := f(x)``: ``value`` must be a call."""
    if not isinstance(value, s.Call):
        raise FlattenError("several outputs need a function call on the right-hand side",
                           value.span, hint="write (a, b) := f(x)")
    return call_outputs(ev, value, scope, len(targets))


def _with_inherited(ev: ExpressionEvaluator, comp: ViewComponent, view: ClassView
                    ) -> s.Component:
    """A function's component with the causality of its type (``type In = input
    Real``) and the default an ``extends`` modification gives it (``extends F(x = 10)``)."""
    decl = comp.decl
    if not decl.causality:
        causality = ev.flattener.declared_type(comp).rtype.prefixes[1]
        if causality:
            decl = replace(decl, causality=causality)
    for mod, _owner in view.extends_mods:
        for arg in mod.arguments:
            if arg.path == (decl.name,) and arg.modification is not None \
                    and arg.modification.value is not None and decl.modification is None:
                decl = replace(decl, modification=arg.modification)
    return decl


def _declare(ev: ExpressionEvaluator, scope: FunctionScope, comp: s.Component,
             given: dict[str, a.Value], call: s.Call) -> None:
    if comp.name in given:
        scope.names[comp.name] = given[comp.name]
        return
    mod = comp.modification
    if mod is not None and mod.value is not None:
        scope.names[comp.name] = ev.value(mod.value, scope)
        return
    if comp.causality == "input":
        raise FlattenError(f"input '{comp.name}' is missing in this call", call.span,
                           [Note("declared here", comp.span)])
    record = record_class(ev, comp, scope.entry)
    if record is not None:
        scope.names[comp.name] = empty_record(ev, record)
        return
    dims = [d for d in comp.dims + comp.type_dims]
    if dims and all(isinstance(d, s.Colon) for d in dims):
        # a flexible array: empty until assigned (section 12.4.5)
        scope.names[comp.name] = np.empty((0,) * len(dims), dtype=object)
        return
    if any(isinstance(d, s.Colon) for d in dims):
        scope.names[comp.name] = None  # sized by its first assignment
        return
    if dims:
        sizes = tuple(ev.integer(d, scope, "an array size") for d in dims)
        if any(n < 0 for n in sizes):
            raise FlattenError(f"array size must not be negative, found {min(sizes)}",
                               comp.span)
        ev.flattener.limits.check_size(math.prod(sizes), f"'{comp.name}'", comp.span)
        out = np.empty(sizes, dtype=object)
        out.fill(x.ZERO)
        scope.names[comp.name] = out
    else:
        scope.names[comp.name] = None


def _run(ev: ExpressionEvaluator, body: tuple[s.Statement, ...], scope: FunctionScope,
         guard: x.Expr | None = None) -> None:
    """Execute ``body``; ``guard``: the condition under which it runs (inside an ``if``
    on a value known only at run time), for the assertions in it."""
    for stmt in body:
        if isinstance(stmt, s.Assign):
            start = len(ev.flattener.assertions)
            _assign(ev, stmt, scope)
            if guard is not None:  # the functions it calls run only where guard holds
                guard_assertions(ev.flattener.assertions, start, guard)
        elif isinstance(stmt, s.ForStatement):
            _for(ev, stmt, stmt.indices, scope, guard)
        elif isinstance(stmt, s.CallStatement):
            _call(ev, stmt, scope, guard)
        elif isinstance(stmt, s.WhileStatement):
            _while(ev, stmt, scope, guard)
        elif isinstance(stmt, s.Jump):
            raise Jumped(stmt)
        elif isinstance(stmt, s.WhenStatement):
            raise FlattenError("a when statement is not allowed in a function",
                               stmt.span, hint="functions have no events: move the when "
                               "statement to an algorithm section of a model (Modelica "
                               "3.6, section 12.2)")
        else:
            _if(ev, stmt, scope, guard)


def _while(ev: ExpressionEvaluator, stmt: s.WhileStatement, scope: FunctionScope,
           guard: x.Expr | None) -> None:
    run_while(ev, stmt, lambda: ev.scalar(stmt.condition, scope),
              lambda: _run(ev, stmt.body, scope, guard),
              lambda: run_counted(ev, stmt, scope, guard,
                                  lambda running: _run(ev, stmt.body, scope, running)))


def _call(ev: ExpressionEvaluator, stmt: s.CallStatement, scope: FunctionScope,
          guard: x.Expr | None) -> None:
    if stmt.call.func.dotted != "assert":
        start = len(ev.flattener.assertions)
        call_for_effect(ev, stmt.call, scope, "a statement")
        if guard is not None:
            guard_assertions(ev.flattener.assertions, start, guard)
        return
    origin = flat.Origin("function", "", scope.entry.full_name)
    ev.flattener.assertions.append(assertion(ev, stmt.call, scope, origin, guard))


def _for(ev: ExpressionEvaluator, stmt: s.ForStatement, indices: tuple[s.ForIndex, ...],
         scope: FunctionScope, guard: x.Expr | None = None) -> None:
    index, rest = with_range(ev, indices[0], stmt.body, scope), indices[1:]
    values = ev.range_values(index, scope)
    ev.flattener.limits.add_iterations(len(values), index.span)
    for value in values:
        scope.names[index.name] = value
        if rest:
            _for(ev, stmt, rest, scope, guard)
        elif not run_loop_body(lambda: _run(ev, stmt.body, scope, guard)):
            break
    scope.names.pop(index.name, None)


def _if(ev: ExpressionEvaluator, stmt: s.IfStatement, scope: FunctionScope,
        guard: x.Expr | None = None) -> None:
    branches = list(stmt.branches)
    if not branches:
        _run(ev, stmt.otherwise, scope, guard)
        return
    cond_expr, body = branches[0]
    cond = folded(ev.scalar(cond_expr, scope))
    ev.flattener.statement_conditions.append((cond, cond_expr.span))
    rest = s.IfStatement(tuple(branches[1:]), stmt.otherwise, stmt.span)
    if isinstance(cond, x.Const):
        _run(ev, body, scope, guard) if cond.value else _if(ev, rest, scope, guard)
        return
    before = dict(scope.names)
    then_guard = cond if guard is None else x.BinOp("and", guard, cond)
    try:
        branch_jumps(lambda: _run(ev, body, scope, then_guard), stmt.span)
    except FlattenError:  # a branch a parameter rules out need not be evaluable
        if _known(ev, cond) is not False:
            raise
        scope.names = before
        _if(ev, rest, scope, guard)
        return
    then_names = scope.names
    scope.names = dict(before)
    not_cond = x.Not(cond)
    else_guard = not_cond if guard is None else x.BinOp("and", guard, not_cond)
    try:
        branch_jumps(lambda: _if(ev, rest, scope, else_guard), stmt.span)
    except FlattenError:
        if _known(ev, cond) is not True:
            raise
        scope.names = dict(before)
        _run(ev, body, scope, guard)
        return
    resized = [name for name, value in then_names.items() if name in before
               and a.shape(value) != a.shape(scope.names.get(name))]
    one_sided = [name for name, value in then_names.items() if name in before
                 and (value is None) != (scope.names.get(name) is None)]
    if (resized or one_sided) and _known(ev, cond) is not None:
        # sizes are fixed before the simulation (10.1), and a variable a branch leaves
        # unassigned has no value there: the parameters decide the branch taken
        if _known(ev, cond):
            scope.names = then_names
        return
    if resized:
        raise FlattenError(f"'{resized[0]}' gets different sizes in the branches of this "
                           "if-statement, whose condition is known only during the "
                           "simulation", stmt.span)
    for name, then_value in then_names.items():
        other = scope.names.get(name)
        if then_value is other or name not in before:
            continue
        if then_value is None or other is None:
            # unassigned where the other branch runs: its value there is undefined
            # (reading it is an error, 12.4.4), and the assigned one serves as well
            scope.names[name] = other if then_value is None else then_value
            continue
        if is_flag(name):  # a return or break flag (jumps.py): folded Boolean logic
            scope.names[name] = merged_flag(cond, then_value, other)
            continue
        # an element the branch left as it was stays itself (not 'if c then v else v':
        # a loop over a vector would nest one such if per iteration in every element)
        scope.names[name] = a.elementwise(
            lambda t, o: t if t is o else x.If(cond, t, o), then_value, other)


def _known(ev: ExpressionEvaluator, cond: x.Expr) -> bool | None:
    """The value of a condition that is a parameter expression, else None."""
    if not ev.flattener.is_parameter_expression(cond):
        return None
    try:
        return bool(ev.fold(cond))
    except (KeyError, ArithmeticError, ValueError, TypeError):
        return None


def _assign(ev: ExpressionEvaluator, stmt: s.Assign, scope: FunctionScope) -> None:
    if len(stmt.targets) > 1:
        values = multiple_outputs(ev, stmt.targets, stmt.value, scope)
        for target, value in zip(stmt.targets, values):
            if target is not None:
                _store(ev, target, value, stmt, scope)
        return
    target = stmt.targets[0]
    assert target is not None
    _store(ev, target, ev.value(stmt.value, scope), stmt, scope)


def _store(ev: ExpressionEvaluator, target: s.Ref, value: a.Value, stmt: s.Assign,
           scope: FunctionScope) -> None:
    part = target.parts[0]
    current = scope.names.get(part.name)
    if len(target.parts) > 1 and isinstance(current, a.RecordValue) \
            and not any(p.subscripts for p in target.parts):
        scope.names[part.name] = store_field(current, target.parts[1:], value, target)
        return
    if len(target.parts) > 1 or part.name not in scope.names:
        raise FlattenError(f"'{target.dotted}' is not a variable of this function",
                           target.span)
    if not part.subscripts:
        scope.names[part.name] = value
        return
    current = scope.names[part.name]
    if not a.is_array(current):
        raise FlattenError(f"'{part.name}' is not an array", part.span)
    updated = current.copy()
    index = tuple(_subscript(ev, sub, scope) for sub in part.subscripts)
    try:
        if any(isinstance(i, x.Expr) for i in index):
            _store_at_run_time(updated, index, value)
        else:
            updated[cast(tuple[slice | int, ...], index)] = value
    except (IndexError, ValueError) as err:
        raise FlattenError(f"cannot assign to '{target.dotted}': {err}", stmt.span) from None
    scope.names[part.name] = updated


def _subscript(ev: ExpressionEvaluator, sub: s.Expr, scope: FunctionScope
               ) -> slice | int | x.Expr:
    """A 0-based subscript, or the expression of one known only during the simulation
    (an Integer the function computes from its inputs)."""
    if isinstance(sub, s.Colon):
        return slice(None)
    try:
        return ev.integer(sub, scope, "a subscript") - 1
    except FlattenError:
        found = ev.value(sub, scope)
        if isinstance(found, x.Expr) and not isinstance(found, x.Const):
            return found
        raise


def _store_at_run_time(updated: np.ndarray, index: tuple[slice | int | x.Expr, ...],
                       value: a.Value) -> None:
    """``updated[index] := value`` where some subscripts are known only during the
    simulation: every element they may name becomes ``if i == k then value else
    old``, so that an index out of range assigns none."""
    run_time = [k for k, i in enumerate(index) if isinstance(i, x.Expr)]
    for chosen in np.ndindex(*(updated.shape[k] for k in run_time)):
        at: list[Any] = list(index)
        cond: x.Expr | None = None
        for k, j in zip(run_time, chosen):
            test = x.BinOp("==", cast(x.Expr, index[k]), x.Const(j + 1))
            cond = test if cond is None else x.BinOp("and", cond, test)
            at[k] = j
        assert cond is not None
        place: tuple[Any, ...] = tuple(at)
        old = updated[place]
        updated[place] = a.elementwise(lambda new, kept, c=cond: x.If(c, new, kept),
                                       value, old)
