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

from ...errors import FlattenError
from ...ir import syntax as s
from ...parse import ClassEntry
from ..scopes import ClassViews
from .rules import check_operator_base, rule_error

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
