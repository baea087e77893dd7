"""Initial equations ``v = e`` of when-assigned variables (8.6): ``e`` (an expression
of parameters) is the value of ``v`` and ``pre(v)`` until the first event that
assigns it, on both engines; they are not conditions on the states."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = """model Counting
  parameter Real x0 = 1.5;
  discrete Real x;
  discrete Integer n;
  Real s(start = 0, fixed = true);
initial equation
  x = 2 * x0;
  pre(n) = 4;
equation
  der(s) = 1;
  when sample(0.25, 0.25) then
    x = pre(x) + 1.0;
    n = pre(n) - 1;
  end when;
  annotation(experiment(StopTime = 1, Interval = 0.125));
end Counting;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_initial_equations_start_the_discrete_variables(tmp_path: Path, engine: str) -> None:
    path = tmp_path / "Counting.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), engine=engine)
    events = np.floor(result.time / 0.25 + 1e-9)  # samples at 0.25, 0.5, 0.75, 1
    assert result["x"].tolist() == (3.0 + events).tolist()
    assert result["n"].tolist() == (4 - events).tolist()
