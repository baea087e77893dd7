"""The bundled Modelica library (models/Modelica): Units, SIunits, Constants, Math, Icons,
Blocks.Interfaces and the event-free Blocks.Sources, each against a value or a closed
form; signal connectors (``connector RealInput = input Real``) in connections; a user's
own Modelica package on the library path replaces the bundled one."""

from __future__ import annotations

import math
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


def simulate(text: str, stop: float, **options: object) -> springc.SimulationResult:
    model = springc.load_model_from_string(text, cache=False)
    return springc.simulate(model, stop=stop, interval=stop / 100, rtol=1e-10,
                            atol=1e-12, **options)  # type: ignore[arg-type]


def flat_text(tmp_path: Path, text: str, libraries: tuple[Path, ...] = ()) -> str:
    path = tmp_path / "M.mo"
    path.write_text(text)
    return format_flat(flatten_files([path], libraries=libraries))


def test_units_types_carry_their_unit_and_the_old_siunits_names_are_the_same(
        tmp_path: Path) -> None:
    text = ("model M\n  Modelica.Units.SI.Position x(start = 1);\n"
            "  Modelica.SIunits.Velocity v;\n  Modelica.Units.SI.Angle phi = 0;\n"
            "equation\n  der(x) = v;\n  v = 1;\nend M;\n")
    assert flat_text(tmp_path, text) == (
        "model M\n  Real x(start = 1, unit = \"m\");\n  Real v(unit = \"m/s\");\n"
        "  Real phi(unit = \"rad\", displayUnit = \"deg\");\nequation\n  phi = 0;\n"
        "  der(x) = v;\n  v = 1;\nend M;\n")


def test_constants_have_their_values(tmp_path: Path) -> None:
    text = ("model M\n  import C = Modelica.Constants;\n"
            "  parameter Real p[6] = {C.pi, C.e, C.g_n, C.R, C.D2R, Modelica.Constants.pi};\n"
            "  Real x = 1;\nend M;\n")
    flat = flat_text(tmp_path, text)
    values = [float(line.split("= ")[1].rstrip(";")) for line in flat.splitlines()
              if line.startswith("  parameter")]
    expected = [math.pi, math.e, 9.80665, 1.380649e-23 * 6.02214076e23, math.pi / 180,
                math.pi]
    assert values == pytest.approx(expected, rel=1e-15)


def test_math_functions_through_imports_and_full_names() -> None:
    text = ("model M\n  import Modelica.Math;\n  import Modelica.Math.Vectors.norm;\n"
            "  Real y1, y2, y3;\nequation\n  y1 = Math.sin(time) + Modelica.Math.cos(time);\n"
            "  y2 = Math.atan2(time, 1) * Math.exp(time);\n  y3 = norm({time, 2 * time});\n"
            "end M;\n")
    result = simulate(text, 2.0)
    t = result.time
    assert np.max(np.abs(result["y1"] - (np.sin(t) + np.cos(t)))) < 1e-12
    assert np.max(np.abs(result["y2"] - np.arctan2(t, 1) * np.exp(t))) < 1e-12
    assert np.max(np.abs(result["y3"] - math.sqrt(5) * t)) < 1e-12


SIGNALS = """
model Signals
  import Modelica.Blocks.Interfaces;
  block Gain
    extends Interfaces.SISO;
    parameter Real k = 1;
  equation
    y = k * u;
  end Gain;
  block TwoGains "signal connectors connected inside and to the outside"
    extends Interfaces.SISO;
    Gain g1(k = 2), g2(k = 3);
  equation
    connect(u, g1.u);
    connect(g1.y, g2.u);
    connect(g2.y, y);
  end TwoGains;
  Modelica.Blocks.Sources.Constant c(k = 0.5);
  TwoGains two;
  Real x(start = 1, fixed = true);
equation
  connect(c.y, two.u);
  der(x) = two.y;
end Signals;
"""


def test_signal_connectors_connect_inside_and_outside() -> None:
    result = simulate(SIGNALS, 2.0)
    # der(x) = 3 * 2 * 0.5: x = 1 + 3 t.
    assert np.max(np.abs(result["x"] - (1 + 3 * result.time))) < 1e-10


def test_signal_connectors_give_equalities(tmp_path: Path) -> None:
    flat = flat_text(tmp_path, SIGNALS)
    for line in ("  'c.y' = 'two.u';", "  'two.u' = 'two.g1.u';", "  'two.g1.y' = 'two.g2.u';",
                 "  'two.g2.y' = 'two.y';", "  input Real 'two.u' \"Input signal\";"):
        assert line in flat.splitlines()


def test_a_signal_connector_and_a_flange_do_not_connect(tmp_path: Path) -> None:
    text = ("model M\n  Modelica.Blocks.Sources.Constant c;\n"
            "  Modelica.Mechanics.Translational.Components.Fixed f;\n"
            "equation\n  connect(c.y, f.flange);\nend M;\n")
    with pytest.raises(SpringcError) as info:
        flat_text(tmp_path, text)
    assert info.value.message == "connectors 'c.y' and 'f.flange' do not match"
    assert (info.value.span.line, info.value.span.column) == (5, 3)


def test_constant_source() -> None:
    text = ("model M\n  Modelica.Blocks.Sources.Constant c(k = -2);\n"
            "  Real x(start = 0, fixed = true);\nequation\n  der(x) = c.y;\nend M;\n")
    result = simulate(text, 1.0)
    assert np.max(np.abs(result["x"] + 2 * result.time)) < 1e-10


def test_icons_can_be_extended_and_a_partial_block_cannot_be_instantiated(
        tmp_path: Path) -> None:
    text = ("model M\n  extends Modelica.Icons.Example;\n"
            "  Modelica.Blocks.Interfaces.SO so;\nend M;\n")
    with pytest.raises(SpringcError) as info:
        flat_text(tmp_path, text)
    assert info.value.message == ("'so' is of the partial class "
                                  "'Modelica.Blocks.Interfaces.SO', which cannot be "
                                  "instantiated")
    assert (info.value.span.line, info.value.span.column) == (3, 33)


def test_a_users_own_modelica_library_takes_precedence(tmp_path: Path) -> None:
    lib = tmp_path / "lib" / "Modelica"
    lib.mkdir(parents=True)
    (lib / "package.mo").write_text(
        "package Modelica\n  package Constants\n    constant Real answer = 42;\n"
        "  end Constants;\nend Modelica;\n")
    text = ("model M\n  parameter Real a = Modelica.Constants.answer;\n  Real x = a;\nend M;\n")
    assert "  parameter Real a = 42;" in flat_text(tmp_path, text, (tmp_path / "lib",))
    # Without it, the bundled Constants has no such constant.
    with pytest.raises(SpringcError) as info:
        flat_text(tmp_path, text)
    assert info.value.message == "'Modelica.Constants' has no element 'answer'"


def test_an_imported_constant(tmp_path: Path) -> None:
    text = ("model M\n  import Modelica.Constants.pi;\n  import G = Modelica.Constants.g_n;\n"
            "  parameter Real p = 2 * pi + G;\n  Real x = p;\nend M;\n")
    line = next(x for x in flat_text(tmp_path, text).splitlines() if "parameter" in x)
    assert float(line.split("= ")[1].rstrip(";")) == pytest.approx(2 * math.pi + 9.80665,
                                                                     rel=1e-15)
