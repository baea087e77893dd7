"""lark parse tree -> syntax nodes: the second half of :mod:`springc.parse`.

:class:`SyntaxBuilder` has one method per grammar rule (``grammar/modelica.lark``); each
gets the rule's positions and its converted children and returns a :mod:`springc.syntax`
node with its span. Constructs of docs/language.md's "Not supported yet" list are turned
into located ``... not supported yet`` errors; all errors are collected and raised
together. Before that, :func:`check_depth` bounds the nesting (docs/language.md, "Limits").

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

from ..errors import ErrorGroup, ParseError, Span
from ..ir import expr
from ..ir.syntax import End
from .rules_base import KEYWORDS, LATER
from .rules_classes import ClassRules
from .rules_elements import ElementRules
from .rules_equations import EquationRules
from .rules_expressions import ExpressionRules

__all__ = ["KEYWORDS", "LATER", "SyntaxBuilder", "build", "check_depth"]


def build(tree: Tree[Token], file: str, defer: bool = False) -> Any:
    """The syntax node of ``tree`` (a StoredDefinition, or an Expr for an expression);
    raises :class:`ParseError`, or :class:`ErrorGroup` if there are several errors.
    With ``defer``, a construct outside the subset inside a class is no error here: the
    class keeps it (``ClassDef.unsupported``) for flatten to report if a model uses it."""
    check_depth(tree, file)
    builder = SyntaxBuilder(file, defer)
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

    def __init__(self, file: str, defer: bool = False) -> None:
        self.file = file
        self.errors: list[ParseError] = []
        self.defer = defer
        self.deferred: list[ParseError] = []
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
        """Convert bottom-up without recursion (a file's nesting is bounded only by
        :func:`check_depth`, not by Python's stack)."""
        methods = self._methods
        # Each frame: a rule node, the iterator over its children, the converted ones.
        frames: list[tuple[Tree[Token], Any, list[Any]]] = [(tree, iter(tree.children), [])]
        while True:
            node, pending, done = frames[-1]
            for child in pending:
                if type(child) is Tree:
                    frames.append((child, iter(child.children), []))
                    break
                done.append(child)
            else:
                frames.pop()
                method = methods.get(node.data)
                if method is None:  # every rule has a method: a missing one is a bug
                    method = methods[node.data] = getattr(self, node.data)
                value = method(node.meta, done)
                if not frames:
                    return value
                frames[-1][2].append(value)


# ------------------------------------------------------------------ nesting depth

# Rules that add a level to the expression tree springc builds; an ``operation``
# adds one level per operator in it (``a + b + c`` is ``(a + b) + c``), which bounds
# the depth of the tree that precedence climbing makes of it.
_EXPRESSION_RULES = frozenset({
    "operation", "call", "array", "matrix", "array_comprehension", "if_expression",
    "range", "subscripted", "tuple", "call_comprehension",
})
# Rules between two expression levels that add none themselves.
_TRANSPARENT = frozenset({
    "function_call_args", "named_argument", "component_reference", "global_reference",
    "ref_part", "array_subscripts", "matrix_row", "for_indices", "for_index",
    "output_item",
})


def check_depth(tree: Tree[Token], file: str) -> None:
    """Raise a located :class:`ParseError` if an expression of ``tree`` nests deeper
    than :data:`springc.ir.expr.MAX_DEPTH` levels, or the classes, equations and
    modifications around it nest deeper than that many parse-tree levels.

    Iterative, so that the check itself cannot overflow; every later stage may then
    recurse over expressions (see :func:`springc.ir.expr.recursion_room`)."""
    limit = expr.MAX_DEPTH
    deepest, deepest_root = 0, tree
    # (node, depth of the structure around expressions, depth inside the outermost
    # expression, that outermost expression node or None)
    stack: list[tuple[Tree[Token], int, int, Tree[Token] | None]] = [(tree, 1, 0, None)]
    while stack:
        node, outer, inner, root = stack.pop()
        if node.data in _EXPRESSION_RULES:
            inner += (sum(type(c) is Token for c in node.children)
                      if node.data == "operation" else 1)
            if root is None:
                root = node
            if inner > deepest:
                deepest, deepest_root = inner, root
        elif root is None and node.data not in _TRANSPARENT:
            outer += 1
            if outer > limit:
                raise _too_deep("definitions and equations", outer, node, file)
        for child in node.children:
            if type(child) is Tree:
                stack.append((child, outer, inner, root))
    if deepest > limit:
        raise _too_deep("expression", deepest, deepest_root, file)


def _too_deep(what: str, depth: int, node: Tree[Token], file: str) -> ParseError:
    meta = node.meta
    span = Span(file, meta.line, meta.column, meta.end_line, meta.end_column)
    split = ("split it with intermediate variables (`Real s1 = a1 + a2 + ...;`)"
             if what == "expression" else "nest classes, equations and modifications less")
    return ParseError(
        f"{what} nested too deeply (depth {depth}, limit {expr.MAX_DEPTH})", span,
        hint=f"{split}; docs/language.md, \"Limits\", says how depth is counted")
