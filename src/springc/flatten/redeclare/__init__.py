"""Modifications applied and redeclarations: conditional components, inner/outer and
redeclared elements (``declarations``), classes replaced per instance
(``instance_classes``), records as values, constraining types and the subtype relation
(``redeclare_rules``, ``subtyping``)."""

from __future__ import annotations

from .declarations import (
    condition_holds,
    disabled,
    inner_member,
    redeclared,
    redeclared_class,
    redeclared_class_mod,
)
from .instance_classes import (
    class_in_instance,
    class_modification,
    inner_class,
    instance_scope,
    named_through,
    redeclared_package,
    type_name_package,
)
from .records import constructor_fields, record_equation, record_mod
from .redeclare_rules import check_redeclarations, check_replaceables

__all__ = [
    "check_redeclarations",
    "check_replaceables",
    "class_in_instance",
    "class_modification",
    "condition_holds",
    "constructor_fields",
    "disabled",
    "inner_class",
    "inner_member",
    "instance_scope",
    "named_through",
    "record_equation",
    "record_mod",
    "redeclared",
    "redeclared_class",
    "redeclared_class_mod",
    "redeclared_package",
    "type_name_package",
]
