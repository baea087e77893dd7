"""Static rules of the Modelica 3.6 specification that make a class invalid, checked
once per class when its view (inheritance resolved) is built.

Input: a :class:`ClassView` and the flattening context (for type lookup). Output:
nothing, or a :class:`FlattenError` at the offending element whose help names the rule
in plain words and the section of the specification. The rules: the kinds of base
classes (section 7.1.3), the contents of specialized classes (records, connectors,
blocks, functions: sections 4.6 and 12.2), type prefixes (section 4.4.2.2), reserved
and doubly declared names (sections 4.8 and 4.2).
"""

from __future__ import annotations

from collections.abc import Iterator

from ...errors import FlattenError, Note, Span
from ...ir import syntax as s
from ...parse import ClassEntry
from ..natives import is_external_object
from ..scopes import (
    PRIMITIVES,
    ClassView,
    ClassViews,
    ResolvedType,
    ViewComponent,
    inherited_class,
    mod_values,
    refs,
    same_text,
    statement_exprs,
    statements,
)

#: The kinds of base class each kind of class may extend (section 7.1.3's table).
BASE_KINDS: dict[str, frozenset[str]] = {
    "package": frozenset({"package", "class"}),
    "function": frozenset({"function", "class"}),
    "type": frozenset({"type", "class"}),
    "record": frozenset({"record", "class"}),
    "connector": frozenset({"type", "record", "connector", "class"}),
    "block": frozenset({"record", "block", "class"}),
    "model": frozenset({"record", "block", "model", "class"}),
    # the table allows only class, but the conformance suite holds `class C extends M`
    # (a model M) valid (Classes.Declarations.Long.ClassSections): class extends anything
    "class": frozenset({"package", "function", "type", "record", "connector", "block",
                        "model", "class"}),
}

#: Names with the restrictions of keywords (section 4.8).
RESERVED = frozenset({"Real", "Integer", "Boolean", "String"})


def rule_error(message: str, span: Span | None, rule: str, section: str,
               notes: tuple[Note, ...] = ()) -> FlattenError:
    """An error whose help states ``rule`` and the section of the specification."""
    return FlattenError(message, span, notes, f"{rule} (Modelica 3.6, section {section})")


def _plural(kind: str) -> str:
    return {"class": "classes"}.get(kind, kind + "s")


def _kinds(kinds: frozenset[str]) -> str:
    """``records, blocks or classes``."""
    order = [_plural(k) for k in BASE_KINDS if k in kinds]
    return ", ".join(order[:-1]) + f" or {order[-1]}" if len(order) > 1 else order[0]


def check_class(ctx: ClassViews, view: ClassView) -> None:
    """Every rule of this module for the class of ``view``."""
    entry = view.entry
    defn = entry.defn
    if defn.name in RESERVED:
        raise rule_error(f"'{defn.name}' is a predefined type and cannot be the name of a "
                         "class", defn.span, "Real, Integer, Boolean and String are "
                         "reserved names, like keywords", "4.8")
    _check_names(defn)
    if defn.kind in ("record", "connector"):
        _check_public_only(view)
    if defn.kind == "package":
        _check_package(view)
    for comp in view.components.values():
        if comp.defined_in is entry:
            _check_component(ctx, entry, comp)
    if defn.kind == "block":
        _check_block(ctx, view)
    elif defn.kind == "function":
        _check_function(ctx, view)
    if defn.kind in ("function", "record", "connector"):
        _check_no_time(view)


def _check_names(defn: s.ClassDef) -> None:
    classes = {e.name: e for e in defn.elements if isinstance(e, s.ClassDef)}
    for element in defn.elements:
        if isinstance(element, s.Component):
            if element.name in RESERVED:
                raise rule_error(f"'{element.name}' is a predefined type and cannot be the "
                                 "name of a component", element.span, "Real, Integer, "
                                 "Boolean and String are reserved names, like keywords", "4.8")
            if element.type_name.parts[0].name == element.name and \
                    not element.type_name.is_global:
                raise rule_error(f"the component '{element.name}' has the name of its type "
                                 f"'{element.type_name.dotted}'", element.span,
                                 "a component hides the class of the same name from the "
                                 "lookup of its own type; rename one of them", "5.3.2")
            if element.name in classes:
                raise rule_error(f"'{element.name}' is declared twice, as a component and as "
                                 "a class", element.span,
                                 "the elements of a class must have different names", "4.2",
                                 (Note("the class is defined here",
                                       classes[element.name].span),))


def check_extends(ctx: ClassViews, entry: ClassEntry) -> None:
    """The extends clauses of ``entry``, before its inheritance is resolved: the kind of
    each base class (7.1.3), and no other element beside a base class that is an array
    class, has type prefixes or is a simple type (4.5.2)."""
    kind = entry.defn.kind
    allowed = BASE_KINDS.get(kind)
    clauses = [e for e in entry.defn.elements if isinstance(e, s.Extends)
               and e.base.dotted != "ExternalObject"  # predefined (section 12.9.7)
               and not (kind == "type" and e.base.dotted in RESERVED)]  # extends Real
    for element in clauses:
        inherited = entry.defn.class_extends and element is entry.defn.elements[0]
        base = inherited_class(ctx.resolve_class, entry, element.span) if inherited \
            else ctx.resolve_class(element.base, entry.parent or entry, entry)
        if base.defn.replaceable and not inherited:
            raise rule_error(f"'{entry.name}' extends the replaceable class "
                             f"'{element.base.dotted}'", element.base.span,
                             "a base class is not replaceable (a redeclaration could "
                             "change what is inherited)", "7.1.4",
                             (Note("declared replaceable here", base.defn.span),))
        special = ""
        while base.defn.short is not None:
            short = base.defn.short
            special = special or ("an array class" if short.dims else "a class with type "
                                  "prefixes" if short.variability or short.causality or
                                  short.flow else "")
            if short.base.dotted in PRIMITIVES:
                special = special or "a simple type"
                break
            try:
                base = ctx.resolve_class(short.base, base.parent or base)
            except FlattenError:
                return
        _check_inherited_classes(entry, base)
        if not inherited:
            check_operator_base(element, base)
        base_kind = base.defn.kind
        if allowed is not None and base_kind not in allowed:
            raise rule_error(
                f"a {kind} cannot extend a {base_kind}: '{element.base.dotted}' is a "
                f"{base_kind}", element.base.span,
                f"{_plural(kind)} may extend only {_kinds(allowed)}", "7.1.3",
                (Note(f"'{base.full_name}' is defined here", base.defn.span),))
        others = [e for e in entry.defn.elements
                  if isinstance(e, s.Component) or (isinstance(e, s.Extends) and e is not element)]
        defn = entry.defn
        if special and (others or defn.equations or defn.initial_equations or defn.algorithm):
            raise rule_error(
                f"'{entry.name}' extends '{element.base.dotted}', {special}, and cannot have "
                "other components, equations or base classes", element.span,
                "a class extending an array class, a class with type prefixes or a simple "
                "type holds nothing else", "4.5.2")


def check_operator_base(element: s.Extends, base: ClassEntry) -> None:
    """A long ``extends`` may name neither an operator record nor a class enclosing one
    (section 4.6; a short class definition ``operator record R2 = R(...)`` may)."""
    if base.defn.operator and base.defn.kind == "record":
        raise rule_error(f"extending the operator record '{element.base.dotted}'",
                         element.base.span, "an operator record can be extended only by a "
                         "short class definition modifying its components", "4.6",
                         (Note(f"'{base.full_name}' is defined here", base.defn.span),))
    inner = next(_operator_records(base.defn), None)
    if inner is not None:
        raise rule_error(f"extending '{element.base.dotted}', which encloses the operator "
                         f"record '{inner.name}'", element.base.span, "no class may extend "
                         "a class enclosing an operator record", "4.6",
                         (Note("the operator record is defined here", inner.span),))


def _operator_records(defn: s.ClassDef) -> Iterator[s.ClassDef]:
    for element in defn.elements:
        if isinstance(element, s.ClassDef):
            if element.operator and element.kind == "record":
                yield element
            yield from _operator_records(element)


def _check_inherited_classes(entry: ClassEntry, base: ClassEntry) -> None:
    """A class inherited under the name of a local class must be the same class (unless
    the local one redeclares it, section 7.3)."""
    local = {e.name: e for e in entry.defn.elements
             if isinstance(e, s.ClassDef) and not e.redeclare and not e.class_extends}
    for element in base.defn.elements:
        if isinstance(element, s.ClassDef) and element.name in local and \
                not same_text(element, local[element.name]):
            raise rule_error(f"class '{element.name}' is inherited from '{base.full_name}' "
                             "and declared here differently", local[element.name].span,
                             "an inherited element may have the name of a local one only "
                             "if both are identical", "7.1",
                             (Note("the inherited class is defined here", element.span),))


def _check_public_only(view: ClassView) -> None:
    defn = view.entry.defn
    kind = defn.kind
    rule = (f"a {kind} may have only public elements: no equation, algorithm or "
            "protected section")
    sections = [*view.equations, *view.initial_equations]
    if sections:
        raise rule_error(f"a {kind} cannot have equations", sections[0].equation.span,
                         rule, "4.6")
    if defn.algorithm:
        raise rule_error(f"a {kind} cannot have an algorithm section",
                         defn.algorithm[0].span, rule, "4.6")
    for element in defn.elements:
        if isinstance(element, s.Component | s.ClassDef) and element.protected:
            raise rule_error(f"a {kind} cannot have protected elements", element.span,
                             rule, "4.6")
    for comp in view.components.values():
        if comp.decl.protected:
            raise rule_error(f"a {kind} cannot have protected elements", comp.decl.span,
                             rule, "4.6")


def _check_package(view: ClassView) -> None:
    """A package holds only classes and constants."""
    for comp in view.components.values():
        if comp.decl.variability != "constant":
            what = f"a {comp.decl.variability}" if comp.decl.variability else "a variable"
            raise rule_error(f"a package cannot have {what}: '{comp.decl.name}'",
                             comp.decl.span, "a package may contain only classes and "
                             "constants", "4.6")
    sections = [*view.equations, *view.initial_equations]
    if sections:
        raise rule_error("a package cannot have equations", sections[0].equation.span,
                         "a package may contain only classes and constants", "4.6")


def _resolved(ctx: ClassViews, comp: ViewComponent) -> ResolvedType | None:
    """The type of ``comp``, or None where it cannot be resolved (reported later,
    where the component is instantiated)."""
    try:
        return ctx.resolve_type(comp.decl.type_name, comp.defined_in)
    except FlattenError:
        return None


def _check_component(ctx: ClassViews, entry: ClassEntry, comp: ViewComponent) -> None:
    decl = comp.decl
    if entry.defn.kind in ("record", "connector") and (decl.inner or decl.outer):
        kind = entry.defn.kind
        raise rule_error(f"a {kind} component cannot be declared "
                         f"`{'inner' if decl.inner else 'outer'}`", decl.span,
                         f"the elements of a {kind} cannot have the prefixes inner or "
                         "outer", "4.6")
    rtype = _resolved(ctx, comp)
    if rtype is None:
        return
    variability = decl.variability or rtype.prefixes[0]
    causality = decl.causality or rtype.prefixes[1]
    flow = decl.flow or rtype.prefixes[2]
    kind = entry.defn.kind
    if kind == "record" and (causality or flow):
        prefix = causality or "flow"
        raise rule_error(f"a record component cannot be declared `{prefix}`", decl.span,
                         "the elements of a record cannot have the prefixes input, "
                         "output or flow", "4.6")
    if causality == "input" and variability in ("parameter", "constant"):
        raise rule_error(f"'{decl.name}' cannot be both `input` and `{variability}`",
                         decl.span, "an input cannot also be a parameter or a constant",
                         "4.4.2.2")
    if rtype.primitive is not None:
        if rtype.primitive == "Real" and variability == "discrete" and kind != "function" \
                and decl.modification is not None and decl.modification.value is not None:
            raise rule_error(f"the discrete Real '{decl.name}' cannot have a binding "
                             "equation", decl.modification.value.span,
                             "a Real declared discrete is assigned only in when-clauses; "
                             "give its initial value with `start` instead", "4.4.4")
        if flow and rtype.primitive != "Real":
            raise rule_error(f"'{decl.name}' is a flow variable of type {rtype.primitive}",
                             decl.span, "flow variables must be of type Real (or a type "
                             "derived from Real)", "4.4.2.2")
        return
    assert rtype.entry is not None
    type_kind = rtype.entry.defn.kind
    if kind in ("record", "connector"):
        allowed = ("record", "type") if kind == "record" else ("record", "type", "connector")
        if type_kind not in allowed:
            raise rule_error(
                f"a {kind} cannot have a component of the {type_kind} "
                f"'{rtype.entry.full_name}'", decl.span,
                f"the components of a {kind} may only be of "
                + ("a record or type" if kind == "record" else "a connector, record or type"),
                "4.6")
    prefixes = [p for p in (variability, causality, "flow" if flow else "") if p]
    external = type_kind == "class" and is_external_object(rtype.entry)
    if prefixes and type_kind not in ("record", "type", "connector") and not (
            type_kind == "function" and causality == "input" and not variability) and not (
            external and not flow):  # parameters, constants, inputs (section 12.9.7)
        raise rule_error(
            f"the prefix `{prefixes[0]}` cannot be applied to '{decl.name}', a component "
            f"of the {type_kind} '{rtype.entry.full_name}'", decl.span,
            "type prefixes (flow, discrete, parameter, constant, input, output) apply "
            "only to components of a type, record or connector", "4.4.2.2")
    if (causality or flow) and type_kind != "function":  # a functional input (12.4.2)
        prefix = causality or "flow"
        if flow and rtype.entry.defn.unsupported:  # not viewed: stream elements, ...
            _check_flow_over_stream(decl, rtype.entry.defn)
        for inner, inner_decl in _elements(ctx, rtype.entry):
            # flow over an input/output element is accepted (the conformance suite
            # holds it valid: Components.Prefixes.FlowValidClassType)
            if inner_decl.flow or (inner_decl.causality and causality):
                raise _prefix_clash(decl, prefix, inner, inner_decl.causality or "flow",
                                    inner_decl.span)
    if variability in ("parameter", "constant") and type_kind == "connector":
        raise rule_error(f"the connector '{decl.name}' cannot be declared `{variability}`",
                         decl.span, "a connector component cannot be a parameter or a "
                         "constant", "9.3")
    if variability in ("parameter", "constant"):
        for inner, inner_decl in _elements(ctx, rtype.entry):
            if inner_decl.causality == "input":
                raise rule_error(
                    f"'{decl.name}' is declared `{variability}`, but its element '{inner}' "
                    "is an input", decl.span, "an input cannot also be a parameter or a "
                    "constant (the prefix of a structured component applies to its "
                    "elements)", "4.4.2.2", (Note(f"'{inner}' is declared here",
                                                  inner_decl.span),))


def _check_flow_over_stream(decl: s.Component, defn: s.ClassDef) -> None:
    """``flow C c`` with a class C outside the subset (not viewed): its own elements
    declared flow or stream (section 4.4.2.2)."""
    for inner in defn.elements:
        if isinstance(inner, s.Component) and (inner.flow or inner.stream):
            raise _prefix_clash(decl, "flow", inner.name,
                                "flow" if inner.flow else "stream", inner.span)


def _prefix_clash(decl: s.Component, prefix: str, inner: str, inner_prefix: str,
                  inner_span: Span | None) -> FlattenError:
    """The error of ``prefix`` on ``decl`` whose element ``inner`` has ``inner_prefix``
    (section 4.4.2.2)."""
    return rule_error(
        f"'{decl.name}' is declared `{prefix}`, but its element '{inner}' is already "
        f"`{inner_prefix}`", decl.span,
        "flow, input and output on a structured component apply to its elements, which "
        "then may not have any of these prefixes", "4.4.2.2",
        (Note(f"'{inner}' is declared here", inner_span),))


def _elements(ctx: ClassViews, entry: ClassEntry, prefix: str = "",
              depth: int = 0) -> Iterator[tuple[str, s.Component]]:
    """The components of ``entry`` and of its structured components, by relative name
    (short-definition prefixes folded into each declaration's own)."""
    if depth > 20:
        return
    for name, comp in ctx.view(entry).components.items():
        rtype = _resolved(ctx, comp)
        decl = comp.decl
        if rtype is not None and any(rtype.prefixes):
            decl = s.Component(
                decl.name, decl.type_name, decl.type_dims, decl.dims, decl.modification,
                decl.variability or rtype.prefixes[0], decl.causality or rtype.prefixes[1],
                decl.flow or rtype.prefixes[2], decl.final, decl.protected,
                decl.description, decl.span)
        yield prefix + name, decl
        if rtype is not None and rtype.entry is not None and \
                rtype.entry.defn.kind in ("record", "connector"):
            yield from _elements(ctx, rtype.entry, f"{prefix}{name}.", depth + 1)


def _check_block(ctx: ClassViews, view: ClassView) -> None:
    """Each public connector component of a block has input or output on all its
    variables."""
    for comp in view.components.values():
        decl = comp.decl
        rtype = _resolved(ctx, comp)
        if decl.protected or rtype is None or rtype.entry is None or \
                rtype.entry.defn.kind != "connector" or decl.causality or rtype.prefixes[1]:
            continue
        for inner, inner_decl in _elements(ctx, rtype.entry):
            if not inner_decl.causality and inner_decl.variability not in (
                    "parameter", "constant") and _is_variable(ctx, inner_decl, rtype.entry):
                raise rule_error(
                    f"'{decl.name}' is a connector of a block, but its variable '{inner}' is "
                    "neither input nor output", decl.span,
                    "every variable of a public connector of a block must be an input or "
                    "an output", "4.6", (Note(f"'{inner}' is declared here",
                                              inner_decl.span),))


def _is_variable(ctx: ClassViews, decl: s.Component, entry: ClassEntry) -> bool:
    """Whether ``decl`` (of a connector) is a primitive variable, not a structure."""
    comp = ViewComponent(decl, entry)
    rtype = _resolved(ctx, comp)
    return rtype is not None and rtype.primitive is not None


def _check_function(ctx: ClassViews, view: ClassView) -> None:
    """Public elements of a function are inputs or outputs; inputs are not assigned."""
    inputs = set()
    for comp in view.components.values():
        decl = comp.decl
        rtype = _resolved(ctx, comp)
        causality = decl.causality or (rtype.prefixes[1] if rtype is not None else "")
        if causality == "input":
            inputs.add(decl.name)
        elif not decl.protected and not causality:
            raise rule_error(f"'{decl.name}' is a public element of a function but neither "
                             "input nor output", decl.span, "the public components of a "
                             "function must be inputs or outputs; declare the others "
                             "protected", "12.2")
    for stmt in statements(view.entry.defn.algorithm):
        if isinstance(stmt, s.Assign):
            for target in stmt.targets:
                if target is not None and target.parts[0].name in inputs:
                    raise rule_error(f"the input '{target.parts[0].name}' of a function "
                                     "cannot be assigned", target.span,
                                     "the inputs of a function are read-only", "12.2")


def _check_no_time(view: ClassView) -> None:
    """``time`` is available in models and blocks only."""
    kind = view.entry.defn.kind
    local = set(view.components)
    exprs: list[s.Expr] = []
    for comp in view.components.values():
        if comp.defined_in is view.entry:
            exprs += mod_values(comp.decl.modification)
    for stmt in statements(view.entry.defn.algorithm):
        exprs += statement_exprs(stmt)
    for e in exprs:
        for ref in refs(e):
            if ref.parts[0].name == "time" and "time" not in local:
                raise rule_error(f"`time` cannot be used in a {kind}", ref.span,
                                 "the built-in variable time is available only in models "
                                 "and blocks", "3.6.7")
