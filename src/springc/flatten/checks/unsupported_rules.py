"""Static rules of constructs outside springc's subset: operator records and operators
(section 14, their restrictions in section 4.6) and stream variables (sections 4.4.2.2
and 15.1).

springc does not flatten these constructs (a class using them is refused with "not
supported yet"), but a class that breaks one of their rules is invalid whatever the
subset: :func:`check_unsupported_class` raises that error first, at the offending
element, with the rule and the section in its help. Input: the class entry whose
``unsupported`` errors are about to be reported, and the class lookup. Output: nothing
or a :class:`FlattenError`.
"""

from __future__ import annotations

from ...errors import FlattenError, Note
from ...ir import syntax as s
from ...parse import ClassEntry
from ..scopes import ClassViews, ExpressionEvaluator, Scope
from .rules import check_operator_base, rule_error

#: The operators that are only binary (section 14.5; '-' is unary or binary).
_BINARY = frozenset({"+", "*", "/", "^", "==", "<>", "<", "<=", ">", ">=", "and", "or"})

_OPERATOR_RECORD = ("an operator record may have only public components: no equation, "
                    "algorithm or protected section")


def check_unsupported_class(ctx: ClassViews, entry: ClassEntry) -> None:
    """The rules of operator classes and stream variables written in ``entry``."""
    defn = entry.defn
    if defn.operator:
        _check_operator_class(ctx, entry, defn)
    _check_streams(ctx, entry)


def _check_operator_class(ctx: ClassViews, entry: ClassEntry, defn: s.ClassDef) -> None:
    if defn.kind == "record":
        sections = [*defn.equations, *defn.initial_equations]
        if sections:
            raise rule_error("an operator record cannot have equations or algorithms",
                             sections[0].span, _OPERATOR_RECORD, "4.6")
        for element in defn.elements:
            if isinstance(element, s.Component | s.ClassDef) and element.protected:
                raise rule_error("an operator record cannot have protected elements",
                                 element.span, _OPERATOR_RECORD, "4.6")
        for element in defn.elements:
            if isinstance(element, s.Extends):
                try:
                    base = ctx.resolve_class(element.base, entry.parent or entry, entry)
                except FlattenError:
                    continue
                check_operator_base(element, base)
    for element in defn.elements:
        if isinstance(element, s.ClassDef) and element.operator:
            _check_operator(element)
            inner = entry.classes.get(element.name)
            if inner is not None:
                _check_operator_functions(ctx, entry, inner)


def _check_operator(defn: s.ClassDef) -> None:
    """An ``operator`` holds only declarations of functions (section 4.6)."""
    if defn.kind != "operator":
        return
    for element in defn.elements:
        if isinstance(element, s.Import) or (isinstance(element, s.ClassDef)
                                             and element.kind == "function"):
            continue
        what = (f"the {element.kind} '{element.name}'" if isinstance(element, s.ClassDef)
                else f"the component '{element.name}'" if isinstance(element, s.Component)
                else "an extends clause")
        raise rule_error(f"the operator '{defn.name}' holds {what}", element.span,
                         "an operator may hold only declarations of functions", "4.6")


def _check_operator_functions(ctx: ClassViews, record: ClassEntry, op: ClassEntry) -> None:
    """The functions of the operator ``op`` of the operator record ``record``: one output
    each, of the record for a constructor and a String for 'String', two inputs or more
    for a binary operator, no two constructors taking the same inputs (section 14)."""
    functions = [op] if op.defn.kind == "function" else [
        e for e in op.classes.values() if e.defn.kind == "function"]
    signatures: dict[tuple[str, ...], s.ClassDef] = {}
    for function in functions:
        defn = function.defn
        inputs = [e for e in defn.elements if isinstance(e, s.Component)
                  and e.causality == "input"]
        outputs = [e for e in defn.elements if isinstance(e, s.Component)
                   and e.causality == "output"]
        if len(outputs) != 1:
            raise rule_error(f"the function '{defn.name}' of the operator '{op.name}' has "
                             f"{len(outputs)} outputs", defn.span, "every function of an "
                             "operator returns exactly one output", "14.1")
        if op.name in _BINARY and len(inputs) < 2:
            raise rule_error(f"the function '{defn.name}' of the binary operator "
                             f"'{op.name}' has {len(inputs)} input", defn.span, "a binary "
                             "operator's function takes at least two inputs", "14.5")
        if op.name in ("constructor", "String"):
            _check_output_type(ctx, record, op, function, outputs[0])
        if op.name == "constructor":
            key = tuple(f"{c.type_name.dotted}{len(c.dims) + len(c.type_dims)}"
                        for c in inputs if c.modification is None
                        or c.modification.value is None)
            if key in signatures:
                raise rule_error(f"the constructors '{signatures[key].name}' and "
                                 f"'{defn.name}' take the same inputs", defn.span,
                                 "no call of an operator record's constructor may match "
                                 "two of its functions", "14.3",
                                 (Note("the other constructor", signatures[key].span),))
            signatures[key] = defn


def _check_output_type(ctx: ClassViews, record: ClassEntry, op: ClassEntry,
                       function: ClassEntry, output: s.Component) -> None:
    try:
        found = ctx.resolve_type(output.type_name, function)
    except FlattenError:
        return
    if op.name == "String":
        if found.primitive != "String":
            raise rule_error(f"the output '{output.name}' of the operator 'String' is "
                             f"of type {output.type_name.dotted}", output.type_name.span,
                             "an overloaded String conversion returns a String", "14.4")
    elif found.entry is not record:
        raise rule_error(f"the output '{output.name}' of the constructor "
                         f"'{function.name}' is of type {output.type_name.dotted}",
                         output.type_name.span, "a constructor of an operator record "
                         f"returns the operator record ('{record.name}')", "14.3")


def _check_streams(ctx: ClassViews, entry: ClassEntry) -> None:
    defn = entry.defn
    streams = [e for e in defn.elements if isinstance(e, s.Component) and e.stream]
    if not streams:
        return
    if defn.kind != "connector":
        raise rule_error(f"the stream variable '{streams[0].name}' is declared in a "
                         f"{defn.kind}", streams[0].span, "the prefix stream may be used "
                         "only in a connector", "4.4.2.2")
    for comp in streams:
        _check_stream_type(ctx, entry, comp)
    flows = [e for e in defn.elements if isinstance(e, s.Component) and e.flow]
    if any(isinstance(e, s.Extends) for e in defn.elements):
        return  # inherited flow variables: not counted here
    scalar = len(flows) == 1 and not flows[0].dims and not flows[0].type_dims
    if not scalar:
        raise rule_error(f"the stream connector '{defn.name}' has {len(flows)} flow "
                         f"declarations{'' if len(flows) != 1 else ' (an array)'}",
                         streams[0].span, "a connector with stream variables has exactly "
                         "one scalar flow variable", "15.1")
    _check_balance(defn, flows)


def _check_balance(defn: s.ClassDef, flows: list[s.Component]) -> None:
    """A stream connector of scalar variables of predefined types: as many flow
    variables as variables that are neither parameter, constant, input, output, stream
    nor flow (section 9.3.1)."""
    comps = [e for e in defn.elements if isinstance(e, s.Component)]
    if any(c.dims or c.type_dims or c.type_name.dotted not in ("Real", "Integer", "Boolean")
           for c in comps):
        return  # records, arrays, derived types: not counted here
    potentials = [c for c in comps if not (c.flow or c.stream or c.causality)
                  and c.variability not in ("parameter", "constant")]
    if len(potentials) != len(flows):
        raise rule_error(f"the connector '{defn.name}' has {len(flows)} flow and "
                         f"{len(potentials)} potential variables", defn.span,
                         "a connector has as many flow variables as variables that are "
                         "neither parameter, constant, input, output, stream nor flow",
                         "9.3.1")


def _check_stream_type(ctx: ClassViews, entry: ClassEntry, comp: s.Component) -> None:
    try:
        found = ctx.resolve_type(comp.type_name, entry)
    except FlattenError:
        return
    rule = "a stream variable is a subtype of Real, or a record of such"
    if found.primitive is not None:
        if found.primitive != "Real" or found.enumeration is not None:
            raise rule_error(f"the stream variable '{comp.name}' is of type "
                             f"{comp.type_name.dotted}, not Real", comp.type_name.span,
                             rule, "15.1")
        return
    kind = found.entry.defn.kind if found.entry is not None else ""
    if kind not in ("record", "type"):
        raise rule_error(f"the stream variable '{comp.name}' is a {kind}",
                         comp.type_name.span, rule, "4.4.2.2")
    assert found.entry is not None
    inner = [e for e in found.entry.defn.elements if isinstance(e, s.Component)
             and (e.flow or e.stream)]
    if inner:
        raise rule_error(f"the stream variable '{comp.name}' has the "
                         f"{'flow' if inner[0].flow else 'stream'} element "
                         f"'{inner[0].name}'", comp.type_name.span, rule, "4.4.2.2")


#: The operators of stream variables (sections 15.2 and 15.3).
STREAM_OPERATORS = {"inStream": "15.2", "actualStream": "15.3"}


def check_stream_argument(ev: ExpressionEvaluator, e: s.Call, scope: Scope) -> None:
    """``inStream(v)`` or ``actualStream(v)`` met while flattening: no class springc
    flattens declares a stream variable (one that does is refused first), so a ``v``
    naming a component is not a stream variable."""
    name = e.func.dotted
    if len(e.args) != 1 or e.named or not isinstance(e.args[0], s.Ref):
        return
    try:
        ev.reference(e.args[0], scope)
    except FlattenError:
        return
    raise rule_error(f"the argument of {name} must be a stream variable, and "
                     f"'{e.args[0].dotted}' is not one", e.args[0].span,
                     f"{name}(v) is defined for a stream variable v of a connector",
                     STREAM_OPERATORS[name])
