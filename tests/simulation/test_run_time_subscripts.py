"""Assignments whose subscript is known only during the simulation (the MSL's
RealFFT buffer ``buf[iTick] := u``), simulated against closed forms on both
engines: each sample lands in its own element, an index out of range assigns none."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc

BUFFER = """model Buffer
  Real x(start = 1, fixed = true);
  Real buf[3](each start = 0, each fixed = true);
  Integer k(start = 0, fixed = true);
  function put
    input Integer i;
    input Real v;
    output Real y[3];
  algorithm
    y := {1, 2, 3};
    y[i] := v;
  end put;
  Real z[3] = put(if time < 0.5 then 1 else 3, x);
equation
  der(x) = -x;
algorithm
  when sample(0.1, 0.1) then
    k := pre(k) + 1;
    buf[k] := x;
  end when;
  annotation(experiment(StopTime = 1, Interval = 0.05));
end Buffer;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_samples_land_in_the_element_the_counter_names(tmp_path: Path, engine: str) -> None:
    path = tmp_path / "Buffer.mo"
    path.write_text(BUFFER)
    result = springc.simulate(str(path), rtol=1e-10, engine=engine)
    t = result.time
    # the j-th sample (t = 0.1 j) writes x = exp(-0.1 j) into buf[j]; from the fourth
    # on, k is out of range and nothing is written
    for j in (1, 2, 3):
        expected = np.where(t < 0.1 * j - 1e-9, 0.0, math.exp(-0.1 * j))
        assert np.max(np.abs(result[f"buf[{j}]"] - expected)) < 1e-8, j
    assert result["k"][-1] == 10
    # the function writes x into z[1] before t = 0.5, into z[3] after
    early = t < 0.5 - 1e-9
    x = np.exp(-t)
    assert np.max(np.abs(result["z[1]"] - np.where(early, x, 1.0))) < 1e-8
    assert np.max(np.abs(result["z[2]"] - 2.0)) == 0.0
    assert np.max(np.abs(result["z[3]"] - np.where(early, 3.0, x))) < 1e-8
