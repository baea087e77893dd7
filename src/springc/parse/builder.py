"""lark parse tree -> syntax nodes: the second half of :mod:`springc.parse`.

:class:`SyntaxBuilder` has one method per grammar rule (``grammar/modelica.lark``); each
gets the rule's positions and its converted children and returns a :mod:`springc.syntax`
node with its span. Constructs of LANGUAGE.md's "Later" list are turned into located
``... not supported yet`` errors; all errors are collected and raised together.

The rule methods live in one module per group of rules, combined here:

- :mod:`springc.build_classes`: the stored definition, class definitions and sections;
- :mod:`springc.build_elements`: declarations, imports, extends, modifications;
- :mod:`springc.build_equations`: equations and statements;
- :mod:`springc.build_expressions`: expressions and operator precedence;
- :mod:`springc.build_base`: the helpers and intermediate results they share.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lark import Token, Tree

from ..errors import ErrorGroup, ParseError
from ..ir.syntax import End
from .rules_base import KEYWORDS, LATER
from .rules_classes import ClassRules
from .rules_elements import ElementRules
from .rules_equations import EquationRules
from .rules_expressions import ExpressionRules

__all__ = ["KEYWORDS", "LATER", "SyntaxBuilder", "build"]


def build(tree: Tree[Token], file: str) -> Any:
    """The syntax node of ``tree`` (a StoredDefinition, or an Expr for an expression);
    raises :class:`ParseError`, or :class:`ErrorGroup` if there are several errors."""
    builder = SyntaxBuilder(file)
    result = builder.convert(tree)
    if builder.errors:
        errors = sorted(builder.errors,
                        key=lambda e: (e.span.line, e.span.column) if e.span else (0, 0))
        raise errors[0] if len(errors) == 1 else ErrorGroup(errors)
    return result


class SyntaxBuilder(ClassRules, ElementRules, EquationRules, ExpressionRules):
    """Maps each grammar rule to a syntax node; collects errors instead of stopping.

    The method named after a rule receives the rule's ``meta`` (positions) and its
    already converted children. (A hand-written walk: lark's ``Transformer`` with
    ``v_args(meta=True)`` costs about three times as much per node.)
    """

    def __init__(self, file: str) -> None:
        self.file = file
        self.errors: list[ParseError] = []
        self._methods: dict[str, Callable[[Any, list[Any]], Any]] = {}
        self.loose_ends: list[End] = []  # `end`s not yet known to sit in a subscript

    def convert(self, tree: Tree[Token]) -> Any:
        """The syntax node for the whole ``tree``; problems are left in ``errors``."""
        result = self.transform(tree)
        for end in self.loose_ends:
            self.error("`end` may only be used inside array subscripts such as x[end]",
                        end.span)
        return result

    def transform(self, tree: Tree[Token]) -> Any:
        children = [self.transform(c) if type(c) is Tree else c for c in tree.children]
        method = self._methods.get(tree.data)
        if method is None:  # every rule has a method: a missing one is a bug, not a skip
            method = self._methods[tree.data] = getattr(self, tree.data)
        return method(tree.meta, children)
