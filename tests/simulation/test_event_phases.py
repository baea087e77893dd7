"""``initial()`` and ``terminal()`` during a simulation (3.7.5, 8.3.4): assertions in
if-equations on them are checked at the first and at the last row only, and a
when-clause on ``not initial()`` fires at the start time, right after the
initialization (before its result row), on both engines."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError

DECAY = """model Decay
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  if initial() then
    assert(x > 0.9, "starts high");
  elseif terminal() then
    assert(x < LIMIT, "ends low");
  end if;
  annotation(experiment(StopTime = 1, Interval = 0.1));
end Decay;
"""

TERMINAL_WHEN = """model Ending
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  when terminal() then
    assert(x < LIMIT, "ends low");
  end when;
  annotation(experiment(StopTime = 1, Interval = 0.1));
end Ending;
"""

PRIORITY = """model Priority
  Boolean close(fixed = true);
  Real x(start = 3, fixed = true);
equation
  when not initial() then
    x = 6;
  end when;
  when x >= 5 then
    close = true;
  elsewhen x >= 4 then
    close = false;
  end when;
  annotation(experiment(StopTime = 0.1, Interval = 0.05));
end Priority;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_phase_assertions_hold_only_at_their_rows(tmp_path: Path, engine: str) -> None:
    # x = exp(-t) falls below 0.9 at t = 0.105 and ends at exp(-1) = 0.3679
    path = tmp_path / "Decay.mo"
    path.write_text(DECAY.replace("LIMIT", "0.37"))
    result = springc.simulate(str(path), rtol=1e-8, engine=engine)
    assert abs(result["x"][-1] - np.exp(-1)) < 1e-6
    path.write_text(DECAY.replace("LIMIT", "0.36"))
    with pytest.raises(SimulationError) as info:
        springc.simulate(str(path), rtol=1e-8, engine=engine)
    assert info.value.message == "assertion failed at t = 1: ends low"


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_when_not_initial_fires_at_the_start(tmp_path: Path, engine: str) -> None:
    path = tmp_path / "Priority.mo"
    path.write_text(PRIORITY)
    result = springc.simulate(str(path), engine=engine)
    # x = 6 right after the initialization, so 'x >= 5' (the first branch) sets close
    assert result["x"].tolist() == [6.0, 6.0, 6.0]
    assert result["close"].tolist() == [1.0, 1.0, 1.0]


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_assert_in_a_when_clause_on_terminal_checks_the_end(tmp_path: Path, engine: str
                                                           ) -> None:
    # x(1) = exp(-1) = 0.3679: below 0.37, above 0.36
    path = tmp_path / "Ending.mo"
    path.write_text(TERMINAL_WHEN.replace("LIMIT", "0.37"))
    springc.simulate(str(path), rtol=1e-8, engine=engine)
    path.write_text(TERMINAL_WHEN.replace("LIMIT", "0.36"))
    with pytest.raises(SimulationError) as info:
        springc.simulate(str(path), rtol=1e-8, engine=engine)
    assert info.value.message == "assertion failed at t = 1: ends low"
