"""lark parse tree -> syntax nodes: the second half of :mod:`springc.parse`.

:class:`SyntaxBuilder` has one method per grammar rule (``grammar/modelica.lark``); each
gets the rule's positions and its converted children and returns a :mod:`springc.syntax`
node with its span. Constructs of LANGUAGE.md's "Later" list are turned into located
``... not supported yet`` errors; all errors are collected and raised together.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any

from lark import Token, Tree

from .errors import ErrorGroup, Note, ParseError, Span
from .syntax import (
    ArrayLit,
    Assign,
    Binary,
    Bool,
    Call,
    CallEquation,
    ClassDef,
    Colon,
    Component,
    Comprehension,
    Connect,
    Element,
    ElementModification,
    End,
    Equality,
    Expr,
    Extends,
    ForEquation,
    ForIndex,
    ForStatement,
    IfEquation,
    IfExpr,
    IfStatement,
    Import,
    MatrixLit,
    Modification,
    NamedArg,
    Number,
    Range,
    Ref,
    RefPart,
    ShortDef,
    StoredDefinition,
    String,
    Unary,
)

LATER = "springc supports a subset of Modelica; see the \"Later\" list in LANGUAGE.md"

KEYWORDS = frozenset(
    [
        "algorithm", "and", "annotation", "block", "break", "class", "connect", "connector",
        "constant", "constrainedby", "der", "discrete", "each", "else", "elseif", "elsewhen",
        "encapsulated", "end", "enumeration", "equation", "expandable", "extends", "external",
        "false", "final", "flow", "for", "function", "if", "import", "impure", "in", "initial",
        "inner", "input", "loop", "model", "not", "operator", "or", "outer", "output", "package",
        "parameter", "partial", "protected", "public", "pure", "record", "redeclare",
        "replaceable", "return", "stream", "then", "true", "type", "when", "while", "within",
    ]
)
# `der` and `initial` are also called as ordinary functions (see the grammar).
_FUNCTION_WORDS = frozenset({"der", "initial"})

_ESCAPES = {"'": "'", '"': '"', "?": "?", "\\": "\\", "a": "\a", "b": "\b", "f": "\f",
            "n": "\n", "r": "\r", "t": "\t", "v": "\v"}


def build(tree: Tree, file: str) -> Any:
    """The syntax node of ``tree`` (a StoredDefinition, or an Expr for an expression);
    raises :class:`ParseError`, or :class:`ErrorGroup` if there are several errors."""
    builder = SyntaxBuilder(file)
    result = builder.convert(tree)
    if builder.errors:
        errors = sorted(builder.errors, key=lambda e: (e.span.line, e.span.column))
        raise errors[0] if len(errors) == 1 else ErrorGroup(errors)
    return result


# ---------------------------------------- intermediate results of rules (module-private)


@dataclass(frozen=True, slots=True)
class _Rejected:
    """Stands in for an unsupported construct; its error is already recorded."""

    span: Span


@dataclass(frozen=True, slots=True)
class _Subs:
    items: tuple[Expr, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class _ClassMod:
    arguments: tuple[ElementModification, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class _Annotation:
    modification: Modification


@dataclass(frozen=True, slots=True)
class _Comment:
    description: str
    annotation: Modification | None


@dataclass(frozen=True, slots=True)
class _Within:
    path: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class _Args:
    args: tuple[Expr, ...]
    named: tuple[NamedArg, ...]


@dataclass(frozen=True, slots=True)
class _Decl:
    name: str
    dims: tuple[Expr, ...]
    modification: Modification | None
    description: str
    span: Span


@dataclass(frozen=True, slots=True)
class _Clause:
    prefixes: tuple[str, ...]
    type_name: Ref
    type_dims: tuple[Expr, ...]
    declarations: tuple[_Decl, ...]


@dataclass(frozen=True, slots=True)
class _Section:
    """A composition section: ``kind`` is public, protected, equation,
    initial equation, algorithm, initial algorithm or external."""

    kind: str
    items: tuple
    span: Span


@dataclass(frozen=True, slots=True)
class _Spec:
    """The part of a class definition after its prefixes."""

    name: Token
    description: str
    sections: tuple[_Section, ...]
    short: ShortDef | None
    annotation: Modification | None
    end_name: Token | None


_RELATIONS = frozenset({"<", "<=", ">", ">=", "==", "<>"})
_ADDITIVE = frozenset({"+", "-", ".+", ".-"})
_MULTIPLICATIVE = frozenset({"*", "/", ".*", "./"})
_POWER = frozenset({"^", ".^"})


def _tokens(children: list) -> list[Token]:
    return [c for c in children if isinstance(c, Token)]


def _of(children: list, kind: type):
    """The first child of type ``kind``, or ``None``."""
    return next((c for c in children if isinstance(c, kind)), None)


def _join(a: Span, b: Span) -> Span:
    return Span(a.file, a.line, a.column, b.end_line, b.end_column)


def _section_rule(kind: str):
    """The transformer method for a section that starts with the keyword(s) ``kind``."""

    def method(self: SyntaxBuilder, meta, ch) -> _Section:
        items = [i for c in ch for i in (c if isinstance(c, tuple) else (c,))]
        return _Section(kind, tuple(items), self._kw(meta, kind.split()[0]))

    return method


class SyntaxBuilder:
    """Maps each grammar rule to a syntax node; collects errors instead of stopping.

    The method named after a rule receives the rule's ``meta`` (positions) and its
    already converted children. (A hand-written walk: lark's ``Transformer`` with
    ``v_args(meta=True)`` costs about three times as much per node.)
    """

    def __init__(self, file: str) -> None:
        self.file = file
        self.errors: list[ParseError] = []
        self._methods: dict[str, Callable[[Any, list], Any]] = {}
        self._loose_ends: list[End] = []  # `end`s not yet known to sit in a subscript

    def convert(self, tree: Tree) -> Any:
        """The syntax node for the whole ``tree``; problems are left in ``errors``."""
        result = self.transform(tree)
        for end in self._loose_ends:
            self._error("`end` may only be used inside array subscripts such as x[end]",
                        end.span)
        return result

    def transform(self, tree: Tree) -> Any:
        children = [self.transform(c) if type(c) is Tree else c for c in tree.children]
        method = self._methods.get(tree.data)
        if method is None:  # every rule has a method: a missing one is a bug, not a skip
            method = self._methods[tree.data] = getattr(self, tree.data)
        return method(tree.meta, children)

    # ---------------------------------------------------------------- helpers

    def _span(self, meta) -> Span:
        return Span(self.file, meta.line, meta.column, meta.end_line, meta.end_column)

    def _tspan(self, tok: Token) -> Span:
        return Span(self.file, tok.line, tok.column, tok.end_line, tok.end_column)

    def _kw(self, meta, word: str) -> Span:
        """The span of the keyword ``word`` that starts the rule at ``meta``."""
        return Span(self.file, meta.line, meta.column, meta.line, meta.column + len(word))

    def _error(self, message: str, span: Span, hint: str | None = None,
               notes: Iterable[Note] = ()) -> None:
        self.errors.append(ParseError(message, span, notes, hint))

    def _reject(self, what: str, span: Span, hint: str | None = LATER) -> _Rejected:
        self._error(f"{what} not supported yet", span, hint)
        return _Rejected(span)

    def _ident(self, tok: Token, function: bool = False) -> str:
        """The name written by ``tok`` (without quotes); reserved words are errors,
        except ``der``/``initial`` as the ``function`` name of a call."""
        if tok.startswith("'"):
            return _unescape(tok[1:-1], self, tok)
        if tok in KEYWORDS and not (function and tok in _FUNCTION_WORDS):
            self._error(f"'{tok}' is a reserved word and cannot be used as a name",
                        self._tspan(tok))
        return str(tok)

    def _ref(self, toks: tuple[Token, ...]) -> Ref:
        parts = tuple(RefPart(self._ident(t), (), self._tspan(t)) for t in toks)
        return Ref(parts, _join(parts[0].span, parts[-1].span))

    # ----------------------------------------------------------- stored definition

    def start(self, meta, ch):
        within = _of(ch, _Within)
        classes = tuple(c for c in ch if isinstance(c, ClassDef))
        return StoredDefinition(self.file, within.path if within else None, classes)

    def expression_start(self, meta, ch):
        return ch[0]

    def within_clause(self, meta, ch):
        return _Within(tuple(self._ident(t) for t in ch[0]) if ch else ())

    def top_class(self, meta, ch):
        return ch[-1]

    # ----------------------------------------------------------------- classes

    def class_prefixes(self, meta, ch):
        return [t for c in ch for t in (c if isinstance(c, list) else [c])]

    def class_kind(self, meta, ch):
        return list(ch)

    def class_definition(self, meta, ch):
        prefixes, spec = ch
        if isinstance(spec, _Rejected):
            return spec
        words = [str(t) for t in prefixes]
        for tok in prefixes:
            if tok in ("operator", "expandable", "impure"):
                kind = {"operator": "`operator` classes are",
                        "expandable": "`expandable` connectors are",
                        "impure": "`impure` functions are"}[tok]
                self._reject(kind, self._tspan(tok))
        kind = words[-1]
        name = self._ident(spec.name)
        span = self._span(meta)
        if spec.end_name is not None and spec.end_name != spec.name:
            head = Span(self.file, meta.line, meta.column, spec.name.end_line,
                        spec.name.end_column)
            self._error(f"class '{name}' ends with 'end {spec.end_name}'",
                        self._tspan(spec.end_name),
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
            protected=False, span=span,
        )

    def _body(self, sections: tuple[_Section, ...], kind: str) -> dict:
        body: dict = {"elements": [], "equation": [], "initial equation": [], "algorithm": [],
                      "annotations": []}
        for section in sections:
            if section.kind == "algorithm" and kind != "function":
                self._reject("`algorithm` sections outside functions are", section.span,
                             hint="use equations; springc accepts `algorithm` only in "
                                  "functions (see the \"Later\" list in LANGUAGE.md)")
            elif section.kind == "initial algorithm":
                self._reject("`initial algorithm` sections are", section.span)
            elif section.kind == "external":
                self._reject("`external` functions are", section.span)
            elif section.kind in ("equation", "initial equation") and kind == "function":
                self._error(f"a function cannot have an `{section.kind}` section", section.span,
                            hint="compute the outputs in an `algorithm` section")
            for item in section.items:
                if isinstance(item, _Annotation):
                    body["annotations"].append(item.modification)
                elif isinstance(item, _Rejected):
                    continue
                elif section.kind in ("public", "protected"):
                    if section.kind == "protected" and isinstance(item, Component | ClassDef):
                        item = replace(item, protected=True)
                    body["elements"].append(item)
                elif section.kind in body:
                    body[section.kind].append(item)
        return {k: tuple(v) for k, v in body.items()}

    def long_class(self, meta, ch):
        name, description, sections, end_name = ch
        return _Spec(name, description, sections, None, None, end_name)

    def extends_class(self, meta, ch):
        return self._reject("`class extends` definitions are", self._kw(meta, "extends"))

    def short_class(self, meta, ch):
        name, prefixes, base = ch[0], ch[1], ch[2]
        dims = _of(ch, _Subs)
        mod = _of(ch, _ClassMod)
        comment = ch[-1]
        words = [str(t) for t in prefixes]
        short = ShortDef(
            base=base, dims=dims.items if dims else (),
            modification=Modification(mod.arguments, None, mod.span) if mod else None,
            variability=_variability(words), causality=_causality(words),
            flow="flow" in words, span=_join(base.span, self._span(meta)),
        )
        return _Spec(name, comment.description, (), short, comment.annotation, None)

    def enum_class(self, meta, ch):
        keyword = next(t for t in _tokens(ch) if t.type == "ENUMERATION")
        return self._reject("`enumeration` types are", self._tspan(keyword))

    def enum_body(self, meta, ch):
        return None

    enum_literal = enum_body

    def composition(self, meta, ch):
        elements = [i for c in ch if not isinstance(c, _Section) for i in c]
        first = _Section("public", tuple(elements), self._span(meta) if not meta.empty
                         else Span(self.file, 1, 1, 1, 1))
        return (first, *(c for c in ch if isinstance(c, _Section)))

    def element_item(self, meta, ch):
        item = ch[0]
        return (item,) if isinstance(item, Element | _Annotation | _Rejected) else tuple(item)

    def equation_item(self, meta, ch):
        return ch[0]

    statement_item = equation_item

    public_section = _section_rule("public")
    protected_section = _section_rule("protected")
    equation_section = _section_rule("equation")
    initial_equation_section = _section_rule("initial equation")
    algorithm_section = _section_rule("algorithm")
    initial_algorithm_section = _section_rule("initial algorithm")

    def external_part(self, meta, ch):
        return _Section("external", (), self._kw(meta, "external"))

    def external_clause(self, meta, ch):
        return None

    def external_call(self, meta, ch):
        return None

    # ---------------------------------------------------------------- elements

    def declaration_element(self, meta, ch):
        prefixes, item = ch[0], ch[1]
        words = [str(t) for t in prefixes]
        for tok in prefixes:
            if tok in ("redeclare", "replaceable"):
                self._reject(f"`{tok}` is", self._tspan(tok))
            elif tok in ("inner", "outer"):
                self._reject(f"`{tok}` elements are", self._tspan(tok))
        if len(ch) > 2 and "replaceable" not in words:
            self._reject("`constrainedby` is", ch[2])
        if isinstance(item, ClassDef | _Rejected):
            return [item]
        words += list(item.prefixes)
        return [
            Component(
                name=d.name, type_name=item.type_name, type_dims=item.type_dims, dims=d.dims,
                modification=d.modification, variability=_variability(words),
                causality=_causality(words), flow="flow" in words, final="final" in words,
                protected=False, description=d.description, span=d.span,
            )
            for d in item.declarations
        ]

    def element_prefixes(self, meta, ch):
        return list(ch)

    def type_prefix(self, meta, ch):
        for tok in ch:
            if tok == "stream":
                self._reject("`stream` connectors are", self._tspan(tok))
        return list(ch)

    def constraining_clause(self, meta, ch):
        return self._kw(meta, "constrainedby")

    def import_alias(self, meta, ch):
        alias, path = ch[0], ch[1]
        names = tuple(self._ident(t) for t in path)
        return Import(names[:-1], names[-1:], self._ident(alias), False, self._span(meta))

    def import_single(self, meta, ch):
        names = tuple(self._ident(t) for t in ch[0])
        return Import(names[:-1], names[-1:], None, False, self._span(meta))

    def import_wildcard(self, meta, ch):
        names = tuple(self._ident(t) for t in ch[0])
        return Import(names, (), None, True, self._span(meta))

    def import_list(self, meta, ch):
        path = tuple(self._ident(t) for t in ch[0])
        names = tuple(self._ident(t) for t in ch[1:] if isinstance(t, Token))
        return Import(path, names, None, False, self._span(meta))

    def extends_clause(self, meta, ch):
        mod = _of(ch, _ClassMod)
        modification = Modification(mod.arguments, None, mod.span) if mod else None
        return Extends(ch[0], modification, self._span(meta))

    def component_clause(self, meta, ch):
        prefixes, type_name = ch[0], ch[1]
        dims = _of(ch, _Subs)
        decls = tuple(c for c in ch if isinstance(c, _Decl))
        return _Clause(tuple(str(t) for t in prefixes), type_name,
                       dims.items if dims else (), decls)

    def type_specifier(self, meta, ch):
        return self._ref(ch[0])

    def global_type_specifier(self, meta, ch):
        self._reject("global names (`.A.B`) are", self._kw(meta, "."))
        return self._ref(ch[0])

    def component_declaration(self, meta, ch):
        dims = _of(ch, _Subs)
        comment = ch[-1]
        return _Decl(self._ident(ch[0]), dims.items if dims else (), _of(ch, Modification),
                     comment.description, self._span(meta))

    def condition_attribute(self, meta, ch):
        return self._reject("conditional components (`... if condition`) are",
                            self._kw(meta, "if"))

    # ------------------------------------------------------------ modifications

    def modification(self, meta, ch):
        mod = _of(ch, _ClassMod)
        value = ch[-1] if not isinstance(ch[-1], _ClassMod) else None
        return Modification(mod.arguments if mod else (), value, self._span(meta))

    def assign_modification(self, meta, ch):
        self._reject("`:=` in a declaration is", self._kw(meta, ":="),
                     hint="use '=' for a binding")
        return Modification((), ch[0], self._span(meta))

    def class_modification(self, meta, ch):
        args = tuple(c for c in ch if isinstance(c, ElementModification))
        return _ClassMod(args, self._span(meta))

    def element_modification(self, meta, ch):
        flags = {t.type for t in ch if isinstance(t, Token)}
        path = next(c for c in ch if isinstance(c, tuple))
        return ElementModification(
            path=tuple(self._ident(t) for t in path), modification=_of(ch, Modification),
            each="EACH" in flags, final="FINAL" in flags, span=self._span(meta),
        )

    def element_replaceable(self, meta, ch):
        return _Rejected(self._span(meta))

    def replaceable_body(self, meta, ch):
        return self._reject("`replaceable` is", self._kw(meta, "replaceable"))

    def element_redeclaration(self, meta, ch):
        return self._reject("`redeclare` is", self._kw(meta, "redeclare"))

    def short_class_definition(self, meta, ch):
        return _Rejected(self._span(meta))

    def component_clause1(self, meta, ch):
        return _Rejected(self._span(meta))

    def component_declaration1(self, meta, ch):
        return _Rejected(self._span(meta))

    def annotation_clause(self, meta, ch):
        return _Annotation(Modification(ch[0].arguments, None, self._span(meta)))

    def comment(self, meta, ch):
        annotation = _of(ch, _Annotation)
        return _Comment(ch[0], annotation.modification if annotation else None)

    def description(self, meta, ch):
        return "".join(_unescape(t[1:-1], self, t) for t in ch)

    # ---------------------------------------------------------------- equations

    def equation(self, meta, ch):
        return ch[0]

    def equations(self, meta, ch):
        return tuple(c for c in ch if not isinstance(c, _Rejected))

    statements = equations

    def simple_equation(self, meta, ch):
        span = self._span(meta)
        if len(ch) == 2:
            return Equality(ch[0], ch[1], span)
        if isinstance(ch[0], Call):
            return CallEquation(ch[0], span)
        self._error("this expression is not an equation", span,
                    hint="write 'lhs = rhs'; only a function call may stand alone")
        return _Rejected(span)

    def _branches(self, meta, ch, make):
        branches = [(ch[0], ch[1])]
        otherwise: tuple = ()
        for extra in ch[2:]:
            if extra[0] == "elseif":
                branches.append((extra[1], extra[2]))
            else:
                otherwise = extra[1]
        return make(tuple(branches), otherwise, self._span(meta))

    def if_equation(self, meta, ch):
        return self._branches(meta, ch, IfEquation)

    def if_statement(self, meta, ch):
        return self._branches(meta, ch, IfStatement)

    def elseif_equation(self, meta, ch):
        return ("elseif", ch[0], ch[1])

    elseif_statement = elseif_equation

    def else_equation(self, meta, ch):
        return ("else", ch[0])

    else_statement = else_equation

    def for_equation(self, meta, ch):
        return ForEquation(ch[0], ch[1], self._span(meta))

    def for_statement(self, meta, ch):
        return ForStatement(ch[0], ch[1], self._span(meta))

    def connect_clause(self, meta, ch):
        return Connect(ch[0], ch[1], self._span(meta))

    def when_equation(self, meta, ch):
        return self._reject("`when` equations are", self._kw(meta, "when"))

    def for_indices(self, meta, ch):
        return tuple(ch)

    def for_index(self, meta, ch):
        return ForIndex(self._ident(ch[0]), ch[1] if len(ch) > 1 else None, self._span(meta))

    # --------------------------------------------------------------- statements

    def statement(self, meta, ch):
        return ch[0]

    def assign_statement(self, meta, ch):
        return Assign((ch[0],), ch[1], self._span(meta))

    def call_statement(self, meta, ch):
        return self._reject("call statements (`f(x);`) are", self._span(meta))

    def multi_assign(self, meta, ch):
        *targets, func, args = ch
        for target in targets:
            if target is not None and not isinstance(target, Ref):
                self._error("only a component reference can be assigned to", target.span)
        call = Call(func, args.args, args.named, _join(func.span, self._span(meta)))
        return Assign(tuple(targets), call, self._span(meta))

    def output_item(self, meta, ch):
        return ch[0] if ch else None

    def break_statement(self, meta, ch):
        return self._reject("`break` statements are", self._span(meta))

    def return_statement(self, meta, ch):
        return self._reject("`return` statements are", self._span(meta))

    def while_statement(self, meta, ch):
        return self._reject("`while` loops are", self._kw(meta, "while"))

    def when_statement(self, meta, ch):
        return self._reject("`when` statements are", self._kw(meta, "when"))

    # -------------------------------------------------------------- expressions

    def if_expression(self, meta, ch):
        pairs = tuple((ch[i], ch[i + 1]) for i in range(0, len(ch) - 1, 2))
        return IfExpr(pairs, ch[-1], self._span(meta))

    def range(self, meta, ch):
        step = ch[1] if len(ch) == 3 else None
        return Range(ch[0], step, ch[-1], self._span(meta))

    def operation(self, meta, ch):
        return _Precedence(self, ch).build()

    def number(self, meta, ch):
        text = str(ch[0])
        value = int(text) if text.isdigit() else float(text)
        return Number(value, self._span(meta))

    def string(self, meta, ch):
        return String(_unescape(ch[0][1:-1], self, ch[0]), self._span(meta))

    def true(self, meta, ch):
        return Bool(True, self._span(meta))

    def false(self, meta, ch):
        return Bool(False, self._span(meta))

    def call(self, meta, ch):
        func, args = ch
        return Call(func, args.args, args.named, self._span(meta))

    def subscripted(self, meta, ch):
        self._reject("subscripts on a parenthesized expression (`(e)[i]`) are",
                     self._span(meta))
        return ch[0]

    def tuple(self, meta, ch):
        self._reject("output lists (`(a, b)`) outside `(a, b) := f(x)` are", self._span(meta))
        return next((c for c in ch if c is not None), Bool(False, self._span(meta)))

    def matrix(self, meta, ch):
        return MatrixLit(tuple(ch), self._span(meta))

    def matrix_row(self, meta, ch):
        return tuple(ch)

    def array(self, meta, ch):
        return ArrayLit(tuple(ch), self._span(meta))

    def array_comprehension(self, meta, ch):
        return Comprehension(ch[0], ch[1], self._span(meta))

    def component_reference(self, meta, ch):
        first = ch[0]
        if first == "end" and len(ch) == 1:
            end = End(self._span(meta))
            self._loose_ends.append(end)
            return end
        subs = ch[1] if len(ch) > 1 and isinstance(ch[1], _Subs) else None
        head = self._tspan(first)
        if subs:
            head = _join(head, subs.span)
        parts = (RefPart(self._ident(first, len(ch) == 1), subs.items if subs else (), head),
                 *(c for c in ch if isinstance(c, RefPart)))
        return Ref(parts, self._span(meta))

    def global_reference(self, meta, ch):
        self._reject("global names (`.A.B`) are", self._kw(meta, "."))
        return self.component_reference(meta, ch)

    def ref_part(self, meta, ch):
        subs = _of(ch, _Subs)
        return RefPart(self._ident(ch[0]), subs.items if subs else (), self._span(meta))

    def array_subscripts(self, meta, ch):
        span = self._span(meta)
        if self._loose_ends:  # those inside these brackets are where they belong
            inside = (span.line, span.column), (span.end_line, span.end_column)
            self._loose_ends = [e for e in self._loose_ends
                                if not inside[0] <= (e.span.line, e.span.column) < inside[1]]
        return _Subs(tuple(ch), span)

    def colon(self, meta, ch):
        return Colon(self._span(meta))

    def function_call_args(self, meta, ch):
        named = tuple(c for c in ch if isinstance(c, NamedArg))
        args = tuple(c for c in ch if not isinstance(c, NamedArg))
        seen_named = False
        for c in ch:
            seen_named = seen_named or isinstance(c, NamedArg)
            if seen_named and not isinstance(c, NamedArg):
                self._error("positional argument after a named argument", c.span)
                break
        return _Args(args, named)

    def call_comprehension(self, meta, ch):
        body, indices = ch
        return _Args((Comprehension(body, indices, _join(body.span, indices[-1].span)),), ())

    def named_argument(self, meta, ch):
        return NamedArg(self._ident(ch[0]), ch[1], self._span(meta))

    def name(self, meta, ch):
        return (ch[0],) if len(ch) == 1 else (*ch[0], ch[1])


class _Precedence:
    """Builds the tree of a flat ``operand (op operand)*`` list by Modelica precedence.

    Follows appendix A: ``expr: or; or: and {or and}; and: not {and not};
    not: [not] rel; rel: arith [relop arith]; arith: [addop] term {addop term};
    term: factor {mulop factor}; factor: primary [^ primary]``.
    """

    def __init__(self, owner: SyntaxBuilder, items: list) -> None:
        self.owner, self.items, self.i = owner, items, 0

    def build(self) -> Expr:
        result = self.or_()
        if self.i < len(self.items):
            tok = self.items[self.i]
            hint = ("comparisons cannot be chained; combine them with `and`"
                    if tok in _RELATIONS else
                    "'^' is not associative; add parentheses: (a^b)^c or a^(b^c)")
            self.owner._error(f"unexpected '{tok}'", self.owner._tspan(tok), hint=hint)
        return result

    def _take(self, ops: frozenset[str]) -> Token | None:
        if self.i < len(self.items):
            item = self.items[self.i]
            if isinstance(item, Token) and item in ops:
                self.i += 1
                return item
        return None

    def _binary(self, left: Expr, op: Token, right: Expr) -> Binary:
        return Binary(str(op), left, right, _join(left.span, right.span))

    def or_(self) -> Expr:
        left = self.and_()
        while op := self._take(frozenset({"or"})):
            left = self._binary(left, op, self.and_())
        return left

    def and_(self) -> Expr:
        left = self.not_()
        while op := self._take(frozenset({"and"})):
            left = self._binary(left, op, self.not_())
        return left

    def not_(self) -> Expr:
        if op := self._take(frozenset({"not"})):
            operand = self.relation()
            return Unary("not", operand, _join(self.owner._tspan(op), operand.span))
        return self.relation()

    def relation(self) -> Expr:
        left = self.arithmetic()
        if op := self._take(_RELATIONS):
            left = self._binary(left, op, self.arithmetic())
        return left

    def arithmetic(self) -> Expr:
        if sign := self._take(_ADDITIVE):
            operand = self.term()
            left: Expr = Unary(str(sign), operand, _join(self.owner._tspan(sign), operand.span))
        else:
            left = self.term()
        while op := self._take(_ADDITIVE):
            left = self._binary(left, op, self.term())
        return left

    def term(self) -> Expr:
        left = self.factor()
        while op := self._take(_MULTIPLICATIVE):
            left = self._binary(left, op, self.factor())
        return left

    def factor(self) -> Expr:
        base = self.primary()
        if op := self._take(_POWER):
            return self._binary(base, op, self.primary())
        return base

    def primary(self) -> Expr:
        item = self.items[self.i]
        self.i += 1
        if not isinstance(item, Token):
            return item
        example = "a and (not b)" if item == "not" else f"a * ({item}b)"
        self.owner._error(
            f"unexpected '{item}'", self.owner._tspan(item),
            hint=f"a unary '{item}' may only start an expression or an operand of a "
                 f"comparison; put it in parentheses, e.g. {example}",
        )
        return self.primary()


# ------------------------------------------------------------------- helpers

def _variability(words: list[str]) -> str:
    return next((w for w in words if w in ("parameter", "constant", "discrete")), "")


def _causality(words: list[str]) -> str:
    return next((w for w in words if w in ("input", "output")), "")


def _merge_annotations(first: Modification | None,
                       more: tuple[Modification, ...]) -> Modification | None:
    mods = ([first] if first else []) + list(more)
    if len(mods) <= 1:
        return mods[0] if mods else None
    return Modification(tuple(a for m in mods for a in m.arguments), None, mods[0].span)


_ESCAPE = re.compile(r"\\(.)", re.S)


def _unescape(body: str, owner: SyntaxBuilder, token: Token) -> str:
    """Resolve Modelica's escapes (``\\n``, ``\\"``, ...) in a string or quoted name."""
    if "\\" not in body:
        return body

    def one(m: re.Match) -> str:
        if m.group(1) in _ESCAPES:
            return _ESCAPES[m.group(1)]
        owner._error(f"invalid escape '\\{m.group(1)}'", owner._tspan(token),
                     hint="Modelica knows \\' \\\" \\? \\\\ \\a \\b \\f \\n \\r \\t \\v")
        return m.group(1)

    return _ESCAPE.sub(one, body)

