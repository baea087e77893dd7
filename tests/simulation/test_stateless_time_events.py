"""A model without states steps from output row to output row; a time event that
falls within the event-time tolerance (1e-12 relative) after a row is taken there, not
passed by (Modelica.Blocks.Examples.BusUsage on the reference's grid, interval
0.00039999999999995595: row 1250 is at 0.49999999999994493, 5.5e-14 before the steps'
event at 0.5, and the steps never switched)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc

MODEL = """model NoState
  Boolean b;
  Integer k;
equation
  b = time >= 0.5;
  k = 2 + (if time < 0.5 then 0 else 1);
end NoState;
"""


def test_a_time_event_just_after_an_output_row_is_taken(tmp_path: Path) -> None:
    path = tmp_path / "nostate.mo"
    path.write_text(MODEL)
    interval = 0.00039999999999995595
    result = springc.simulate([path], stop=2.0, interval=interval, engine="scipy",
                              backend="python", error_control="off")
    t = np.asarray(result.time)
    assert 0.5 - 1e-12 < t[1250] < 0.5
    expected = t > 0.5  # row 1250, just before the event, holds the left limit
    assert np.array_equal(np.asarray(result["b"]) > 0.5, expected)
    assert np.array_equal(np.asarray(result["k"]), np.where(expected, 3.0, 2.0))
    assert result.stats.time_events == 1
