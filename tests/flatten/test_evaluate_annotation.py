"""``annotation(Evaluate = true)`` (Modelica 18.3): the parameter is folded into the
model as a constant, and so is a ``final`` parameter bound to such parameters only
(Electrical.Analog's Heating*_NORGate: ``parameter CapVal = 0 annotation(Evaluate =
true)`` and ``Capacitor C1(final C = CapVal)``). Alias elimination then folds the
constant: ``c*der(v)`` with ``c = 0`` reads no derivative, and ``v`` is no state."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc
from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files
from springc.simplify.passes import simplify

MODEL = """
model Ev
  model Cap
    parameter Real C = 1;
    Real v(start = 1);
    Real i;
    Real c;
  equation
    c = smooth(1, C*v^2 + C);
    i = c*der(v);
  end Cap;
  parameter Real CapVal = 0 annotation(Evaluate = true);
  parameter Real k = 2;
  parameter Real R = 2 annotation(Evaluate = K);
  parameter Real G = k annotation(Evaluate = true);
  Cap cap(final C = CapVal);
  Cap other(final C = k);
  Real u;
equation
  u = sin(time);
  u - cap.v = R*cap.i;
  der(other.v) = -G*other.v;
end Ev;
"""


def _flat(tmp_path: Path, text: str):
    path = tmp_path / "Ev.mo"
    path.write_text(text)
    return flatten_files([path])


def test_evaluated_parameters_are_constants(tmp_path: Path) -> None:
    flat = _flat(tmp_path, MODEL.replace("Evaluate = K", "Evaluate = false"))
    text = format_flat(flat)
    # CapVal and cap.C are folded; k (plain), R (Evaluate = false), G (its binding reads
    # a parameter) and other.C (final, but bound to a plain parameter) stay parameters
    # (the class Cap's equations are flattened per instance: no template is shared
    # between an instance with a folded parameter and one without)
    assert "  'cap.c' = 0;\n" in text
    assert "  'other.c' = 'other.C' * 'other.v' ^ 2 + 'other.C';\n" in text
    names = [v.name for v in flat.parameters]
    assert names == ["k", "R", "G", "other.C"]


def test_a_zero_capacitance_leaves_no_state(tmp_path: Path) -> None:
    flat = _flat(tmp_path, MODEL.replace("Evaluate = K", "Evaluate = false"))
    states = [s.name for s in simplify(flat).ode.states]
    assert states == ["other.v"]
    path = tmp_path / "Ev.mo"
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.25, rtol=1e-10, atol=1e-12, error_control="off")
    t = np.asarray(result.time)
    assert np.allclose(np.asarray(result["cap.v"]), np.sin(t), rtol=0, atol=1e-12)
    assert np.allclose(np.asarray(result["other.v"]), [math.exp(-2 * s) for s in t],
                       rtol=1e-7, atol=0)
