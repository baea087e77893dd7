"""``springc.simulate`` switches states for RigidPair when its rod passes vertical."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError

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


def test_assertions_are_checked_at_output_times_of_a_switching_run(tmp_path: Path) -> None:
    path = tmp_path / "checked.mo"
    path.write_text("model Checked\n  extends Scenes.RigidPair;\nequation\n"
                    '  assert(p2.pos[1] > 0.5, "p2 swung past x = 0.5");\nend Checked;\n')
    free = springc.simulate([MODELS / "Scenes.mdl"], model_name="Scenes.RigidPair",
                            stop=1.0, interval=0.01, rtol=1e-8, cache=False)
    first = free.time[np.flatnonzero(free["p2.pos[1]"] <= 0.5)[0]]
    with pytest.raises(SimulationError) as info:
        springc.simulate([MODELS / "Scenes.mdl", path], model_name="Checked", stop=1.0,
                         interval=0.01, rtol=1e-8, cache=False)
    assert info.value.message == \
        f"assertion failed at t = {first:.9g}: p2 swung past x = 0.5"
    assert info.value.span is not None and info.value.span.line == 4
