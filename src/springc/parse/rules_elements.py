"""Element and modification rules -> :mod:`springc.syntax` elements (``Component``,
``Import``, ``Extends``) and ``Modification``s.

:class:`ElementRules` has one method per rule of ``grammar/modelica.lark`` for
declarations (with ``inner``/``outer``, ``replaceable``, ``constrainedby``, conditions),
imports, ``extends`` clauses, modifications (with ``redeclare``) and comments; unsupported
forms (``stream``, ``:=`` bindings) become located
``... not supported yet`` errors.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from lark import Token
from lark.tree import Meta

from ..errors import Span
from ..ir.syntax import (
    Bool,
    ClassDef,
    Component,
    ElementModification,
    Expr,
    Extends,
    Import,
    Modification,
    Ref,
)
from .rules_base import Annotation, ClassMod, Rejected, RuleBase, Subs, of


@dataclass(frozen=True, slots=True)
class _Comment:
    description: str
    annotation: Modification | None


@dataclass(frozen=True, slots=True)
class _Decl:
    name: str
    dims: tuple[Expr, ...]
    modification: Modification | None
    description: str
    span: Span
    condition: Expr | None
    evaluate: bool = False


def _evaluate_annotation(annotation: Modification | None) -> bool:
    """Whether an element's annotation says ``Evaluate = true`` (Modelica 18.3)."""
    if annotation is None:
        return False
    return any(arg.path == ("Evaluate",) and arg.modification is not None
               and isinstance(arg.modification.value, Bool) and arg.modification.value.value
               for arg in annotation.arguments)


@dataclass(frozen=True, slots=True)
class _Condition:
    expr: Expr


@dataclass(frozen=True, slots=True)
class _Constraint:
    type_name: Ref
    modification: Modification | None
    span: Span


@dataclass(frozen=True, slots=True)
class _Clause:
    prefixes: tuple[str, ...]
    type_name: Ref
    type_dims: tuple[Expr, ...]
    declarations: tuple[_Decl, ...]


def variability(words: list[str]) -> str:
    """``parameter``, ``constant``, ``discrete`` or ``""``, from a list of prefixes."""
    return next((w for w in words if w in ("parameter", "constant", "discrete")), "")


def causality(words: list[str]) -> str:
    """``input``, ``output`` or ``""``, from a list of prefixes."""
    return next((w for w in words if w in ("input", "output")), "")


class ElementRules(RuleBase):
    """The rules of element declarations, imports, extends clauses and modifications."""

    # ---------------------------------------------------------------- elements

    def declaration_element(self, meta: Meta, ch: list[Any]) -> Any:
        prefixes, item = ch[0], ch[1]
        words = [str(t) for t in prefixes]
        constraint = of(ch[2:], _Constraint)
        if constraint is not None and "replaceable" not in words:
            self.error("`constrainedby` needs a `replaceable` element", constraint.span,
                       hint="write `replaceable` before the declaration")
        if isinstance(item, Rejected):
            return [item]
        if isinstance(item, ClassDef):
            return [replace(item, replaceable="replaceable" in words,
                            redeclare="redeclare" in words, final="final" in words,
                            constraint=(constraint.type_name, constraint.modification)
                            if constraint else None,
                            inner="inner" in words, outer="outer" in words)]
        return self._components(item, words, constraint)

    def _components(self, item: _Clause, words: list[str], constraint: _Constraint | None
                    ) -> list[Component]:
        words = words + list(item.prefixes)
        return [
            Component(
                name=d.name, type_name=item.type_name, type_dims=item.type_dims, dims=d.dims,
                modification=d.modification, variability=variability(words),
                causality=causality(words), flow="flow" in words, final="final" in words,
                stream="stream" in words,
                protected=False, description=d.description, span=d.span,
                condition=d.condition, inner="inner" in words, outer="outer" in words,
                replaceable="replaceable" in words,
                constraint=(constraint.type_name, constraint.modification)
                if constraint else None, redeclare="redeclare" in words,
                evaluate=d.evaluate,
            )
            for d in item.declarations
        ]

    def element_prefixes(self, meta: Meta, ch: list[Any]) -> Any:
        return list(ch)

    def type_prefix(self, meta: Meta, ch: list[Any]) -> Any:
        for tok in ch:
            if tok == "stream":
                self.reject("`stream` connectors are", self.token_span(tok))
        return list(ch)

    def constraining_clause(self, meta: Meta, ch: list[Any]) -> Any:
        mod = of(ch, ClassMod)
        return _Constraint(ch[0], Modification(mod.arguments, None, mod.span) if mod else None,
                           self.keyword_span(meta, "constrainedby"))

    def import_alias(self, meta: Meta, ch: list[Any]) -> Import:
        alias, path = ch[0], ch[1]
        names = tuple(self.ident(t) for t in path)
        return Import(names[:-1], names[-1:], self.ident(alias), False, self.span_of(meta))

    def import_single(self, meta: Meta, ch: list[Any]) -> Import:
        names = tuple(self.ident(t) for t in ch[0])
        return Import(names[:-1], names[-1:], None, False, self.span_of(meta))

    def import_wildcard(self, meta: Meta, ch: list[Any]) -> Import:
        names = tuple(self.ident(t) for t in ch[0])
        return Import(names, (), None, True, self.span_of(meta))

    def import_list(self, meta: Meta, ch: list[Any]) -> Import:
        path = tuple(self.ident(t) for t in ch[0])
        names = tuple(self.ident(t) for t in ch[1:] if isinstance(t, Token))
        return Import(path, names, None, False, self.span_of(meta))

    def extends_clause(self, meta: Meta, ch: list[Any]) -> Extends:
        mod = of(ch, ClassMod)
        modification = Modification(mod.arguments, None, mod.span) if mod else None
        return Extends(ch[0], modification, self.span_of(meta))

    def component_clause(self, meta: Meta, ch: list[Any]) -> Any:
        prefixes, type_name = ch[0], ch[1]
        dims = of(ch, Subs)
        decls = tuple(c for c in ch if isinstance(c, _Decl))
        return _Clause(tuple(str(t) for t in prefixes), type_name,
                       dims.items if dims else (), decls)

    def type_specifier(self, meta: Meta, ch: list[Any]) -> Any:
        return self.make_ref(ch[0])

    def global_type_specifier(self, meta: Meta, ch: list[Any]) -> Any:
        ref = self.make_ref(ch[0])
        return Ref(ref.parts, self.span_of(meta), is_global=True)

    def component_declaration(self, meta: Meta, ch: list[Any]) -> Any:
        dims = of(ch, Subs)
        comment = ch[-1]
        condition = of(ch, _Condition)
        return _Decl(self.ident(ch[0]), dims.items if dims else (), of(ch, Modification),
                     comment.description, self.span_of(meta),
                     condition.expr if condition else None,
                     _evaluate_annotation(comment.annotation))

    def condition_attribute(self, meta: Meta, ch: list[Any]) -> _Condition:
        return _Condition(ch[0])

    # ------------------------------------------------------------ modifications

    def modification(self, meta: Meta, ch: list[Any]) -> Modification:
        mod = of(ch, ClassMod)
        value = ch[-1] if not isinstance(ch[-1], ClassMod) else None
        return Modification(mod.arguments if mod else (), value, self.span_of(meta))

    def assign_modification(self, meta: Meta, ch: list[Any]) -> Modification:
        self.reject("`:=` in a declaration is", self.keyword_span(meta, ":="),
                     hint="use '=' for a binding")
        return Modification((), ch[0], self.span_of(meta))

    def class_modification(self, meta: Meta, ch: list[Any]) -> ClassMod:
        args = tuple(c for c in ch if isinstance(c, ElementModification))
        return ClassMod(args, self.span_of(meta))

    def element_modification(self, meta: Meta, ch: list[Any]) -> ElementModification:
        flags = {t.type for t in ch if isinstance(t, Token)}
        path = next(c for c in ch if isinstance(c, tuple))
        return ElementModification(
            path=tuple(self.ident(t) for t in path), modification=of(ch, Modification),
            each="EACH" in flags, final="FINAL" in flags, span=self.span_of(meta),
        )

    def element_replaceable(self, meta: Meta, ch: list[Any]) -> ElementModification | Rejected:
        return self._redeclaration(meta, ch)

    def replaceable_body(self, meta: Meta, ch: list[Any]) -> Any:
        item = ch[0]
        constraint = of(ch[1:], _Constraint)
        if isinstance(item, ClassDef):
            return replace(item, replaceable=True, constraint=(
                constraint.type_name, constraint.modification) if constraint else None)
        if isinstance(item, Component):
            return replace(item, replaceable=True, constraint=(
                constraint.type_name, constraint.modification) if constraint else None)
        return item

    def element_redeclaration(self, meta: Meta, ch: list[Any]) -> ElementModification | Rejected:
        return self._redeclaration(meta, ch)

    def _redeclaration(self, meta: Meta, ch: list[Any]) -> ElementModification | Rejected:
        """``redeclare each final Real x = 1`` in a modification: an element modification
        of ``x`` carrying the new declaration."""
        flags = {t.type for t in ch if isinstance(t, Token)}
        item = next((c for c in ch if isinstance(c, Component | ClassDef | Rejected)), None)
        if not isinstance(item, Component | ClassDef):
            return item if isinstance(item, Rejected) else Rejected(self.span_of(meta))
        return ElementModification(path=(item.name,), modification=None,
                                   each="EACH" in flags, final="FINAL" in flags,
                                   span=self.span_of(meta), redeclare=item)

    def component_clause1(self, meta: Meta, ch: list[Any]) -> Any:
        clause = _Clause(tuple(str(t) for t in ch[0]), ch[1], (), (ch[2],))
        return self._components(clause, [], None)[0]

    def component_declaration1(self, meta: Meta, ch: list[Any]) -> Any:
        dims = of(ch, Subs)
        comment = ch[-1]
        return _Decl(self.ident(ch[0]), dims.items if dims else (), of(ch, Modification),
                     comment.description, self.span_of(meta), None)

    def annotation_clause(self, meta: Meta, ch: list[Any]) -> Annotation:
        return Annotation(Modification(ch[0].arguments, None, self.span_of(meta)))

    def comment(self, meta: Meta, ch: list[Any]) -> Any:
        annotation = of(ch, Annotation)
        return _Comment(ch[0], annotation.modification if annotation else None)

    def description(self, meta: Meta, ch: list[Any]) -> Any:
        return "".join(self.unescape(t[1:-1], t) for t in ch)
