"""A state that is the derivative of another (``der(r)``): index reduction keeps it
where the velocities are ``StateSelect.avoid`` copies of ``der(r)`` (MultiBody's
Body and BodyShape: ``v_0 = der(frame_a.r_0)`` twice on one frame, FreeBody). The
generated right-hand side reads ``der(r)`` from the states for ``r``'s derivative;
the trajectory is checked against the closed form of the oscillator."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc

DER_STATE = """model DerState
  parameter Real k = 4, m = 1;
  Real r(start = 1, fixed = true, stateSelect = StateSelect.avoid);
  Real v1(start = 0, fixed = true, stateSelect = StateSelect.avoid);
  Real v2(stateSelect = StateSelect.avoid);
  Real a1, a2;
equation
  v1 = der(r);
  v2 = der(r);
  a1 = der(v1);
  a2 = der(v2);
  m*a1 = -k*r;
end DerState;
"""


def test_a_derivative_is_a_state_of_the_generated_model(tmp_path: Path) -> None:
    path = tmp_path / "der_state.mo"
    path.write_text(DER_STATE)
    model = springc.compile_model(str(path), backend="python")
    assert model.states == ("r", "der(r)")
    result = springc.simulate(model, stop=3.0, interval=0.1, rtol=1e-10, atol=1e-12,
                              engine="scipy")
    t = result.time
    assert np.max(np.abs(result["r"] - np.cos(2 * t))) < 1e-7  # omega = sqrt(k/m) = 2
    assert np.max(np.abs(result["v2"] + 2 * np.sin(2 * t))) < 1e-7
    assert np.max(np.abs(result["a2"] + 4 * np.cos(2 * t))) < 1e-6
