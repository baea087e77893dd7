"""Models with algorithm sections simulated against closed forms: the section's
assignments (with an if on a value known only at run time, merged as an
if-expression) computed in the generated code of both backends."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = """model Alg
  parameter Real k = 2;
  Real x(start = 1, fixed = true);
  Real y;
  Real z;
  Real w;
initial algorithm
  w := 3;
equation
  der(x) = -k * x;
  der(w) = -w;
algorithm
  y := 2 * x;
  z := 0;
  for i in 1:3 loop
    z := z + i * y;
  end for;
  if noEvent(x < 0.5) then
    z := -z;
  end if;
  annotation(experiment(StopTime = 1, Interval = 0.01));
end Alg;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_algorithm_values_match_the_closed_form(tmp_path: Path, backend: str) -> None:
    if backend == "numba":
        pytest.importorskip("numba")
    path = tmp_path / "alg.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), rtol=1e-9, backend=backend, engine="scipy")
    t = result.time
    x = np.exp(-2 * t)
    z = 12 * x * np.where(x < 0.5, -1, 1)  # (1 + 2 + 3) * 2x, negated once x < 0.5
    assert np.max(np.abs(result["y"] - 2 * x)) < 1e-7
    assert np.max(np.abs(result["z"] - z)) < 1e-6
    # the initial algorithm sets w(0) = 3
    assert np.max(np.abs(result["w"] - 3 * np.exp(-t))) < 1e-7
