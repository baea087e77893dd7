"""Tests of springc.parse.parser: syntax tree shapes, spans and the exact text of parse errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, LoadError, ParseError, Span, SpringcError, render_all
from springc.ir.syntax import (
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
    End,
    Equality,
    Expr,
    Extends,
    ForEquation,
    ForStatement,
    IfEquation,
    IfExpr,
    IfStatement,
    Import,
    MatrixLit,
    Number,
    Range,
    Ref,
    String,
    Unary,
)
from springc.parse.parser import parse_expression, parse_file, parse_text
from springc.resources import models_dir

SEED = """\
model Mass
  parameter Real m = 1.0;
  parameter Real xy[2] = {0, 0};
  parameter Real u[2] = {0, 0};
  Real pos[2](start = xy);
  Real v[2](start = u);
equation
  der(pos) = v;
end Mass;

model Spring
  parameter Real k = 1e4;
  parameter Real l = 1;
  Real x;
  Real dir[2];
end Spring;

model SpringMass
  Mass mass(m = 1.0, xy = {1, -1});
  Spring spring(k = 1e4, l = 1);
  parameter Real center[2] = {0, 0};
  parameter Real g[2] = {0, -9.81};
equation
  spring.x = sqrt(spring.dir * spring.dir);
  spring.dir = mass.pos - center;
  der(mass.v) = -spring.k * spring.dir * (spring.x - spring.l) / spring.x / mass.m + g;
end SpringMass;
"""


def show(e: Expr) -> str:
    """A fully parenthesized rendering, to compare tree shapes at a glance."""
    match e:
        case Number(value=v) | Bool(value=v):
            return repr(v)
        case String(value=v):
            return repr(v)
        case Ref(parts=parts):
            return ".".join(
                p.name + (f"[{', '.join(show(s) for s in p.subscripts)}]" if p.subscripts else "")
                for p in parts
            )
        case Colon():
            return ":"
        case End():
            return "end"
        case Unary(op=op, operand=x):
            return f"({op} {show(x)})"
        case Binary(op=op, left=a, right=b):
            return f"({show(a)} {op} {show(b)})"
        case IfExpr(branches=branches, otherwise=other):
            conds = " elseif ".join(f"{show(c)} then {show(v)}" for c, v in branches)
            return f"(if {conds} else {show(other)})"
        case Call(func=f, args=args, named=named):
            items = [show(a) for a in args] + [f"{n.name}={show(n.value)}" for n in named]
            return f"{show(f)}({', '.join(items)})"
        case Comprehension(body=body, indices=indices):
            idx = ", ".join(f"{i.name} in {show(i.range)}" for i in indices if i.range)
            return f"{{{show(body)} for {idx}}}"
        case ArrayLit(items=items):
            return "{" + ", ".join(show(i) for i in items) + "}"
        case MatrixLit(rows=rows):
            return "[" + "; ".join(", ".join(show(i) for i in r) for r in rows) + "]"
        case Range(start=a, step=s, stop=b):
            return f"({show(a)}:{show(s) + ':' if s else ''}{show(b)})"
    raise AssertionError(f"unexpected node {e!r}")


def one_class(text: str) -> ClassDef:
    (cls,) = parse_text(text, "t.mo").classes
    return cls


def error_text(text: str, file: str = "t.mo") -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        parse_text(text, file)
    return render_all(info.value, lambda _: text)


# ------------------------------------------------------------------ the seed model


def test_seed_model_shapes() -> None:
    stored = parse_text(SEED, "seed.mo")
    assert stored.within is None
    assert [c.name for c in stored.classes] == ["Mass", "Spring", "SpringMass"]
    assert {c.kind for c in stored.classes} == {"model"}
    mass, spring, scene = stored.classes

    pos = mass.elements[3]
    assert isinstance(pos, Component)
    assert (pos.name, pos.type_name.dotted, pos.variability) == ("pos", "Real", "")
    assert [show(d) for d in pos.dims] == ["2"] and pos.type_dims == ()
    (start,) = pos.modification.arguments
    assert start.path == ("start",) and show(start.modification.value) == "xy"
    m = mass.elements[0]
    assert (m.variability, show(m.modification.value)) == ("parameter", "1.0")
    (eq,) = mass.equations
    assert isinstance(eq, Equality) and (show(eq.lhs), show(eq.rhs)) == ("der(pos)", "v")

    assert [c.name for c in spring.elements] == ["k", "l", "x", "dir"]
    assert spring.equations == ()
    assert isinstance(spring.elements[0].modification.value.value, float)  # 1e4

    mass_comp = scene.elements[0]
    assert mass_comp.type_name.dotted == "Mass"
    assert [(a.path, show(a.modification.value)) for a in mass_comp.modification.arguments] == [
        (("m",), "1.0"),
        (("xy",), "{1, (- 1)}"),
    ]
    assert [show(e.lhs) + " = " + show(e.rhs) for e in scene.equations] == [
        "spring.x = sqrt((spring.dir * spring.dir))",
        "spring.dir = (mass.pos - center)",
        "der(mass.v) = ((- ((((spring.k * spring.dir) * (spring.x - spring.l)) / spring.x)"
        " / mass.m)) + g)",
    ]


def test_bundled_models_parse() -> None:
    files = sorted(models_dir().glob("*.mdl"))
    assert files
    for path in files:
        stored = parse_file(path)
        assert stored.classes, path


# ------------------------------------------------------------------ expressions


@pytest.mark.parametrize(
    ("text", "tree"),
    [
        ("-a^2", "(- (a ^ 2))"),
        ("a-b-c", "((a - b) - c)"),
        ("a/b/c", "((a / b) / c)"),
        ("2*x[i+1].y", "(2 * x[(i + 1)].y)"),
        ("-a*b+c", "((- (a * b)) + c)"),
        ("a - (-b)", "(a - (- b))"),
        ("a or b and not c < d + 1", "(a or (b and (not (c < (d + 1)))))"),
        ("not a or b", "((not a) or b)"),
        ("a .* b ./ c .^ 2 .+ d", "(((a .* b) ./ (c .^ 2)) .+ d)"),
        ("x < -1", "(x < (- 1))"),
        ("1:n", "(1:n)"),
        ("1:2:10", "(1:2:10)"),
        ("x[end-1, :, 2:3]", "x[(end - 1), :, (2:3)]"),
        ("if a then 1 elseif b then 2 else 3", "(if a then 1 elseif b then 2 else 3)"),
        ("if a then b else if c then d else e", "(if a then b else (if c then d else e))"),
        ("{i^2 for i in 1:n}", "{(i ^ 2) for i in (1:n)}"),
        ("sum(x[i, j] for i in 1:n, j in 1:2)", "sum({x[i, j] for i in (1:n), j in (1:2)})"),
        ("[1, 2; 3, 4]", "[1, 2; 3, 4]"),
        ("{{1, 2}, {3, 4}}", "{{1, 2}, {3, 4}}"),
        ("f(1, b = 2, c = {1, 2})", "f(1, b=2, c={1, 2})"),
        ("Modelica.Math.Vectors.norm(v)", "Modelica.Math.Vectors.norm(v)"),
        ("ms[i].pos[1]", "ms[i].pos[1]"),
        ("der(x.y) + initial()", "(der(x.y) + initial())"),
        ("true and not false", "(True and (not False))"),
        ("'mass.pos[1]' + 1", "(mass.pos[1] + 1)"),
        ('"a\\"b\\n" + "c"', "('a\"b\\n' + 'c')"),
        ("x.*y", "(x .* y)"),
        ("a <> b", "(a <> b)"),
        ("{}", "{}"),
    ],
)
def test_expression_trees(text: str, tree: str) -> None:
    assert show(parse_expression(text)) == tree


def test_numbers_are_int_or_float() -> None:
    values = [parse_expression(t).value for t in ("2", "2.0", "1e3", "1.", "12E-1")]
    assert values == [2, 2.0, 1000.0, 1.0, 1.2]
    assert [type(v) for v in values] == [int, float, float, float, float]


def test_expression_spans() -> None:
    e = parse_expression("a + f(b)*2", "x.mo")
    assert e.span == Span("x.mo", 1, 1, 1, 11)
    assert e.right.span == Span("x.mo", 1, 5, 1, 11)
    assert e.right.left.span == Span("x.mo", 1, 5, 1, 9)
    neg = parse_expression(" -x[2].y")
    assert neg.span == Span("<expr>", 1, 2, 1, 9)
    ref = neg.operand
    assert [p.span.column for p in ref.parts] == [3, 8]
    assert ref.parts[0].span.end_column == 7  # x[2]


# ------------------------------------------------------------------ declarations


def test_spans_of_class_component_and_equation() -> None:
    stored = parse_text(SEED, "seed.mo")
    mass = stored.classes[0]
    assert mass.span == Span("seed.mo", 1, 1, 9, 9)  # `;` ends the stored definition item
    assert mass.elements[1].span == Span("seed.mo", 3, 18, 3, 32)  # xy[2] = {0, 0}
    eq = mass.equations[0]
    assert eq.span == Span("seed.mo", 8, 3, 8, 15)
    assert eq.rhs.span == Span("seed.mo", 8, 14, 8, 15)


def test_several_names_in_one_clause() -> None:
    cls = one_class('model A\n  parameter Real[2] a, b(start = 1) "the b", c[3] = x;\nend A;')
    a, b, c = cls.elements
    assert [x.name for x in (a, b, c)] == ["a", "b", "c"]
    assert all(show(x.type_dims[0]) == "2" and x.variability == "parameter" for x in (a, b, c))
    assert a.modification is None and a.description == ""
    assert b.modification.arguments[0].path == ("start",) and b.description == "the b"
    assert [show(d) for d in c.dims] == ["3"] and show(c.modification.value) == "x"
    assert (b.span.line, b.span.column, b.span.end_column) == (2, 24, 44)


def test_prefixes_and_sections() -> None:
    cls = one_class(
        "connector C\n  flow input Real f;\n  final output Real y;\n  discrete Integer n;\n"
        "protected\n  constant Real k = 2;\npublic\n  Real z;\nend C;"
    )
    f, y, n, k, z = cls.elements
    assert (f.flow, f.causality, f.final) == (True, "input", False)
    assert (y.final, y.causality) == (True, "output")
    assert n.variability == "discrete"
    assert (k.variability, k.protected) == ("constant", True)
    assert not z.protected and cls.kind == "connector"


def test_modifications_each_final_dotted_nested() -> None:
    cls = one_class(
        "model A\n  B b[3](each final k = 2 \"desc\", c.d.e = 1, f(g = 3, h(i = 4)) = 5,"
        " start);\nend A;"
    )
    (b,) = cls.elements
    k, cde, f, start = b.modification.arguments
    assert (k.path, k.each, k.final, show(k.modification.value)) == (("k",), True, True, "2")
    assert (cde.path, cde.each, cde.final) == (("c", "d", "e"), False, False)
    assert show(f.modification.value) == "5"
    g, h = f.modification.arguments
    assert g.path == ("g",) and h.modification.arguments[0].path == ("i",)
    assert start.modification is None


def test_extends_with_modification_and_annotations() -> None:
    cls = one_class(
        "partial model A \"a \" + \"model\"\n"
        "  extends Base(k = 2) annotation(Placement());\n"
        "  Real x annotation(Dialog(group = \"g\"));\n"
        "equation\n  x = 1 annotation(Line());\n"
        "  annotation(experiment(StopTime = 5, Interval = 0.1));\nend A;"
    )
    assert cls.partial and cls.description == "a model"
    ext = cls.elements[0]
    assert isinstance(ext, Extends) and ext.base.dotted == "Base"
    assert ext.modification.arguments[0].path == ("k",)
    (experiment,) = cls.annotation.arguments
    assert experiment.path == ("experiment",)
    assert [(a.path[0], show(a.modification.value))
            for a in experiment.modification.arguments] == [("StopTime", "5"), ("Interval", "0.1")]


def test_short_class_definitions() -> None:
    stored = parse_text(
        'package P\n  type Force = Real(unit = "N") "a force";\n  type Vec = Real[2];\n'
        "  model M2 = M(k = 2);\n  connector RealInput = input Real;\nend P;",
        "t.mo",
    )
    force, vec, m2, real_input = stored.classes[0].elements
    assert (force.kind, force.short.base.dotted, force.description) == ("type", "Real", "a force")
    assert force.short.modification.arguments[0].path == ("unit",)
    assert show(force.short.modification.arguments[0].modification.value) == "'N'"
    assert [show(d) for d in vec.short.dims] == ["2"]
    assert (m2.kind, m2.short.base.dotted) == ("model", "M")
    assert (real_input.kind, real_input.short.causality) == ("connector", "input")
    assert all(c.elements == () for c in (force, vec, m2, real_input))


def test_within_and_imports() -> None:
    stored = parse_text(
        "within Lib.Sub;\nencapsulated package P\n  import A.B.C;\n  import D = A.B.C;\n"
        "  import A.B.*;\n  import A.B.{C, D};\nend P;",
        "t.mo",
    )
    assert stored.within == ("Lib", "Sub")
    pkg = stored.classes[0]
    assert pkg.encapsulated and pkg.kind == "package"
    assert [(i.path, i.names, i.alias, i.wildcard) for i in pkg.elements] == [
        (("A", "B"), ("C",), None, False),
        (("A", "B"), ("C",), "D", False),
        (("A", "B"), (), None, True),
        (("A", "B"), ("C", "D"), None, False),
    ]
    assert all(isinstance(i, Import) for i in pkg.elements)
    assert parse_text("within;\nmodel A end A;", "t.mo").within == ()


def test_quoted_identifiers_drop_their_quotes() -> None:
    cls = one_class("model 'my model'\n  Real 'mass.pos[1]' = 'x y';\nend 'my model';")
    assert cls.name == "my model"
    assert cls.elements[0].name == "mass.pos[1]"
    assert cls.elements[0].modification.value.dotted == "x y"


# ------------------------------------------------------------------ equations


def test_for_if_connect_and_call_equations() -> None:
    cls = one_class(
        "model A\nequation\n"
        "  for i in 1:n, j in 1:m loop\n    for k loop x[i, j, k] = 0; end for;\n  end for;\n"
        "  if n > 2 then a = 1; elseif n < 1 then a = 2; else a = 3; b = 4; end if;\n"
        "  connect(p.q, r[1].s);\n  assert(x > 0, \"positive\");\n"
        "initial equation\n  x = 0;\nend A;"
    )
    loop, cond, conn, call = cls.equations
    assert isinstance(loop, ForEquation)
    assert [(i.name, show(i.range)) for i in loop.indices] == [("i", "(1:n)"), ("j", "(1:m)")]
    (inner,) = loop.body
    assert inner.indices[0].range is None and isinstance(inner.body[0], Equality)
    assert isinstance(cond, IfEquation)
    assert [show(c) for c, _ in cond.branches] == ["(n > 2)", "(n < 1)"]
    assert len(cond.otherwise) == 2
    assert isinstance(conn, Connect) and (show(conn.a), show(conn.b)) == ("p.q", "r[1].s")
    assert isinstance(call, CallEquation) and show(call.call) == "assert((x > 0), 'positive')"
    assert [show(e.lhs) for e in cls.initial_equations] == ["x"]


def test_function_with_algorithm() -> None:
    cls = one_class(
        "function f \"doc\"\n  input Real x;\n  output Real y[2];\nprotected\n  Real t;\n"
        "algorithm\n  t := 2*x;\n  (a, , b) := g(x, n = 1);\n"
        "  for i in 1:2 loop\n    if i > 1 then y[i] := t; elseif i < 0 then y[i] := 0;"
        " else y[i] := -t; end if;\n  end for;\nend f;"
    )
    assert (cls.kind, cls.description) == ("function", "doc")
    assert [(c.name, c.causality, c.protected) for c in cls.elements] == [
        ("x", "input", False), ("y", "output", False), ("t", "", True)]
    assign, multi, loop = cls.algorithm
    assert isinstance(assign, Assign) and show(assign.targets[0]) == "t"
    assert [t and show(t) for t in multi.targets] == ["a", None, "b"]
    assert show(multi.value) == "g(x, n=1)"
    assert isinstance(loop, ForStatement) and isinstance(loop.body[0], IfStatement)
    assert len(loop.body[0].branches) == 2 and len(loop.body[0].otherwise) == 1


# ------------------------------------------------------------------ errors


def test_missing_semicolon() -> None:
    assert error_text("model A\n  Real x\n  Real y;\nend A;\n") == (
        "t.mo:3:3: error: unexpected identifier 'Real', expected one of: "
        "';', ',', '=', '(', '[', ...\n"
        "    3 |   Real y;\n"
        "      |   ^^^^\n"
        "help: a ';' may be missing at the end of line 2"
    )
    assert error_text("model A\nequation\n  x = 1\nend A;\n") == (
        "t.mo:4:1: error: unexpected 'end', expected one of: "
        "';', 'annotation', string, an operator\n"
        "    4 | end A;\n"
        "      | ^^^\n"
        "help: a ';' may be missing at the end of line 3"
    )


def test_unexpected_end_of_file() -> None:
    assert error_text("model A\n  Real x = (1 +") == (
        "t.mo:2:16: error: unexpected end of file, expected one of: "
        "'(', '[', identifier, '{', 'false', ...\n"
        "    2 |   Real x = (1 +\n"
        "      |                ^"
    )


def test_when_equation_keeps_its_branches_in_order() -> None:
    from springc.ir.syntax import WhenEquation

    text = ("model A\n  Real x;\nequation\n  when x > 1 then\n    reinit(x, 0);\n"
            "  elsewhen x < -1 then\n    reinit(x, 1);\n  end when;\nend A;")
    (cls,) = parse_text(text, "t.mo").classes
    (when,) = [e for e in cls.equations if isinstance(e, WhenEquation)]
    assert [(c.op, len(body)) for c, body in when.branches] == [(">", 1), ("<", 1)]
    assert (when.span.line, when.span.column) == (4, 3)


def test_mismatched_end_name() -> None:
    assert error_text("model A\n  Real x;\nend B;\n") == (
        "t.mo:3:5: error: class 'A' ends with 'end B'\n"
        "    3 | end B;\n"
        "      |     ^\n"
        "t.mo:1:1: note: class 'A' starts here\n"
        "    1 | model A\n"
        "      | ^^^^^^^\n"
        "help: write 'end A;'"
    )


def test_unterminated_string_and_comment() -> None:
    assert error_text('model A\n  Real x "abc;\nend A;\n') == (
        "t.mo:2:10: error: unterminated string\n"
        '    2 |   Real x "abc;\n'
        "      |          ^\n"
        "help: a string ends with '\"'"
    )
    assert error_text("model A\n  /* Real x;\nend A;\n") == (
        "t.mo:2:3: error: unterminated comment\n"
        "    2 |   /* Real x;\n"
        "      |   ^^\n"
        "help: a '/*' comment ends with '*/'"
    )
    assert error_text("model A Real 'x; end A;").startswith(
        "t.mo:1:14: error: unterminated quoted identifier")


def test_misplaced_unary_and_chained_operators() -> None:
    text = "model A\n  Real x = a * -b;\n  Real y = a < b < c;\n  Real z = a^b^c;\nend A;"
    assert error_text(text) == (
        "t.mo:2:16: error: unexpected '-'\n"
        "    2 |   Real x = a * -b;\n"
        "      |                ^\n"
        "help: a unary '-' may only start an expression or an operand of a comparison; "
        "put it in parentheses, e.g. a * (-b)\n\n"
        "t.mo:3:18: error: unexpected '<'\n"
        "    3 |   Real y = a < b < c;\n"
        "      |                  ^\n"
        "help: comparisons cannot be chained; combine them with `and`\n\n"
        "t.mo:4:15: error: unexpected '^'\n"
        "    4 |   Real z = a^b^c;\n"
        "      |               ^\n"
        "help: '^' is not associative; add parentheses: (a^b)^c or a^(b^c)\n\n"
        "3 errors"
    )


def test_other_lexical_and_syntax_errors() -> None:
    assert error_text("model A Real x @; end A;").startswith(
        "t.mo:1:16: error: unexpected character '@'")
    assert error_text('model A Real x "a\\d"; end A;').startswith(
        "t.mo:1:16: error: invalid escape '\\d'")
    assert error_text("model A Real end; end A;").startswith(
        "t.mo:1:14: error: 'end' is a reserved word and cannot be used as a name")
    assert error_text("model A equation x + 1; end A;").startswith(
        "t.mo:1:18: error: this expression is not an equation")
    assert error_text("model A Real x = f(a = 1, 2); end A;").startswith(
        "t.mo:1:27: error: positional argument after a named argument")
    assert error_text("model A Real x = {end}; end A;").startswith(
        "t.mo:1:19: error: `end` may only be used inside array subscripts such as x[end]")
    assert error_text("function f equation x = 1; end f;").startswith(
        "t.mo:1:12: error: a function cannot have an `equation` section")
    assert error_text("function f initial algorithm end f;").startswith(
        "t.mo:1:12: error: a function cannot have an `initial algorithm` section")
    with pytest.raises(ParseError, match="unexpected end of file"):
        parse_expression("1 +")


UNSUPPORTED = [
    ("connector C stream Real h; end C;", "`stream` connectors are"),
    ("operator record R end R;", "`operator` classes are"),
    ("impure function f end f;", "`impure` functions are"),
    ("model A Real x = (y)[1]; end A;", "subscripts on a parenthesized expression (`(e)[i]`) are"),
    ("model A Real x := 1; end A;", "`:=` in a declaration is"),
]


@pytest.mark.parametrize(("text", "what"), UNSUPPORTED)
def test_unsupported_constructs_are_rejected(text: str, what: str) -> None:
    with pytest.raises(ParseError) as info:
        parse_text(text, "t.mo")
    assert info.value.message == f"{what} not supported yet"
    assert info.value.span is not None and info.value.span.line == 1


def test_all_unsupported_constructs_are_reported_together() -> None:
    text = (
        "model A\n  Real y;\n  stream Real h;\nend A;\n"
        "impure function f\nend f;\n"
    )
    with pytest.raises(ErrorGroup) as info:
        parse_text(text, "t.mo")
    assert [(e.message, e.span.line, e.span.column) for e in info.value.errors] == [
        ("`stream` connectors are not supported yet", 3, 3),
        ("`impure` functions are not supported yet", 5, 1),
    ]


def test_parse_file_reads_and_reports_unreadable(tmp_path: Path) -> None:
    path = tmp_path / "A.mo"
    path.write_text("model A\n  Real x;\nend A;\n", encoding="utf-8")
    stored = parse_file(path)
    assert stored.file == str(path) and stored.classes[0].span.file == str(path)
    with pytest.raises(LoadError, match="cannot read"):
        parse_file(tmp_path / "missing.mo")


def test_empty_quoted_identifier_is_named_as_such() -> None:
    assert error_text("model A Real ''; end A;") == (
        "t.mo:1:14: error: empty quoted identifier\n"
        "    1 | model A Real ''; end A;\n"
        "      |              ^^\n"
        "help: a quoted identifier has at least one character: 'x'")


def test_numbers_beyond_the_double_range_are_errors() -> None:
    with pytest.raises(ErrorGroup) as group:
        parse_text("model A\n  Real x = 1e309 + 2E400;\nend A;", "t.mo")
    assert [(e.message, e.span) for e in group.value.errors] == [
        ("the number 1e309 is too large", Span("t.mo", 2, 12, 2, 17)),
        ("the number 2E400 is too large", Span("t.mo", 2, 20, 2, 25))]
    number = parse_expression("1" + "0" * 300)  # an integer literal in range stays exact
    assert isinstance(number, Number) and number.value == 10**300


def test_end_cannot_be_called() -> None:
    assert error_text("model A\n  Real x[end(2)];\nend A;") == (
        "t.mo:2:10: error: 'end' cannot be called\n"
        "    2 |   Real x[end(2)];\n"
        "      |          ^^^\n"
        "help: call a function by its name, e.g. size(x, 1)")


def test_global_names_in_types_and_expressions() -> None:
    stored = parse_text("model A\n  .P.B b;\n  Real x = .P.c + y;\nend A;\n", "g.mo")
    b, x = stored.classes[0].elements
    assert isinstance(b, Component) and isinstance(x, Component)
    assert b.type_name.is_global and [p.name for p in b.type_name.parts] == ["P", "B"]
    assert (b.type_name.span.line, b.type_name.span.column) == (2, 3)
    value = x.modification.value if x.modification else None
    assert isinstance(value, Binary) and isinstance(value.left, Ref)
    assert value.left.is_global and value.left.dotted == "P.c"
    assert isinstance(value.right, Ref) and not value.right.is_global
