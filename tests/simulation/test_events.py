"""Hybrid models against exact or independent references: the bouncing ball's
piecewise parabola, a time event hit exactly, the event output rows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc

BALL = """
model BouncingBall
  parameter Real e = 0.8 "coefficient of restitution";
  parameter Real g = 9.81;
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -g;
  when h <= 0 then
    reinit(v, -e*pre(v));
  end when;
end BouncingBall;
"""

E, G = 0.8, 9.81


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def write(tmp_path: Path, text: str, name: str = "m.mo") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def ball_exact(t: np.ndarray, bounces: int) -> tuple[np.ndarray, np.ndarray, list[float]]:
    """h, v of the ball dropped from 1 m, and its impact times."""
    u = math.sqrt(2 * G)  # speed at the first impact
    impacts = [u / G]
    for k in range(1, bounces):
        impacts.append(impacts[-1] + 2 * E**k * u / G)
    h = 1 - G * t**2 / 2
    v = -G * t
    for k, tk in enumerate(impacts):
        after = t >= tk
        w = E ** (k + 1) * u
        h = np.where(after, w * (t - tk) - G * (t - tk) ** 2 / 2, h)
        v = np.where(after, w - G * (t - tk), v)
    return h, v, impacts


def test_bouncing_ball_matches_the_exact_parabolas(tmp_path: Path) -> None:
    _, _, impacts = ball_exact(np.zeros(1), 11)
    stop = impacts[9] + 0.5 * (impacts[10] - impacts[9])
    result = springc.simulate(write(tmp_path, BALL), rtol=1e-8, stop=stop, interval=1e-3)
    h, v, _ = ball_exact(result.time, 11)
    assert np.max(np.abs(result["h"] - h)) < 1e-6
    assert np.max(np.abs(result["v"] - v)) < 1e-6
    bounces = [e.time for e in result.events if e.x_right[1] != e.x_left[1]]
    assert len(bounces) == 10
    assert np.max(np.abs(np.array(bounces) - impacts[:10])) < 1e-9
    assert result.stats.state_events >= 10 and result.stats.time_events == 0
