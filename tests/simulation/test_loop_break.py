"""``break`` under a condition known only during the simulation in a for loop of an
algorithm section (11.2.5): the loop is unrolled, the values after the break kept;
simulated on both backends against the closed form."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = """model FirstAbove
  Real u[4] = {time, 2 * time, 3 * time, 4 * time};
  Real first "the first u[k] above 1, else -1";
  Integer count "the number of u[k] tried";
algorithm
  first := -1;
  count := 0;
  for k in 1:4 loop
    count := count + 1;
    if noEvent(u[k] > 1) then
      first := u[k];
      break;
    end if;
  end for;
  annotation(experiment(StopTime = 1.5, Interval = 0.01));
end FirstAbove;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_the_first_element_above_one(tmp_path: Path, backend: str) -> None:
    if backend == "numba":
        pytest.importorskip("numba")
    path = tmp_path / "FirstAbove.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend=backend)
    t = result.time
    k = np.floor(1 / np.maximum(t, 1e-300)) + 1  # the smallest k with k*t > 1
    expected_first = np.where(k <= 4, k * t, -1.0)
    expected_count = np.minimum(k, 4)
    assert np.max(np.abs(result["first"] - expected_first)) < 1e-12
    assert result["count"].tolist() == expected_count.tolist()
