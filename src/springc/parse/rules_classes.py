"""Stored-definition and class rules -> :class:`springc.syntax.StoredDefinition` and
:class:`springc.syntax.ClassDef`.

:class:`ClassRules` has one method per rule of ``grammar/modelica.lark`` for the file
(``within``, top-level classes), class definitions (long, short, ``enumeration``,
``class extends``) and their sections; a class's sections are sorted into elements,
equations and algorithms here, and unsupported class kinds and sections become located
``... not supported yet`` errors.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

from lark import Token
from lark.tree import Meta

from ..errors import Note, Span
from ..ir.syntax import (
    AlgorithmSection,
    ClassDef,
    Component,
    Element,
    Extends,
    ExternalCall,
    Modification,
    Ref,
    ShortDef,
    StoredDefinition,
)
from .rules_base import Annotation, ClassMod, Rejected, RuleBase, Subs, join, of
from .rules_elements import causality, variability

#: The attributes of enumeration types, which no literal may be named (section 4.8.5.1).
ENUMERATION_ATTRIBUTES = frozenset({"quantity", "min", "max", "start", "fixed"})

@dataclass(frozen=True, slots=True)
class _Within:
    path: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class _Section:
    """A composition section: ``kind`` is public, protected, equation,
    initial equation, algorithm, initial algorithm or external."""

    kind: str
    items: tuple[Any, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class _EnumBody:
    literals: tuple[str, ...] | None  # None for `enumeration(:)`


@dataclass(frozen=True, slots=True)
class _Spec:
    """The part of a class definition after its prefixes."""

    name: Token
    description: str
    sections: tuple[_Section, ...]
    short: ShortDef | None
    annotation: Modification | None
    end_name: Token | None
    enumeration: tuple[str, ...] | None = None
    class_extends: bool = False


def _section_rule(kind: str) -> Callable[[RuleBase, Meta, list[Any]], _Section]:
    """The rule method for a section that starts with the keyword(s) ``kind``."""

    def method(self: RuleBase, meta: Meta, ch: list[Any]) -> _Section:
        items = [i for c in ch for i in (c if isinstance(c, tuple) else (c,))]
        return _Section(kind, tuple(items), self.keyword_span(meta, kind.split()[0]))

    return method


def _merge_annotations(first: Modification | None,
                       more: tuple[Modification, ...]) -> Modification | None:
    mods = ([first] if first else []) + list(more)
    if len(mods) <= 1:
        return mods[0] if mods else None
    return Modification(tuple(a for m in mods for a in m.arguments), None, mods[0].span)


class ClassRules(RuleBase):
    """The rules of the stored definition, class definitions and sections."""

    # ----------------------------------------------------------- stored definition

    def start(self, meta: Meta, ch: list[Any]) -> StoredDefinition:
        within = of(ch, _Within)
        classes = tuple(c for c in ch if isinstance(c, ClassDef))
        return StoredDefinition(self.file, within.path if within else None, classes)

    def expression_start(self, meta: Meta, ch: list[Any]) -> Any:
        return ch[0]

    def within_clause(self, meta: Meta, ch: list[Any]) -> Any:
        return _Within(tuple(self.ident(t) for t in ch[0]) if ch else ())

    def top_class(self, meta: Meta, ch: list[Any]) -> Any:
        return ch[-1]

    # ----------------------------------------------------------------- classes

    def class_prefixes(self, meta: Meta, ch: list[Any]) -> Any:
        return [t for c in ch for t in (c if isinstance(c, list) else [c])]

    def class_kind(self, meta: Meta, ch: list[Any]) -> Any:
        return list(ch)

    def class_definition(self, meta: Meta, ch: list[Any]) -> Any:
        prefixes, spec = ch
        if isinstance(spec, Rejected):
            return spec
        words = [str(t) for t in prefixes]
        for tok in prefixes:
            if tok in ("operator", "impure"):
                kind = {"operator": "`operator` classes are",
                        "impure": "`impure` functions are"}[tok]
                self.reject(kind, self.token_span(tok))
        kind = words[-1]
        name = self.ident(spec.name)
        span = self.span_of(meta)
        if spec.end_name is not None and spec.end_name != spec.name:
            head = Span(self.file, meta.line, meta.column, spec.name.end_line,
                        spec.name.end_column)
            self.error(f"class '{name}' ends with 'end {spec.end_name}'",
                        self.token_span(spec.end_name),
                        hint=f"write 'end {spec.name};'",
                        notes=[Note(f"class '{name}' starts here", head)])
        body = self._body(spec.sections, kind)
        return ClassDef(
            name=name, kind=kind, partial="partial" in words,
            encapsulated="encapsulated" in words, description=spec.description,
            elements=body["elements"], equations=body["equation"],
            initial_equations=body["initial equation"], algorithm=body["algorithm"],
            short=spec.short,
            annotation=_merge_annotations(spec.annotation, body["annotations"]),
            protected=False, span=span, enumeration=spec.enumeration,
            class_extends=spec.class_extends,
            unsupported=self.take_deferred(span) if self.defer else (),
            external=body["external"][0] if body["external"] else None,
            expandable="expandable" in words, operator="operator" in words,
        )

    def short_class_definition(self, meta: Meta, ch: list[Any]) -> Any:
        """A class written in a modification: ``redeclare model M = Other``."""
        return self.class_definition(meta, ch)

    def _body(self, sections: tuple[_Section, ...], kind: str) -> dict[str, tuple[Any, ...]]:
        body: dict[str, list[Any]] = {"elements": [], "equation": [], "initial equation": [],
                                      "algorithm": [], "annotations": [],
                                      "algorithm_sections": [], "external": []}
        for section in sections:
            if section.kind in ("algorithm", "initial algorithm") and kind != "function":
                statements = tuple(i for i in section.items
                                   if not isinstance(i, Annotation | Rejected))
                target = "equation" if section.kind == "algorithm" else "initial equation"
                body[target].append(AlgorithmSection(statements, section.span))
            elif section.kind == "initial algorithm":
                self.error("a function cannot have an `initial algorithm` section",
                           section.span, hint="a function computes its outputs in one "
                           "`algorithm` section, and has no equations and no initial "
                           "algorithms (Modelica 3.6, section 12.2)")
            elif section.kind == "external":
                # every external clause is kept: flattening evaluates the ones springc
                # implements (ir.native_externals) and names the others where called
                body["external"].append(section.items[0] if section.items else ExternalCall(
                    "C", "", None, (), section.span))
                continue
            elif section.kind == "algorithm" and body["algorithm_sections"]:
                self.error("a function can have at most one `algorithm` section",
                           section.span, hint="merge the statements into one section "
                           "(Modelica 3.6, section 12.2)")
            elif section.kind in ("equation", "initial equation") and kind == "function":
                self.error(f"a function cannot have an `{section.kind}` section", section.span,
                            hint="compute the outputs in an `algorithm` section")
            if section.kind == "algorithm":
                body["algorithm_sections"].append(section)
            for item in section.items:
                if isinstance(item, Annotation):
                    body["annotations"].append(item.modification)
                elif isinstance(item, Rejected):
                    continue
                elif section.kind in ("public", "protected"):
                    if section.kind == "protected" and isinstance(item, Component | ClassDef
                                                                  | Extends):
                        item = replace(item, protected=True)
                    body["elements"].append(item)
                elif section.kind in body:
                    body[section.kind].append(item)
        return {k: tuple(v) for k, v in body.items()}

    def long_class(self, meta: Meta, ch: list[Any]) -> Any:
        name, description, sections, end_name = ch
        return _Spec(name, description, sections, None, None, end_name)

    def extends_class(self, meta: Meta, ch: list[Any]) -> Any:
        """``model extends M(k = 1) ... end M;``: a long class whose first element extends
        the class M inherited by the enclosing class (section 7.3.1)."""
        name, (description, sections, end_name) = ch[0], ch[-3:]
        mod = of(ch, ClassMod)
        base = Extends(self.make_ref((name,)),
                       Modification(mod.arguments, None, mod.span) if mod else None,
                       self.keyword_span(meta, "extends"))
        first = replace(sections[0], items=(base, *sections[0].items))
        return _Spec(name, description, (first, *sections[1:]), None, None, end_name,
                     class_extends=True)

    def short_class(self, meta: Meta, ch: list[Any]) -> Any:
        name, prefixes, base = ch[0], ch[1], ch[2]
        dims = of(ch, Subs)
        mod = of(ch, ClassMod)
        comment = ch[-1]
        words = [str(t) for t in prefixes]
        short = ShortDef(
            base=base, dims=dims.items if dims else (),
            modification=Modification(mod.arguments, None, mod.span) if mod else None,
            variability=variability(words), causality=causality(words),
            flow="flow" in words, span=join(base.span, self.span_of(meta)),
        )
        return _Spec(name, comment.description, (), short, comment.annotation, None)

    def enum_class(self, meta: Meta, ch: list[Any]) -> Any:
        name, comment = ch[0], ch[-1]
        body = of(ch, _EnumBody)  # `enumeration(:)` (unspecified): no literals
        literals = body.literals if body is not None and body.literals is not None else ()
        if len(set(literals)) != len(literals):
            self.error(f"enumeration '{self.ident(name)}' has a literal twice",
                       self.span_of(meta))
        attributes = [lit for lit in literals if lit in ENUMERATION_ATTRIBUTES]
        if attributes:
            self.error(f"enumeration '{self.ident(name)}' has a literal named "
                       f"'{attributes[0]}', like an attribute of enumeration types",
                       self.span_of(meta), "the literals and the attributes of an "
                       "enumeration type share one scope, so quantity, min, max, start and "
                       "fixed cannot be literals; rename the literal (Modelica 3.6, "
                       "section 4.8.5.1)")
        return _Spec(name, comment.description, (), None, comment.annotation, None, literals)

    def enum_body(self, meta: Meta, ch: list[Any]) -> Any:
        literals = [c for c in ch if isinstance(c, str)]
        return _EnumBody(tuple(literals) if ch else None)

    def enum_literal(self, meta: Meta, ch: list[Any]) -> str:
        return self.ident(ch[0])

    def composition(self, meta: Meta, ch: list[Any]) -> Any:
        elements = [i for c in ch if not isinstance(c, _Section) for i in c]
        first = _Section("public", tuple(elements), self.span_of(meta) if not meta.empty
                         else Span(self.file, 1, 1, 1, 1))
        return (first, *(c for c in ch if isinstance(c, _Section)))

    def element_item(self, meta: Meta, ch: list[Any]) -> Any:
        item = ch[0]
        return (item,) if isinstance(item, Element | Annotation | Rejected) else tuple(item)

    def equation_item(self, meta: Meta, ch: list[Any]) -> Any:
        return ch[0]

    statement_item = equation_item

    public_section = _section_rule("public")
    protected_section = _section_rule("protected")
    equation_section = _section_rule("equation")
    initial_equation_section = _section_rule("initial equation")
    algorithm_section = _section_rule("algorithm")
    initial_algorithm_section = _section_rule("initial algorithm")

    def external_part(self, meta: Meta, ch: list[Any]) -> Any:
        call = ch[0] if ch and isinstance(ch[0], ExternalCall) else None
        return _Section("external", (call,) if call is not None else (),
                        self.keyword_span(meta, "external"))

    def external_clause(self, meta: Meta, ch: list[Any]) -> Any:
        language = next((str(c)[1:-1] for c in ch if isinstance(c, Token)
                         and c.type == "STRING"), "C")
        call = next((c for c in ch if isinstance(c, ExternalCall)), None)
        notes = next((c.modification for c in ch if isinstance(c, Annotation)), None)
        if call is None:  # the default call (12.9.1): the function's own name
            return ExternalCall(language, "", None, (), self.keyword_span(meta, "external"),
                                notes) if notes is not None else None
        return replace(call, language=language, annotation=notes)

    def external_call(self, meta: Meta, ch: list[Any]) -> Any:
        output = None
        if ch and isinstance(ch[0], Ref):
            output, ch = ch[0].dotted, ch[1:]
        return ExternalCall("C", str(ch[0]), output, tuple(ch[1:]), self.span_of(meta))
