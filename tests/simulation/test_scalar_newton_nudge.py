"""A torn block of one unknown whose derivative is exactly 0 at the warm start, where
the residual is not (``v*i = 6`` with ``v = 2 s``, ``i = 3 s`` from ``s = 0``; the
MSL's ``Sources.DCPowerSupply`` in its constant-power branch, ``P0 = v*(-i)``, from
an empty buffer capacitor in DemoPowerSupplyWithBuffer): Newton's step leaves the
point by ``NEWTON_NUDGE`` (relative) instead of dividing by zero, and converges to
the root beside it, ``s = 1``; then ``x = exp(-t)``."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = '''\
model Nudge
  Real x(start = 1, fixed = true);
  Real s(start = 0);
  Real v;
  Real i;
equation
  v = 2*s;
  i = 3*s;
  v*i = 6;
  der(x) = -s*x;
end Nudge;
'''


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_zero_derivative_at_the_start_is_left(tmp_path: Path, backend: str) -> None:
    path = tmp_path / "Nudge.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend=backend, engine="scipy", stop=1.0,
                              interval=0.25, rtol=1e-10, atol=1e-12, error_control="off")
    assert np.allclose(np.asarray(result["s"]), 1.0, rtol=0, atol=1e-12)
    expected = [math.exp(-float(t)) for t in result.time]
    assert np.allclose(np.asarray(result["x"]), expected, rtol=1e-8, atol=0)
