"""Equation templates (springc.flatten.equation_templates): reused only where every
instance of a class has the same equations up to its prefix; otherwise each instance
is flattened."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.flatten.equation_templates import make_template, renamer
from springc.ir import expr as x
from springc.ir.flat import format_equation
from springc.pipeline.files import flatten_files


def equations(tmp_path: Path, source: str) -> list[str]:
    path = tmp_path / "m.mdl"
    path.write_text(source)
    return [format_equation(eq) for eq in flatten_files([path]).equations]


def test_renamer_swaps_the_instance_prefix() -> None:
    rename = renamer("s[1]", "s[12]")
    e = x.BinOp("*", x.Var("s[1].k"), x.Der(x.Var("s[1].x[2]")))
    assert rename(e) == x.BinOp("*", x.Var("s[12].k"), x.Der(x.Var("s[12].x[2]")))
    assert rename(x.Call("sqrt", (x.Var("s[1].y"), x.TIME))) == \
        x.Call("sqrt", (x.Var("s[12].y"), x.TIME))


def test_no_template_when_a_variable_lies_outside_the_instance() -> None:
    from springc.errors import Span
    from springc.ir.flat import Equation, Origin

    span = Span("m.mdl", 1, 1, 1, 1)
    eq = Equation(x.Var("a.x"), x.Var("b.x"), span, Origin("equation", "a"))
    assert make_template("a", [eq]) is None
    assert make_template("a", [Equation(x.Var("a.x"), x.ZERO, span, eq.origin)]) is not None


def test_reused_equations_are_renamed_per_instance(tmp_path: Path) -> None:
    eqs = equations(tmp_path, """
model M
  model A
    parameter Real k = 1;
    Real x[2];
  equation
    x = {k, 2 * k} * time;
  end A;
  A a[3](k = {1, 2, 3});
end M;
""")
    assert eqs == [f"'a[{i}].x[{j}]' = {'2 * ' if j == 2 else ''}'a[{i}].k' * time;"
                   for i in (1, 2, 3) for j in (1, 2)]


@pytest.mark.parametrize("declaration, expected", [
    # a loop range read from a parameter: instances differ in their equations
    ("parameter Integer n = 1; Real x[2]; equation for i in 1:n loop x[i] = time; "
     "end for; x[2] = 0;",
     ["'a1.x[1]' = time;", "'a1.x[2]' = 0;",
      "'a2.x[1]' = time;", "'a2.x[2]' = time;", "'a2.x[2]' = 0;"]),
    # a constant is folded, and may be modified per instance
    ("constant Real c = 1; Real x[2]; equation x = {c, c} * time;",
     ["'a1.x[1]' = time;", "'a1.x[2]' = time;",
      "'a2.x[1]' = 2 * time;", "'a2.x[2]' = 2 * time;"]),
])
def test_instance_dependent_classes_are_flattened_per_instance(
        tmp_path: Path, declaration: str, expected: list[str]) -> None:
    modification = "n = 2" if "Integer n" in declaration else "c = 2"
    eqs = equations(tmp_path, f"""
model M
  model A
    {declaration}
  end A;
  A a1;
  A a2({modification});
end M;
""")
    assert eqs == expected
