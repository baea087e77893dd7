"""``class extends`` and long class redeclarations (Modelica 3.6, sections 7.3.1 and
7.3.3), replaceable packages seen from the instances that redeclare them, and
packages defined by a modification: exact flat models of valid models, exact errors of
invalid ones."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome
from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files


def flat(tmp_path: Path, text: str) -> str:
    path = tmp_path / "m.mo"
    path.write_text(text)
    return format_flat(flatten_files([path]))


def test_redeclare_class_extends_adds_to_the_inherited_class(tmp_path: Path) -> None:
    """The modification after `extends B` applies; the inherited component inA is of
    the new B (`redeclare`), and so is b, whose own modification wins."""
    assert flat(tmp_path, """model M
  model A
    replaceable model B
      parameter Real k = 1;
      Real x = k;
    end B;
    B inA;
  end A;
  extends A;
  redeclare model extends B(k = 2)
    Real y = 2 * x;
  end B;
  B b(k = 3);
end M;
""") == """model M
  parameter Real 'inA.k' = 2;
  Real 'inA.x';
  Real 'inA.y';
  parameter Real 'b.k' = 3;
  Real 'b.x';
  Real 'b.y';
equation
  'inA.x' = 'inA.k';
  'inA.y' = 2 * 'inA.x';
  'b.x' = 'b.k';
  'b.y' = 2 * 'b.x';
end M;
"""


def test_a_chain_of_class_extends(tmp_path: Path) -> None:
    assert flat(tmp_path, """model M
  model A
    replaceable model C
      Real x = 1;
    end C;
  end A;
  model B
    extends A;
    replaceable model extends C
      Real y = 2;
    end C;
  end B;
  extends B;
  model extends C
    Real z = 3;
  end C;
  C c;
end M;
""") == """model M
  Real 'c.x';
  Real 'c.y';
  Real 'c.z';
equation
  'c.x' = 1;
  'c.y' = 2;
  'c.z' = 3;
end M;
"""


def test_packages_redeclared_in_instances(tmp_path: Path) -> None:
    """Medium.Props and Medium.n in Vessel are those of Three, passed on through Plant;
    Props, inherited by Three from Two, sees Three's n = 3."""
    assert flat(tmp_path, """model M
  package Base
    constant Integer n = 1;
    replaceable partial model Props
      Real v[n];
    end Props;
  end Base;
  package Two
    extends Base(n = 2);
    redeclare model extends Props
    equation
      v = fill(time, n);
    end Props;
  end Two;
  package Three
    extends Two(n = 3);
  end Three;
  model Vessel
    replaceable package Medium = Base;
    Medium.Props props;
    Real total = sum(props.v) + Medium.n;
  end Vessel;
  model Plant
    replaceable package Medium = Base;
    Vessel vessel(redeclare package Medium = Medium);
  end Plant;
  Plant plant(redeclare package Medium = Three);
  package Short = Two(n = 7);
  parameter Integer seven = Short.n;
end M;
""") == """model M
  Real 'plant.vessel.props.v[1]';
  Real 'plant.vessel.props.v[2]';
  Real 'plant.vessel.props.v[3]';
  Real 'plant.vessel.total';
  parameter Integer seven = 7;
equation
  'plant.vessel.total' = 'plant.vessel.props.v[1]' + 'plant.vessel.props.v[2]' + \
'plant.vessel.props.v[3]' + 3;
  'plant.vessel.props.v[1]' = time;
  'plant.vessel.props.v[2]' = time;
  'plant.vessel.props.v[3]' = time;
end M;
"""


def test_extending_a_class_a_short_package_redeclares(tmp_path: Path) -> None:
    assert flat(tmp_path, """model M
  package P
    replaceable model A
      Integer x = 2;
    end A;
  end P;
  model B
    Integer x = 3;
  end B;
  package P2 = P(redeclare model A = B);
  extends P2.A;
end M;
""") == "model M\n  discrete Integer x;\nequation\n  x = 3;\nend M;\n"


EXTENDS_HELP = ("help: `class extends M` extends the class M that the enclosing class "
                "inherits, which must be replaceable there (Modelica 3.6, section 7.3.1)")
REDECLARE_HELP = ("help: only a replaceable, non-final class can be redeclared, and it "
                  "stays public or protected (Modelica 3.6, section 7.3.3)")
INHERITED_B = """model M
  model A
    {prefix}model B
      Real x = 1;
    end B;
  end A;
  extends A;
{section}  {redeclare}model {extends}B
    Real y = 2;
  end B;
  B b;
end M;
"""


def _model(prefix: str = "replaceable ", section: str = "", redeclare: str = "redeclare ",
           extends: str = "") -> str:
    return INHERITED_B.format(prefix=prefix, section=section, redeclare=redeclare,
                              extends=extends)


CASES = {
    "class_extends_of_a_class_not_replaceable": (
        _model(prefix="", redeclare="", extends="extends "),
        f"8:9: `class extends B` extends 'M.A.B', which is not replaceable\n{EXTENDS_HELP}"),
    "class_extends_of_a_name_not_inherited": (
        "model M\n  model extends B\n    Real y = 2;\n  end B;\n  B b;\nend M;\n",
        f"2:9: `class extends B`: 'M' inherits no class named 'B'\n{EXTENDS_HELP}"),
    "final_class_redeclared": (
        _model(prefix="final replaceable "),
        f"8:13: the final class 'B' cannot be redeclared\n{REDECLARE_HELP}"),
    "class_not_replaceable_redeclared": (
        _model(prefix=""),
        f"8:13: 'B' is not replaceable and cannot be redeclared\n{REDECLARE_HELP}"),
    "public_class_redeclared_protected": (
        _model(section="protected\n"),
        f"9:13: the public class 'B' cannot be redeclared protected\n{REDECLARE_HELP}"),
    "nothing_inherited_to_redeclare": (
        "model M\n  redeclare model B\n    Real x = 3;\n  end B;\nend M;\n",
        "2:13: 'B' is redeclared but no inherited class has that name\nhelp: redeclare a "
        "class of a base class, or drop `redeclare`"),
    "class_extends_without_redeclare_keeps_inherited_components": (
        _model(redeclare="", extends="extends ").replace(
            "    end B;\n  end A;", "    end B;\n    B inA;\n  end A;").replace(
            "end M;", "  Real z = inA.y;\nend M;"),
        "13:16: 'inA' (of class 'M.A.B') has no element 'y'\nhelp: None"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_class_redeclaration_errors(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


def test_classes_extending_a_predefined_type(tmp_path: Path) -> None:
    """A type extending Real with a modification, a connector extending a short type
    with a prefix: both read as short definitions (section 4.5.2)."""
    assert flat(tmp_path, """model M
  type Length
    extends Real(unit = "m");
  end Length;
  type Out = output Real;
  connector Signal
    extends Out;
  end Signal;
  Length l = 2 * time;
  Signal s = l;
end M;
""") == ('model M\n  Real l(unit = "m");\n  output Real s;\nequation\n  l = 2 * time;\n'
         "  s = l;\nend M;\n")


def test_an_inherited_declaration_sees_the_package_its_base_is_named_through(
        tmp_path: Path) -> None:
    """v[n] is written in Base.Props; Air extends it as Two.Props, so n is Two's (2);
    Air's own text may not use n (it is not visible there)."""
    text = """model M
  package Base
    constant Integer n = 1;
    partial model Props
      Real v[n];
    end Props;
  end Base;
  package Two
    extends Base(n = 2);
  end Two;
  model Air
    extends Two.Props;
  equation
    v = fill(time, 2);
  end Air;
  Air air;
end M;
"""
    assert flat(tmp_path, text) == ("model M\n  Real 'air.v[1]';\n  Real 'air.v[2]';\n"
                                    "equation\n  'air.v[1]' = time;\n  'air.v[2]' = time;\n"
                                    "end M;\n")
    assert outcome(tmp_path, text.replace("fill(time, 2)", "fill(time, n)")) == (
        "5:14: undefined name 'n'\nhelp: declare it, or check the spelling")


def test_a_function_redeclared_in_an_instance(tmp_path: Path) -> None:
    """f1() in B calls f2, which B's extends clause puts in place of f1."""
    assert flat(tmp_path, """model M
  model A
    replaceable function f1
      output Integer x;
    algorithm
      x := 1;
    end f1;
    Integer inside = f1();
  end A;
  model B
    extends A(redeclare function f1 = f2);
  protected
    function f2
      output Integer x;
    algorithm
      x := 2;
    end f2;
  end B;
  B b;
end M;
""") == "model M\n  discrete Integer 'b.inside';\nequation\n  'b.inside' = 2;\nend M;\n"


def test_a_modification_of_an_inherited_class(tmp_path: Path) -> None:
    """`extends A(B(x = 4))` modifies the class B: every component of type B (here a
    protected one, and an array) has x = 4 unless it modifies x itself."""
    assert flat(tmp_path, """model M
  model A
  protected
    model B
      Real x = 2;
    end B;
    B b;
    B c[2](each x = 5);
  end A;
  extends A(B(x = 4));
end M;
""") == ("model M\n  Real 'b.x';\n  Real 'c[1].x';\n  Real 'c[2].x';\nequation\n"
         "  'b.x' = 4;\n  'c[1].x' = 5;\n  'c[2].x' = 5;\nend M;\n")


def test_a_protected_class_modified_from_outside(tmp_path: Path) -> None:
    assert outcome(tmp_path, """model M
  model A
  protected
    model B
      Real x = 2;
    end B;
    B b;
  end A;
  A a(B(x = 4));
end M;
""") == ("9:7: class 'B' is protected in 'M.A' and cannot be modified in 'a'\nhelp: a "
         "protected element may be modified only by its own declaration or by an extends "
         "clause (Modelica 3.6, section 4.1)")
