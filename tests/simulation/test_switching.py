"""``springc.simulate`` switches states for RigidPair when its rod passes vertical."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc

MODELS = Path(__file__).resolve().parents[2] / "models"


def test_rigid_pair_runs_through_the_switch_with_the_rod_length_kept() -> None:
    result = springc.simulate([MODELS / "Scenes.mdl"], model_name="Scenes.RigidPair",
                              stop=1.0, interval=0.01, rtol=1e-8, cache=False)
    length = np.hypot(result["p2.pos[1]"] - result["p1.pos[1]"],
                      result["p2.pos[2]"] - result["p1.pos[2]"])
    assert np.max(np.abs(length - 1.0)) < 1e-9  # Rod(l = 1), solved from the constraint
    assert result.time[-1] == 1.0 and len(result.time) == 101
    reason = result.stats.reason
    assert reason.startswith("dynamic state selection, 1 switch (t = 0.51")
