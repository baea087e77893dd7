"""A relation that switches and switches back within one accepted step is an event
(simulation/events.py, ``first_switch``): the relations are checked at inner points
of each step's dense output too, not only at its end. The MSL's CoupledClutches
needs it: a clutch's transmitted torque dips under its breakaway limit while every
state moves slowly (the solver takes long steps). And the message of an event iteration
that cycles names what moves."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError

MODEL = '''\
model Window
  Real x(start = 0, fixed = true) "constant: the solver's steps grow tenfold";
  discrete Real tOn(start = -1, fixed = true);
  discrete Real tOff(start = -1, fixed = true);
  Integer entries(start = 0, fixed = true);
equation
  der(x) = 0;
  when time*(1 - time) > 0.2 then
    tOn = time;
    entries = pre(entries) + 1;
  end when;
  when time*(1 - time) < 0.2 then
    tOff = time;
  end when;
end Window;
'''


def test_a_window_inside_one_step_is_found(tmp_path: Path) -> None:
    path = tmp_path / "Window.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.5, error_control="off")
    # time (1 - time) > 0.2 on ((1 - sqrt(0.2))/2, (1 + sqrt(0.2))/2)
    on, off = (1 - np.sqrt(0.2)) / 2, (1 + np.sqrt(0.2)) / 2
    assert abs(float(np.asarray(result["tOn"])[-1]) - on) < 1e-9
    assert abs(float(np.asarray(result["tOff"])[-1]) - off) < 1e-9
    assert float(np.asarray(result["entries"])[-1]) == 1.0


FLIP = '''\
model Flip
  Real x(start = 0, fixed = true);
  Real y;
equation
  der(x) = 1;
  y = if y > 0 then -1 else 1;
end Flip;
'''


def test_a_cycle_of_period_two_is_named(tmp_path: Path) -> None:
    """An event iteration that alternates between two states names the relation that
    moves (the check compares each of two passes, not the second with the first's
    start, which is the same state again)."""
    path = tmp_path / "Flip.mo"
    path.write_text(FLIP)
    with pytest.raises(SimulationError) as caught:
        springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                         error_control="off")
    assert str(caught.value).splitlines()[0] == (
        "error: the event iteration at time 0 did not settle in 100 passes: y > 0 keep "
        "changing")
