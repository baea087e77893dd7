"""``when`` statements in algorithm sections (11.2.7) simulated against closed forms on
both engines: the variables they assign are discrete (held between events), vector
conditions fire on each element becoming true, ``elsewhen`` fires only when no
earlier branch does, and ``terminate`` ends the run at its event."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc

COUNTER = """model Counter
  Real x(start = 1, fixed = true);
  discrete Real y(start = 0, fixed = true);
  Integer n(start = 0, fixed = true);
  Real z;
equation
  der(x) = -x;
algorithm
  z := 2 * x;
  when {x < 0.5, x < 0.25} then
    n := pre(n) + 1;
    y := z + n;
  elsewhen time >= 2 then
    y := -1;
  end when;
  annotation(experiment(StopTime = 3, Interval = 0.1));
end Counter;
"""

STOP = """model Stop
  Real x(start = 0, fixed = true);
  Real y(start = 1, fixed = true);
equation
  der(x) = y;
  der(y) = -x;
algorithm
  when y < 0 then
    terminate("y crossed zero");
  end when;
  annotation(experiment(StopTime = 5, Interval = 0.01));
end Stop;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_when_statement_values_match_the_closed_form(tmp_path: Path, engine: str) -> None:
    path = tmp_path / "Counter.mo"
    path.write_text(COUNTER)
    result = springc.simulate(str(path), rtol=1e-9, engine=engine)
    t = result.time
    # x = exp(-t) passes 0.5 at ln 2 (n = 1, y = 2*0.5 + 1) and 0.25 at ln 4 (n = 2,
    # y = 2*0.25 + 2); at t = 2 only the elsewhen branch fires (y = -1)
    n = np.where(t < math.log(2), 0, np.where(t < math.log(4), 1, 2))
    y = np.where(t < math.log(2), 0.0, np.where(t < math.log(4), 2.0,
                                                np.where(t < 2, 2.5, -1.0)))
    assert result["n"].tolist() == n.tolist()
    assert np.max(np.abs(result["y"] - y)) < 1e-6
    assert np.max(np.abs(result["z"] - 2 * np.exp(-t))) < 1e-7


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_terminate_in_a_when_statement_ends_the_run(tmp_path: Path, engine: str) -> None:
    path = tmp_path / "Stop.mo"
    path.write_text(STOP)
    result = springc.simulate(str(path), rtol=1e-10, engine=engine)
    # y = cos(t) crosses zero at pi/2: the last row is there
    assert abs(result.time[-1] - math.pi / 2) < 1e-6
    assert abs(result["x"][-1] - 1.0) < 1e-6
