"""``tradeoff`` on a hybrid model: the reference locates the events too (dop853
checked by radau, both with event location), and the errors are measured against it."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.tradeoff.model import TradeoffOptions
from springc.tradeoff.study import compare_states, run_tradeoff

BALL = """
model Ball
  parameter Real e = 0.8;
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  when h <= 0 then
    reinit(v, -e*pre(v));
  end when;
  annotation(experiment(StopTime = 2, Interval = 0.01));
end Ball;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_the_reference_of_a_hybrid_model_locates_its_events(tmp_path: Path) -> None:
    path = tmp_path / "ball.mo"
    path.write_text(BALL)
    model = compare_states(springc.compile_model(str(path)))
    study = run_tradeoff(model, TradeoffOptions(("dop853",), (1e-4, 1e-8), repeats=1))
    ref = study.reference
    assert re.search(r"verified by radau with event location at rtol 1e-12", ref.description)
    t = ref.time
    g, u = 9.81, math.sqrt(2 * 9.81)
    h, impact = 1 - g * t**2 / 2, u / g
    for k in range(1, 5):  # the piecewise parabola after each impact
        w = 0.8**k * u
        h = np.where(t >= impact, w * (t - impact) - g * (t - impact) ** 2 / 2, h)
        impact += 2 * w / g
    assert np.max(np.abs(ref.values[:, 0] - h)) < 1e-9
    # dop853 integrates the parabolas exactly: what is left is where it finds the events
    assert all(r.max_error < 1e-9 for r in study.runs)
    assert len(study.runs) == 2
