"""Instances while flattening: scopes, members and primitive variables, the
``FlattenContext`` and ``ExpressionEvaluator`` Protocols, and the values they hold
(modifications, enumerations, parameter values, event uses, size limits). The base every
other subpackage of :mod:`springc.flatten` stands on; it imports none of them."""

from __future__ import annotations

from .class_extends import check_class_redeclarations, inherited_class
from .enumerations import (
    BOOLEAN,
    BUILTIN_ENUMERATIONS,
    BuiltinEnumeration,
    DimensionKind,
    Enumeration,
    EnumLiteral,
    enumeration_of,
    kind_name,
    literal_value,
    literal_values,
    value_kind,
)
from .event_uses import EventUses
from .identity import Ident
from .limits import DEFAULT_MAX_SIZE, Limits, max_size_setting
from .modification import Mod, ModValue, Redeclaration, each, from_syntax, merge, merge_all, select
from .parameters import ParameterValues, binding_errors, check_powers
from .scope import (
    PRIMITIVES,
    REDECLARE_RULES,
    ClassScope,
    ClassView,
    Declared,
    Disabled,
    DisabledReference,
    ExpressionEvaluator,
    FlattenContext,
    FunctionScope,
    Handler,
    Leaf,
    LocalScope,
    Member,
    ObjectMember,
    Primitive,
    ResolvedType,
    Scope,
    ViewComponent,
    build_view,
    check_redeclarable,
    instance_mod,
)
from .syntax_walk import equations, mod_values, refs, same_text, statement_exprs, statements
from .variables import attributes_of, check_attribute_mods

__all__ = [
    "BOOLEAN",
    "BUILTIN_ENUMERATIONS",
    "DEFAULT_MAX_SIZE",
    "PRIMITIVES",
    "REDECLARE_RULES",
    "BuiltinEnumeration",
    "ClassScope",
    "ClassView",
    "Declared",
    "DimensionKind",
    "Disabled",
    "DisabledReference",
    "EnumLiteral",
    "Enumeration",
    "EventUses",
    "ExpressionEvaluator",
    "FlattenContext",
    "FunctionScope",
    "Handler",
    "Ident",
    "Leaf",
    "Limits",
    "LocalScope",
    "Member",
    "Mod",
    "ModValue",
    "ObjectMember",
    "ParameterValues",
    "Primitive",
    "Redeclaration",
    "ResolvedType",
    "Scope",
    "ViewComponent",
    "attributes_of",
    "binding_errors",
    "build_view",
    "check_attribute_mods",
    "check_class_redeclarations",
    "check_powers",
    "check_redeclarable",
    "each",
    "enumeration_of",
    "equations",
    "from_syntax",
    "inherited_class",
    "instance_mod",
    "kind_name",
    "literal_value",
    "literal_values",
    "max_size_setting",
    "merge",
    "merge_all",
    "mod_values",
    "refs",
    "same_text",
    "select",
    "statement_exprs",
    "statements",
    "value_kind",
]
