"""ModelicaStandardTables evaluated natively (flatten/natives/tables.py and
interpolation.py).

``models/MslTables.mo`` declares the table classes and functions under the names and
external C functions of the Modelica Standard Library 4.1.0. Every expected number is
worked out by hand from the formulas the library documents: the table
``[0, 0; 1, 1; 2, 4; 4, 16]`` of CombiTable1D's documentation (u = 1.5 gives 2.5,
u = -1 gives -1), and ``y = x^2`` sampled at 0, 1, 2, 3 for the cubic Hermite splines.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SpringcError
from springc.ir import expr as x
from springc.pipeline.files import flatten_files

MODELS = Path(__file__).parent / "models"
LIBRARY = MODELS / "MslTables.mo"
DOC_TABLE = "[0, 0; 1, 1; 2, 4; 4, 16]"
SQUARES = "[0, 0; 1, 1; 2, 4; 3, 9]"


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def next_event(model):
    """The expression of s.nextTimeEventScaled in the block's when-clause."""
    branch = model.whens[0].branches[0]
    return next(a.value for a in branch.assignments if a.name == "s.nextTimeEventScaled")


def table_1d(tmp_path: Path, table: str, smoothness: str, extrapolation: str):
    """The flat right-hand side of y = table(time), a function of the time."""
    path = tmp_path / "M.mo"
    path.write_text(
        "model M\n  import Modelica.Blocks.Types.*;\n"
        f"  Modelica.Blocks.Tables.CombiTable1Ds t(table = {table}, u = time,\n"
        f"    smoothness = Smoothness.{smoothness},\n"
        f"    extrapolation = Extrapolation.{extrapolation});\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    rhs = next(e.rhs for e in model.equations if e.lhs == x.Var("t.y[1]"))
    return lambda u: float(x.evaluate(rhs, {"t.u": u}, u))


LINEAR_CASES = {
    # u: y, from the documentation's example and the segment formulas
    ("LinearSegments", "LastTwoPoints"): {1.0: 1.0, 1.5: 2.5, 2.0: 4.0, -1.0: -1.0,
                                          3.0: 10.0, 5.0: 22.0},
    ("LinearSegments", "HoldLastPoint"): {-1.0: 0.0, 0.5: 0.5, 5.0: 16.0},
    # one period is [0, 4): u = 5 is u = 1, u = -1 is u = 3
    ("LinearSegments", "Periodic"): {5.0: 1.0, -1.0: 10.0, 4.5: 0.5},
    # y_i on [u_i, u_i+1); outside: held, or the line through the two end points
    ("ConstantSegments", "HoldLastPoint"): {0.99: 0.0, 1.0: 1.0, 1.5: 1.0, 3.9: 4.0,
                                            4.0: 16.0, 5.0: 16.0, -1.0: 0.0},
    ("ConstantSegments", "LastTwoPoints"): {5.0: 22.0, -1.0: -1.0, 2.5: 4.0},
}


@pytest.mark.parametrize(("options", "expected"), list(LINEAR_CASES.items()),
                         ids=["-".join(k) for k in LINEAR_CASES])
def test_linear_and_constant_segments(tmp_path: Path, options: tuple[str, str],
                                      expected: dict[float, float]) -> None:
    y = table_1d(tmp_path, DOC_TABLE, *options)
    assert {u: y(u) for u in expected} == pytest.approx(expected, abs=1e-12)


SPLINE_CASES = {
    # Akima on x^2: every weight is 2, so each slope is the mean of the neighbouring
    # secants (-1, 1, 3, 5, 7 with the extension 2 m0 - m1): 0, 2, 4, 6, the exact
    # derivatives, and the spline is x^2 itself; beyond 3 the end slope 6 continues
    "ContinuousDerivative": {0.5: 0.25, 1.5: 2.25, 2.5: 6.25, 4.0: 15.0, -1.0: 0.0},
    # Fritsch-Butland: slopes 0 (end), 6/(3/1 + 3/3) = 1.5, 6/(3/3 + 3/5) = 3.75, 6
    # (end: ((2 + 1) 5 - 3)/2); on [0, 1]: 1.5 d^2 - 0.5 d^3
    "MonotoneContinuousDerivative1": {0.5: 0.3125, 1.0: 1.0, 4.0: 15.0},
    # Steffen: slopes 0, 2 min(1, 3, 1) = 2, 2 min(3, 5, 2) = 4, end 6; on [0, 1]: d^2
    "MonotoneContinuousDerivative2": {0.5: 0.25, 1.5: 2.25},
    # modified Akima: weights |m_i+1 - m_i| + |m_i+1 + m_i|/2: slope at 1 is
    # (6*1 + 2*3)/8 = 1.5, at 0 it is 0; on [0, 1] as Fritsch-Butland's
    "ModifiedContinuousDerivative": {0.5: 0.3125},
}


@pytest.mark.parametrize(("smoothness", "expected"), list(SPLINE_CASES.items()),
                         ids=list(SPLINE_CASES))
def test_cubic_hermite_splines(tmp_path: Path, smoothness: str,
                               expected: dict[float, float]) -> None:
    y = table_1d(tmp_path, SQUARES, smoothness, "LastTwoPoints")
    assert {u: y(u) for u in expected} == pytest.approx(expected, abs=1e-12)


def test_spline_derivative_is_continuous_at_the_points(tmp_path: Path) -> None:
    """der(y) of the cubic segments: the slopes Akima gives at 1 and 2, from both sides
    (the derivative springc takes for Jacobians is the interpolant's)."""
    path = tmp_path / "M.mo"
    path.write_text("model M\n  Modelica.Blocks.Tables.CombiTable1Ds t(table = [0, 0; 1, "
                    "1; 2, 3; 3, 2; 4, 5], u = time, smoothness = Modelica.Blocks.Types."
                    "Smoothness.ContinuousDerivative);\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    rhs = next(e.rhs for e in model.equations if e.lhs == x.Var("t.y[1]"))
    slope = x.time_derivative(x.substitute(rhs, {"t.u": x.TIME}))
    for point in (1.0, 2.0, 3.0):
        left, right = (float(x.evaluate(slope, {}, point + d)) for d in (-1e-9, 1e-9))
        assert left == pytest.approx(right, abs=1e-6)
    # Akima at u = 2: secants 1, 2, -1, 3: weights |3 - -1| = 4 and |2 - 1| = 1,
    # slope (4*2 + 1*(-1))/5 = 1.4
    assert float(x.evaluate(slope, {}, 2.0)) == pytest.approx(1.4, abs=1e-12)


def test_time_table_start_shift_and_offset(tmp_path: Path) -> None:
    """time < startTime gives the offset; the table is read at time - shiftTime; the
    duplicated abscissa 1 is a jump (the right value from it on)."""
    path = tmp_path / "M.mo"
    path.write_text("model M\n  Modelica.Blocks.Sources.CombiTimeTable s(table = [0, 0; "
                    "1, 1; 1, 3; 2, 3], offset = {10}, startTime = 0.2, shiftTime = 0.5);"
                    "\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    rhs = next(e.rhs for e in model.equations if e.lhs == x.Var("s.y[1]"))
    env = {"s.p_offset[1]": 10.0, "s.timeScaled": 0.0}

    def y(t: float) -> float:
        env["s.timeScaled"] = t
        return float(x.evaluate(rhs, env, t))

    expected = {0.1: 10.0, 0.2: 9.7, 1.0: 10.5, 1.49: 10.99, 1.5: 13.0, 2.7: 13.0}
    assert {t: y(t) for t in expected} == pytest.approx(expected, abs=1e-12)
    event = next_event(model)
    # the start time first, then the breakpoints 0, 1, 2 shifted by 0.5
    nexts = {t: float(x.evaluate(event, {"s.timeScaled": t}, t))
             for t in (0.0, 0.2, 0.5, 1.2, 1.5, 2.5)}
    assert nexts == {0.0: 0.2, 0.2: 0.5, 0.5: 1.5, 1.2: 1.5, 1.5: 2.5, 2.5: 1e60}


def test_periodic_time_events(tmp_path: Path) -> None:
    path = tmp_path / "M.mo"
    path.write_text("model M\n  Modelica.Blocks.Sources.CombiTimeTable s(table = [0, 0; "
                    "1, 1; 3, 0], extrapolation = Modelica.Blocks.Types.Extrapolation."
                    "Periodic);\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    event = next_event(model)
    nexts = {t: float(x.evaluate(event, {"s.timeScaled": t}, t))
             for t in (0.0, 0.5, 1.0, 3.0, 7.5, 9.0)}
    assert nexts == pytest.approx({0.0: 1.0, 0.5: 1.0, 1.0: 3.0, 3.0: 4.0, 7.5: 9.0,
                                   9.0: 10.0}, abs=1e-12)


def test_table_2d_bilinear(tmp_path: Path) -> None:
    path = tmp_path / "M.mo"
    path.write_text(
        "model M\n  import Modelica.Blocks.Tables.Internal.getTable2DValue;\n"
        "  parameter Modelica.Blocks.Types.ExternalCombiTable2D tab = Modelica.Blocks.Types."
        "ExternalCombiTable2D(\"NoName\", \"NoName\", [0, 0, 1; 0, 0, 2; 1, 4, 8], "
        "Modelica.Blocks.Types.Smoothness.LinearSegments);\n"
        "  Real y = getTable2DValue(tab, time, 0.5);\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    rhs = next(e.rhs for e in model.equations if e.lhs == x.Var("y"))
    # rows u1 = 0: (0, 2), u1 = 1: (4, 8) over u2 = 0, 1; at u2 = 0.5: 1 and 6
    values = {t: float(x.evaluate(rhs, {}, t)) for t in (0.0, 0.5, 1.0, 2.0)}
    assert values == pytest.approx({0.0: 1.0, 0.5: 3.5, 1.0: 6.0, 2.0: 11.0}, abs=1e-12)


def test_constant_segments_integrate_exactly_with_time_events(tmp_path: Path) -> None:
    """x = integral of a table of constant segments 1, 2 on [0, 1), [1, 2), and from 2
    on the line through the last two points (3 + (t - 2), LastTwoPoints as documented):
    the time events at 1 and 2 restart the integration, so x follows the exact integral
    (x(3) = 6.5) to the tolerance."""
    path = tmp_path / "M.mo"
    path.write_text(
        "model M\n  Modelica.Blocks.Sources.CombiTimeTable s(table = [0, 1; 1, 2; 2, 3],"
        " smoothness = Modelica.Blocks.Types.Smoothness.ConstantSegments);\n"
        "  Real x(start = 0, fixed = true);\nequation\n  der(x) = s.y[1];\nend M;\n")
    model = springc.compile_model([str(LIBRARY), str(path)], "M", backend="python",
                                  cache=False)
    result = springc.simulate(model, stop=3.0, engine="scipy", rtol=1e-8)
    exact = np.where(result.time < 1, result.time, np.where(
        result.time < 2, 1 + 2 * (result.time - 1),
        3 + 3 * (result.time - 2) + (result.time - 2) ** 2 / 2))
    assert np.max(np.abs(result["x"] - exact)) < 1e-6


def test_no_extrapolation_is_an_assertion(tmp_path: Path) -> None:
    path = tmp_path / "M.mo"
    path.write_text("model M\n  Modelica.Blocks.Tables.CombiTable1Ds t(table = [0, 0; 2, 1],"
                    " u = time, extrapolation = Modelica.Blocks.Types.Extrapolation."
                    "NoExtrapolation);\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    (check,) = [a for a in model.assertions if "Extrapolation" in a.message]
    assert check.message == ("Extrapolation error: the input u of the table must lie in "
                             "[0, 2] (extrapolation = NoExtrapolation)")
    holds = {u: bool(x.evaluate(check.condition, {"t.u": u}, u)) for u in (-0.1, 0, 2, 2.1)}
    assert holds == {-0.1: False, 0: True, 2: True, 2.1: False}


ERRORS = {
    "tableOnFile": ("tableOnFile = true, fileName = \"tab.txt\"",
                    "tables read from files (tableOnFile = true) are not supported yet"),
    "decreasing": ("table = [0, 0; 2, 1; 1, 2]",
                   "the abscissae (first column) of the table must be increasing"),
    "spline with a jump": ("table = [0, 0; 1, 1; 1, 2], smoothness = Modelica.Blocks."
                           "Types.Smoothness.ContinuousDerivative",
                           "the abscissae (first column) of the table must be strictly "
                           "increasing"),
    "column": ("table = [0, 0; 1, 1], columns = {3}",
               "column 3 is not a column of the table, which has 2"),
}


@pytest.mark.parametrize(("modifiers", "message"), list(ERRORS.values()), ids=list(ERRORS))
def test_errors_are_located(tmp_path: Path, modifiers: str, message: str) -> None:
    path = tmp_path / "M.mo"
    modifiers = modifiers if "table =" in modifiers else f"table = [0, 0; 1, 1], {modifiers}"
    path.write_text(f"model M\n  Modelica.Blocks.Tables.CombiTable1Ds t({modifiers}, "
                    "u = time);\nend M;\n")
    with pytest.raises(SpringcError) as caught:
        flatten_files([LIBRARY, path], "M")
    text = str(caught.value)
    assert f"MslTables.mo:146:11: error: {message}" in text


def test_each_instance_has_its_own_table(tmp_path: Path) -> None:
    """An array of table blocks is not copied from one instance (templates): each
    element's table comes from its own parameters."""
    path = tmp_path / "M.mo"
    path.write_text("model M\n  Modelica.Blocks.Tables.CombiTable1Ds t[3](table = {[0, 0; "
                    "1, 1], [0, 0; 1, 2], [0, 0; 1, 3]}, each u = time);\nend M;\n")
    model = flatten_files([LIBRARY, path], "M")
    values = [float(x.evaluate(e.rhs, {f"t[{i}].u": 1.0 for i in (1, 2, 3)}, 1.0))
              for i in (1, 2, 3) for e in model.equations if e.lhs == x.Var(f"t[{i}].y[1]")]
    assert values == [1.0, 2.0, 3.0]


def test_false_and_skips_an_operand_that_cannot_be_evaluated(tmp_path: Path) -> None:
    """`tableOnFile and not Strings.isEmpty(fileName)`, as the MSL's table blocks
    write it: with tableOnFile false the external string function is never needed."""
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "Lib.mo").write_text(
        "package Lib\n  function isEmpty\n    input String s;\n    output Boolean b;\n"
        "  external \"C\" b = ModelicaStrings_isEmpty(s);\n  end isEmpty;\nend Lib;\n")
    path = tmp_path / "M.mo"
    path.write_text("model M\n  parameter Boolean onFile = false;\n"
                    "  parameter Boolean b = onFile and not Lib.isEmpty(\"x\");\n"
                    "  parameter Boolean c = not onFile or Lib.isEmpty(\"x\");\n"
                    "  parameter Boolean d = not onFile and Lib.isEmpty(\"x\");\nend M;\n")
    with pytest.raises(SpringcError) as caught:
        flatten_files([path], "M", [tmp_path / "lib"])
    assert "M.mo:5:40: error: the external function 'Lib.isEmpty' (C function " \
        "'ModelicaStrings_isEmpty') is not supported: its library does not ship its C " \
        "sources" in str(caught.value)
    path.write_text(path.read_text().replace("  parameter Boolean d", "  // "))
    model = flatten_files([path], "M", [tmp_path / "lib"])
    bindings = {v.name: v.binding for v in model.variables if v.name in ("b", "c")}
    assert bindings == {"b": x.Const(False), "c": x.Const(True)}
