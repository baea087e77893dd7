"""The probe of scipy's first step size is a point a step tries: ``select_initial_step``
evaluates the model at ``t + h0``, where ``h0`` reaches the next event when the states
barely move. A torn block warm started at ``t`` may have no converging Newton iterate
there (``atan(s - 10 t) = 0.1`` from 10 away; a transistor's Newton system in
Electrical.Analog's HeatingNPN_NORGate, warm started 20 s before): the probe is then
rejected like a step's trial point instead of stopping the run. DOP853's dense output
evaluates three more stages after the step, outside it: where their Newton system
fails from the warm start the step left, it is solved again from the accepted
point's and the step start's (branch nor; before, DOP853 stopped here: "the nonlinear
system for s did not converge at time 0.0316")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = '''\
model Probe
  Real x(start = 1, fixed = true);
  Real s(start = 0);
  Real y "a relation: the event loop's driver";
equation
  atan(s - 10*time) = 0.1;
  der(x) = 1e-3*s;
  y = if time > 0.5 then 1 else 0;
end Probe;
'''


@pytest.mark.parametrize("solver", ["rk45", "dop853"])
def test_a_failing_probe_is_rejected(tmp_path: Path, solver: str) -> None:
    path = tmp_path / "Probe.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              solver=solver,
                              interval=0.25, rtol=1e-6, atol=1e-9, error_control="off")
    t = np.asarray(result.time)
    c = math.tan(0.1)
    assert np.allclose(np.asarray(result["s"]), 10 * t + c, rtol=0, atol=1e-9)
    assert np.allclose(np.asarray(result["x"]), 1 + 1e-3 * (5 * t**2 + c * t),
                       rtol=0, atol=1e-8)
