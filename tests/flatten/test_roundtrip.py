"""The flat text printed by ``springc flatten`` parses back into the same flat model."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from springc.ir.flat import FlatModel, format_flat
from springc.pipeline.files import flatten_files

ROOT = Path(__file__).resolve().parents[2]
SCENES = {
    "SpringMass": ("models/SpringMass.mdl", None),
    "SpringMassConnected": ("models/Scenes.mdl", "Scenes.SpringMassConnected"),
    "DampedSpringMass": ("models/Scenes.mdl", "Scenes.DampedSpringMass"),
    "Chain3": ("model C = Scenes.Chain(N = 3);\n", None),
    "Oscillator": ("models/Scenes.mdl", "Scenes.Oscillator"),
    "Cloth3": ("model C = Scenes.Cloth(N = 3, M = 3);\n", None),
    "Pendulum": ("models/Scenes.mdl", "Scenes.Pendulum"),
    "RigidPair": ("models/Scenes.mdl", "Scenes.RigidPair"),
    "BouncingBall": ("models/EventScenes.mdl", "EventScenes.BouncingBall"),
    "NewtonsCradle": ("models/EventScenes.mdl", "EventScenes.NewtonsCradle"),
    "Hybrid": ("""
model H "when/elsewhen, vector conditions, pre/edge/change, sample, a variable if"
  Real x(start = 1, fixed = true);
  Real y;
  Boolean b(start = false);
  Integer n(start = 0);
  discrete Real t1(start = -1);
equation
  if x > 0.5 then
    y = 2 * x;
  else
    y = x;
  end if;
  der(x) = -y;
  when {x < 0.8, sample(0, 0.5)} then
    n = pre(n) + 1;
  elsewhen initial() then
    n = 0;
  end when;
  when edge(b) or change(n) then
    t1 = time;
  end when;
  when x < 0.7 then
    b = true;
    reinit(x, 0.9);
  end when;
end H;
""", None),
    "Attributes": ("""
model M "attributes, initial equations, Integer and Boolean parameters, quoting"
  parameter Integer n = 2;
  parameter Boolean on = true;
  parameter Real k(unit = "N/m", min = 0) = 1e-3 "a \\"quoted\\" description";
  Real x[n](each start = 1.5, each fixed = true, each nominal = 2, each stateSelect =
    StateSelect.prefer, each unit = "m", each displayUnit = "mm");
initial equation
  der(x[1]) = 0;
equation
  der(x) = {if on then -k * x[1] else 0, noEvent(if x[2] > 0 then -x[2] else x[2] ^ 2)};
  annotation(experiment(StartTime = 0, StopTime = 1, Interval = 1e-3, Tolerance = 1e-6));
end M;
""", None),
}


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def _flatten(tmp_path: Path, source: str, model: str | None) -> FlatModel:
    if source.startswith("models/"):
        return flatten_files([ROOT / source], model)
    path = tmp_path / "scene.mdl"
    path.write_text(source)
    return flatten_files([path], model)


def _without_locations(m: FlatModel) -> tuple[object, ...]:
    variables = tuple(replace(v, span=None, component="") for v in m.variables)
    eqs = tuple((e.lhs, e.rhs) for e in m.equations)
    init = tuple((e.lhs, e.rhs) for e in m.initial_equations)
    return variables, eqs, init, m.experiment


@pytest.mark.parametrize("scene", list(SCENES))
def test_flat_text_parses_back_to_the_same_model(scene: str, tmp_path: Path) -> None:
    model = _flatten(tmp_path, *SCENES[scene])
    text = format_flat(model)
    printed = tmp_path / "flat.mdl"
    printed.write_text(text)
    again = flatten_files([printed])
    assert format_flat(again) == text
    assert again.name == model.name
    assert _without_locations(again) == _without_locations(model)
