"""A stage outside the model's domain rejects the attempt (as scipy's NaN error norm
does) instead of ending the run: the compiled explicit loops, numba's and C's."""

from __future__ import annotations

import math
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import springc

CRITICAL = """
model Critical "critically damped to x = 1; a stage past x = 2 leaves sqrt's domain"
  parameter Real w = 1e6;
  Real x(start = 0, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(x) = v + 1e-20 * sqrt(2 - x);
  der(v) = w^2 * (1 - x) - 2 * w * v;
end Critical;
"""
STOP = 1e-5  # one output interval: the first attempt spans it (x of its stages near 50)


@pytest.mark.parametrize("loop", ["c", "numba"])
@pytest.mark.parametrize("solver", ["dop853", "rk45"])
def test_a_stage_outside_the_domain_is_a_rejected_attempt(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, loop: str, solver: str) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("SPRINGC_LOOP", loop)
    path = tmp_path / "Critical.mo"
    path.write_text(CRITICAL)
    result = springc.simulate(str(path), solver=solver, engine="compiled", backend="numba",
                              stop=STOP, interval=STOP, error_control="off")
    assert result.stats.engine == "compiled"
    wt = 1e6 * STOP  # x = 1 - (1 + w t) exp(-w t), v = w^2 t exp(-w t)
    assert abs(result["x"][-1] - (1 - (1 + wt) * math.exp(-wt))) < 1e-7
    assert abs(result["v"][-1] / (1e12 * STOP * math.exp(-wt)) - 1) < 1e-4


@pytest.mark.parametrize("engine", ["c", "numba"])
def test_the_ensemble_engines_reject_the_same_attempts(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch,
                                                      engine: str) -> None:
    from springc.studies import EnsembleOptions, parse_parameter, run_ensemble

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "Critical.mo"
    path.write_text(CRITICAL)
    model = springc.compile_model(str(path), backend="numba")
    run_ensemble(model, EnsembleOptions((parse_parameter("w=1e6,2e6"),), stop=STOP,
                                        interval=STOP, engine=engine),
                 str(tmp_path / "e.parquet"))
    table = pq.read_table(tmp_path / "e.parquet").to_pydict()
    assert table["status"] == ["ok", "ok"], table["error"]
    for w, x in zip((1e6, 2e6), table["x.final"]):
        assert abs(x - (1 - (1 + w * STOP) * math.exp(-w * STOP))) < 1e-7
