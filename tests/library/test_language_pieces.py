"""The language pieces real libraries use: enumerations (4.9.5), inner/outer (5.4),
conditional components (4.4.5), replaceable/redeclare/constrainedby (7.3), partial
classes, StateSelect parameters; and the regressions of issue 12 (lookup through
``extends``, an unselected if-branch, a construct the model does not use)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SpringcError
from springc.ir.flat import format_flat
from springc.pipeline import flatten_files


@pytest.fixture(autouse=True)
def _no_environment_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("MODELICAPATH", raising=False)


def flat(tmp_path: Path, text: str, model: str | None = None) -> str:
    path = tmp_path / "M.mo"
    path.write_text(text)
    return format_flat(flatten_files([path], model))


def error(tmp_path: Path, text: str, model: str | None = None) -> tuple[str, int, int]:
    with pytest.raises(SpringcError) as info:
        flat(tmp_path, text, model)
    span = info.value.span
    assert span is not None
    return info.value.message, span.line, span.column


ENUMS = """model E
  type Mode = enumeration(off "not running", slow, fast) "a mode";
  parameter Mode mode = Mode.fast;
  parameter Integer k = Integer(mode);
  parameter Boolean quick = mode == Mode.fast;
  parameter StateSelect sel = StateSelect.prefer;
  Real x(start = 1, stateSelect = sel);
equation
  der(x) = if mode > Mode.slow then -2 * x else -x;
end E;
"""


def test_enumerations_literals_comparisons_and_integer(tmp_path: Path) -> None:
    assert flat(tmp_path, ENUMS) == (
        "model E\n  parameter Integer mode = 3;\n  parameter Integer k = mode;\n"
        "  parameter Boolean quick = mode == 3;\n  parameter Integer sel = 4;\n"
        "  Real x(start = 1, stateSelect = StateSelect.prefer);\nequation\n"
        "  der(x) = if mode > 2 then -2 * x else -x;\nend E;\n")


def test_enumeration_parameter_selects_the_dynamics() -> None:
    model = springc.load_model_from_string(ENUMS, cache=False)
    result = springc.simulate(model, stop=1.0, interval=0.01, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(result["x"] - np.exp(-2 * result.time))) < 1e-8


def test_unknown_enumeration_literal(tmp_path: Path) -> None:
    text = "model E\n  type Mode = enumeration(a, b);\n  parameter Mode m = Mode.c;\nend E;\n"
    assert error(tmp_path, text) == ("enumeration 'E.Mode' has no literal 'c'", 3, 27)


WORLD = """package W
  model World
    parameter Real g = 9.81;
  end World;
  model Ball
    outer World world;
    Real h(start = 10, fixed = true);
    Real v(start = 0, fixed = true);
  equation
    der(h) = v;
    der(v) = -world.g;
  end Ball;
  model Group
    Ball b;
  end Group;
  model Scene
    inner World world(g = 2);
    Group group;
    Ball ball;
  end Scene;
  model Lonely
    Ball ball;
  end Lonely;
end W;
"""


def test_outer_elements_at_several_depths_refer_to_the_inner_one(tmp_path: Path) -> None:
    text = flat(tmp_path, WORLD, "W.Scene")
    assert "  der('group.b.v') = -'world.g';" in text.splitlines()
    assert "  der('ball.v') = -'world.g';" in text.splitlines()
    assert "  parameter Real 'world.g' = 2;" in text.splitlines()
    assert "group.b.world" not in text


def test_an_outer_element_without_inner_gets_one_at_the_top(tmp_path: Path) -> None:
    """Section 5.4: an inner element of the outer element's class is added, with a
    diagnostic; the ball then falls with the World's default g."""
    path = tmp_path / "M.mo"
    path.write_text(WORLD)
    model = flatten_files([path], "W.Lonely")
    assert "  parameter Real 'world.g' = 9.81;" in format_flat(model).splitlines()
    assert model.notes == (
        f"{path}:6:17: warning: the outer element 'world' has no inner element: `inner "
        "World world` is added at the top of the model (Modelica 3.6, section 5.4)",)


def test_an_outer_element_of_a_partial_class_without_inner_is_an_error(
        tmp_path: Path) -> None:
    message = "the outer element 'ball.world' has no inner element 'world' in an " \
              "enclosing instance"
    text = WORLD.replace("  model World", "  partial model World")
    assert error(tmp_path, text, "W.Lonely") == (message, 6, 17)


def test_outer_gravity_simulates() -> None:
    model = springc.load_model_from_string(WORLD, "W.Scene", cache=False)
    result = springc.simulate(model, stop=1.0, interval=0.01, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(result["group.b.h"] - (10 - result.time ** 2))) < 1e-9


CONDITIONAL = """package C
  connector Pin
    Real v;
    flow Real i;
  end Pin;
  model Source
    parameter Boolean useGround = true;
    Pin p;
    Pin ground if useGround;
  equation
    p.v = 2;
  end Source;
  model Load
    Pin p;
  equation
    p.v = 4 * p.i;
  end Load;
  model Circuit
    parameter Boolean grounded = false;
    Source source(useGround = grounded);
    Load load;
    Pin earth;
  equation
    connect(source.p, load.p);
    connect(source.ground, earth);
    earth.v = 0;
  end Circuit;
  model Bad
    parameter Boolean b = false;
    Real x = 1 if b;
    Real y = x;
  end Bad;
  model Varying
    Boolean on = true;
    Real x = 1 if on;
  end Varying;
end C;
"""


def test_a_disabled_component_and_its_connections_are_dropped(tmp_path: Path) -> None:
    text = flat(tmp_path, CONDITIONAL, "C.Circuit")
    assert "source.ground" not in text
    assert "  'earth.i' = 0;" in text.splitlines()


def test_an_enabled_component_is_connected(tmp_path: Path) -> None:
    text = flat(tmp_path, CONDITIONAL.replace("grounded = false", "grounded = true"),
                "C.Circuit")
    assert "  'source.ground.v' = 'earth.v';" in text.splitlines()
    # earth is a connector of the model itself: an outside connector, counted negative.
    assert "  'source.ground.i' - 'earth.i' = 0;" in text.splitlines()


def test_a_disabled_component_used_in_an_equation_is_an_error(tmp_path: Path) -> None:
    assert error(tmp_path, CONDITIONAL, "C.Bad") == (
        "the conditional component 'x' is used outside a connect equation", 31, 14)


def test_the_condition_must_be_a_parameter_expression(tmp_path: Path) -> None:
    message, line, column = error(tmp_path, CONDITIONAL, "C.Varying")
    assert message.startswith("the condition of a conditional component must be a "
                              "parameter expression")
    assert (line, column) == (35, 19)
    assert message.endswith("but it depends on the variable 'on'")


REDECLARE = """package R
  model Iron
    parameter Real k = 1;
    Real x(start = 1, fixed = true);
  equation
    der(x) = -k * x;
  end Iron;
  model Steel
    parameter Real k = 3;
    parameter Real extra = 0;
    Real x(start = 1, fixed = true);
  equation
    der(x) = -k * x + extra;
  end Steel;
  model Holder
    replaceable Iron part constrainedby Iron(k = 5);
    replaceable model Kind = Iron;
    Kind other;
  end Holder;
  model Plain
    Holder h;
  end Plain;
  model Swapped
    Holder h(redeclare Steel part(extra = 1), redeclare model Kind = Steel(k = 7));
  end Swapped;
  model Inherited
    extends Holder(redeclare Steel part);
  end Inherited;
  model Fixed
    Iron part;
  end Fixed;
  model Wrong
    Fixed f(redeclare Steel part);
  end Wrong;
  package Unused
    replaceable model M = Iron;
    replaceable package Medium = Unused;
  end Unused;
end R;
"""


def test_a_replaceable_component_keeps_its_type_until_redeclared(tmp_path: Path) -> None:
    text = flat(tmp_path, REDECLARE, "R.Plain")
    # the constraining clause's modifier (k = 5) applies to the declaration too (7.3.2)
    assert "  parameter Real 'h.part.k' = 5;" in text.splitlines()
    assert "  parameter Real 'h.other.k' = 1;" in text.splitlines()


def test_redeclared_component_and_class_with_modifiers(tmp_path: Path) -> None:
    lines = flat(tmp_path, REDECLARE, "R.Swapped").splitlines()
    # The constraining clause's modifier (k = 5) applies to the new component.
    assert "  parameter Real 'h.part.k' = 5;" in lines
    assert "  parameter Real 'h.part.extra' = 1;" in lines
    assert "  parameter Real 'h.other.k' = 7;" in lines
    assert "  parameter Real 'h.other.extra' = 0;" in lines


def test_redeclare_in_an_extends_clause(tmp_path: Path) -> None:
    lines = flat(tmp_path, REDECLARE, "R.Inherited").splitlines()
    assert "  parameter Real 'part.extra' = 0;" in lines


def test_redeclaring_a_component_that_is_not_replaceable(tmp_path: Path) -> None:
    assert error(tmp_path, REDECLARE, "R.Wrong") == (
        "'f.part' is not replaceable and cannot be redeclared", 33, 13)


def test_redeclared_component_simulates() -> None:
    model = springc.load_model_from_string(REDECLARE, "R.Swapped", cache=False)
    result = springc.simulate(model, stop=1.0, interval=0.01, rtol=1e-10, atol=1e-12)
    t = result.time
    # der(x) = -5 x + 1: x = 1/5 + (4/5) exp(-5 t).
    assert np.max(np.abs(result["h.part.x"] - (0.2 + 0.8 * np.exp(-5 * t)))) < 1e-8
    assert np.max(np.abs(result["h.other.x"] - np.exp(-7 * t))) < 1e-8


def test_instantiating_a_partial_class_is_an_error(tmp_path: Path) -> None:
    text = ("model M\n  partial model P\n    Real x;\n  end P;\n  P p;\nend M;\n")
    assert error(tmp_path, text) == (
        "'p' is of the partial class 'M.P', which cannot be instantiated", 5, 5)


def test_encapsulated_and_partial_packages_parse_and_flatten(tmp_path: Path) -> None:
    text = ("encapsulated package Lib\n  partial model Base\n    parameter Real k = 2;\n"
            "  end Base;\n  model Impl\n    extends Base;\n    Real x = k;\n  end Impl;\n"
            "end Lib;\nmodel M\n  Lib.Impl i;\nend M;\n")
    assert flat(tmp_path, text, "M") == (
        "model M\n  parameter Real 'i.k' = 2;\n  Real 'i.x';\nequation\n  'i.x' = 'i.k';\n"
        "end M;\n")


# ------------------------------------------------------------ issue 12's regressions


EXTENDS_LOOKUP = """package P
  package Base
    constant Real c = 2;
    function f
      input Real u;
      output Real y;
    algorithm
      y := c * u;
    end f;
    model M
      Real x = f(time) + c;
    end M;
  end Base;
  package Derived
    extends Base;
  end Derived;
  model Use
    Derived.M m;
    Real z = Derived.f(1) + Derived.c;
  end Use;
  model Select
    parameter Integer n = 2;
    parameter Real a[2] = {1, 2};
    Real y = if n > 2 then a[3] else a[n];
    Real w = if n <= 2 then a[n] else a[n + 1];
  end Select;
end P;
"""


def test_names_inside_an_inherited_class_are_looked_up_where_it_is_defined(
        tmp_path: Path) -> None:
    assert flat(tmp_path, EXTENDS_LOOKUP, "P.Use") == (
        "model 'P.Use'\n  Real 'm.x';\n  Real z;\nequation\n  'm.x' = 2 * time + 2;\n"
        "  z = 4;\nend 'P.Use';\n")


def test_an_index_in_an_unselected_if_branch_is_not_evaluated(tmp_path: Path) -> None:
    lines = flat(tmp_path, EXTENDS_LOOKUP, "P.Select").splitlines()
    assert "  y = 'a[2]';" in lines
    assert "  w = 'a[2]';" in lines
    # Where the branch may be selected, the index is an error.
    wrong = EXTENDS_LOOKUP.replace("parameter Integer n = 2;", "parameter Integer n = 3;") \
        .replace("    Real w = if n <= 2 then a[n] else a[n + 1];\n", "")
    assert error(tmp_path, wrong, "P.Select") == (
        "index 3 is out of range for 'a' of size 2", 24, 30)


def test_unused_replaceable_classes_do_not_block_the_model(tmp_path: Path) -> None:
    assert "  parameter Real 'part.k' = 1;" in flat(tmp_path, REDECLARE,
                                                  "R.Fixed").splitlines()


UNSUPPORTED = """package L
  model Bad
    Real x;
    Real y;
    Real z := 1;
  equation
    der(x) = 1;
    y = 1;
  end Bad;
  model Good
    Real x(start = 0, fixed = true);
  equation
    der(x) = 1;
  end Good;
  model UsesBad
    Bad b;
  end UsesBad;
end L;
"""


def test_a_construct_outside_the_subset_blocks_only_the_models_that_use_it(
        tmp_path: Path) -> None:
    assert flat(tmp_path, UNSUPPORTED, "L.Good") == (
        "model 'L.Good'\n  Real x(start = 0, fixed = true);\nequation\n  der(x) = 1;\n"
        "end 'L.Good';\n")
    assert error(tmp_path, UNSUPPORTED, "L.UsesBad") == (
        "`:=` in a declaration is not supported yet", 5, 12)
    with pytest.raises(SpringcError) as info:
        flat(tmp_path, UNSUPPORTED, "L.UsesBad")
    (note,) = info.value.notes
    assert note.message == "'b' uses class 'L.Bad' here"
    assert note.span is not None and (note.span.line, note.span.column) == (16, 9)


def test_string_parameters_and_constants(tmp_path: Path) -> None:
    text = ("model S\n  parameter String name = \"mass\";\n  constant String u = \"m\";\n"
            "  Real x(unit = u, start = 1);\nequation\n  der(x) = -x;\nend S;\n")
    assert flat(tmp_path, text) == (
        "model S\n  Real x(start = 1, unit = \"m\");\nequation\n  der(x) = -x;\nend S;\n")
    bad = text.replace("parameter String name = \"mass\";", "parameter String name = 1;")
    assert error(tmp_path, bad) == ("'name' is a String and must be given a string", 2, 27)


def test_redeclare_as_an_element_replaces_the_inherited_declaration(tmp_path: Path) -> None:
    text = ("package R\n  model Iron\n    parameter Real k = 1;\n  end Iron;\n"
            "  model Steel\n    parameter Real k = 3;\n    parameter Real extra = 0;\n"
            "  end Steel;\n  model Holder\n    replaceable Iron part;\n    Iron fixed;\n"
            "  end Holder;\n  model Elem\n    extends Holder;\n"
            "    redeclare Steel part(extra = 2);\n  end Elem;\n  model Wrong\n"
            "    extends Holder;\n    redeclare Steel fixed;\n  end Wrong;\nend R;\n")
    lines = flat(tmp_path, text, "R.Elem").splitlines()
    assert "  parameter Real 'part.k' = 3;" in lines
    assert "  parameter Real 'part.extra' = 2;" in lines
    assert error(tmp_path, text, "R.Wrong") == (
        "'fixed' is not replaceable and cannot be redeclared", 19, 21)


def test_a_for_loop_over_an_enumeration_type(tmp_path: Path) -> None:
    text = ("model E1\n  type E = enumeration(a, b, c);\n  Real x[3];\nequation\n"
            "  for e in E loop\n    x[Integer(e)] = Integer(e);\n  end for;\nend E1;\n")
    assert flat(tmp_path, text).splitlines()[-4:] == [
        "  'x[1]' = 1;", "  'x[2]' = 2;", "  'x[3]' = 3;", "end E1;"]


def test_an_outer_element_cannot_be_modified(tmp_path: Path) -> None:
    text = ("model E2\n  model W\n    Real g = 1;\n  end W;\n  model B\n"
            "    outer W w(g = 2);\n  end B;\n  inner W w;\n  B b;\nend E2;\n")
    assert error(tmp_path, text) == ("the outer element 'b.w' cannot be modified", 6, 14)


def test_a_class_redeclared_as_an_element_of_an_extending_class(tmp_path: Path) -> None:
    text = ("package R\n  model C\n    Real x = 1;\n  end C;\n  model D\n    Real x = 2;\n"
            "    Real z = 3;\n  end D;\n  model B\n    replaceable model M = C;\n    M m;\n"
            "  end B;\n  model E\n    extends B;\n    redeclare model M = D(z = 4);\n"
            "  end E;\n  model Top\n    E e;\n  end Top;\nend R;\n")
    assert flat(tmp_path, text, "R.Top") == (
        "model 'R.Top'\n  Real 'e.m.x';\n  Real 'e.m.z';\nequation\n  'e.m.x' = 2;\n"
        "  'e.m.z' = 4;\nend 'R.Top';\n")
