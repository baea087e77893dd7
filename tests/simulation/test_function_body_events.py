"""A model whose only relation is in a function body is continuous (Modelica 3.6,
section 12.8: a function without ``GenerateEvents = true`` generates no events): it
runs on the continuous driver, and the kink is crossed by step-size control alone. With
``annotation(GenerateEvents = true)`` the same relation is a state event."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc
from springc.simulation import SimulationResult

MODEL = '''\
model Kink
  function larger
    input Real u1;
    input Real u2;
    output Real y;
  algorithm
    y := if u1 > u2 then u1 else u2;
    ANNOTATION
  end larger;
  Real x(start = 1, fixed = true);
equation
  der(x) = -larger(x, 0.5);
end Kink;
'''


def exact(t: float) -> float:
    """x' = -max(x, 1/2), x(0) = 1: exp(-t) until x = 1/2 at t = ln 2, then a line."""
    kink = math.log(2.0)
    return math.exp(-t) if t <= kink else 0.5 - 0.5 * (t - kink)


def run(tmp_path: Path, annotation: str) -> tuple[str, SimulationResult]:
    path = tmp_path / "Kink.mo"
    path.write_text(MODEL.replace("ANNOTATION", annotation))
    model = springc.compile_model([str(path)], backend="python")
    result = springc.simulate(model, engine="scipy", stop=2.0, interval=0.25, rtol=1e-10,
                              atol=1e-12, error_control="off")
    return model.module.KIND, result


def test_a_function_body_relation_is_continuous(tmp_path: Path) -> None:
    kind, result = run(tmp_path, "annotation(Inline = true);")
    assert kind == "continuous"
    expected = [exact(float(t)) for t in result.time]
    assert np.max(np.abs(np.asarray(result["x"]) - expected)) < 1e-7
    assert list(result.time) == [0.25 * k for k in range(9)]


def test_generate_events_makes_it_a_state_event(tmp_path: Path) -> None:
    kind, result = run(tmp_path, "annotation(GenerateEvents = true);")
    assert kind == "hybrid"
    (event,) = [e for e in result.events if e.kind == "state"]
    assert abs(event.time - math.log(2.0)) < 1e-8
    assert abs(float(np.asarray(result["x"])[-1]) - exact(2.0)) < 1e-7
