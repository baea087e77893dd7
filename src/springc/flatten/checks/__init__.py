"""Static rules of the specification, each error naming its section: classes and prefixes
(``rules``), protected and composite lookup (``access``), types and variabilities
(``type_rules``), conditional components, ``outer`` uses, enumeration literals."""

from __future__ import annotations

from .access import (
    check_access_class,
    check_access_component,
    check_access_path,
    check_inside,
    check_modified,
)
from .conditional_rules import check_conditional_uses
from .enum_rules import check_enum_binding, check_enum_relation
from .outer_rules import check_outer_uses
from .rules import check_class, check_extends, rule_error
from .type_rules import (
    check_boolean_condition,
    check_constant_binding,
    check_der_argument,
    check_discrete_binding,
    check_integer_binding,
    check_numeric_arguments,
    declared,
    stronger,
)
from .unsupported_rules import check_stream_argument, check_unsupported_class

__all__ = [
    "check_access_class", "check_access_component", "check_access_path",
    "check_boolean_condition", "check_class", "check_conditional_uses",
    "check_constant_binding", "check_der_argument", "check_discrete_binding",
    "check_enum_binding", "check_enum_relation", "check_extends", "check_inside",
    "check_integer_binding", "check_modified", "check_numeric_arguments", "check_outer_uses",
    "check_stream_argument", "check_unsupported_class",
    "declared", "rule_error", "stronger",
]
