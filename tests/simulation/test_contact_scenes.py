"""The bundled contact elements and event scenes (models/EventScenes.mdl) against
conservation laws and independent references."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc
from hybrid_reference import wall_reference

ROOT = Path(__file__).resolve().parents[2]
SCENES = str(ROOT / "models" / "EventScenes.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_newtons_cradle_passes_the_velocity_to_the_last_ball() -> None:
    result = springc.simulate(SCENES, model_name="EventScenes.NewtonsCradle")
    m, v0, c, d = 0.1, 1.0, 1e6, 0.02
    v = np.column_stack([result[f"ball[{i}].v"] for i in range(1, 6)])
    s = np.column_stack([result[f"ball[{i}].s"] for i in range(1, 6)])
    # momentum, and energy (kinetic + contact springs) are conserved to the tolerance
    momentum = m * v.sum(axis=1)
    assert np.max(np.abs(momentum - m * v0)) < 1e-7
    gaps = np.diff(s, axis=1)
    spring = 0.5 * c * np.where(gaps < d, (gaps - d) ** 2, 0.0).sum(axis=1)
    energy = 0.5 * m * (v**2).sum(axis=1) + spring
    assert np.max(np.abs(energy - 0.5 * m * v0**2)) < 1e-6
    assert abs(v[-1, 4] - v0) < 1e-3
    assert np.max(np.abs(v[-1, :4])) < 1e-3
    assert result.stats.state_events == 8  # four contacts, each begins and ends


def test_wall_contact_scene_matches_the_wall_reference() -> None:
    _, reference, crossings = wall_reference(2.0)
    result = springc.simulate(SCENES, model_name="EventScenes.WallContact", interval=0.005,
                              atol=1e-11)
    assert np.max(np.abs(result["mass.s"] - 1 - reference[:, 0])) < 1e-6
    assert result.stats.state_events == crossings


def test_floor_bounce_keeps_the_horizontal_velocity_and_loses_energy() -> None:
    result = springc.simulate(SCENES, model_name="EventScenes.FloorBounce")
    vx = result["ball.v[1]"]
    assert np.max(np.abs(vx - 1.0)) < 1e-9  # the floor has no friction
    y, vy = result["ball.pos[2]"], result["ball.v[2]"]
    energy = 0.5 * vy**2 + 9.81 * y
    first = int(np.argmax(result["floor.contact"] > 0))
    # free fall from 1 m meets the floor at t = sqrt(2/g); damping then takes energy
    assert abs(result.time[first] - math.sqrt(2 / 9.81)) < 2e-3
    assert energy[-1] < 0.9 * energy[0]
    assert result.stats.state_events >= 4
