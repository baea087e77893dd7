"""Parameters with ``fixed = false`` computed by an initial algorithm (section 8.6),
Booleans included, and an if-equation on such a parameter: its value is known only
once initialized, so the if-equation switches at run time (its branches the same
size, 8.3.4). Electrical.Analog.Sources.DCPowerSupply computes ``vLim``, ``iLim`` and
``cp`` so and switches its characteristic on ``cp`` (DemoPowerSupply was: "the
condition of an if-equation must be a parameter expression, but it depends on the
parameter 'dcPowerSupply.cp', which has no value")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = '''\
model Supply
  parameter Real V0 = 60;
  parameter Real P0 = 1200;
  parameter Real vLim(fixed = false);
  parameter Boolean cp(fixed = false);
  Real v;
  Real x(start = 0, fixed = true);
initial algorithm
  vLim := V0/2;
  cp := false;
  if vLim*V0 > P0 then
    cp := true;
    vLim := P0/V0;
  end if;
equation
  if cp then
    v = vLim*time;
  else
    v = V0*time;
  end if;
  der(x) = v;
end Supply;
'''


@pytest.mark.parametrize(("p0", "slope"), [(1200.0, 20.0), (2000.0, 60.0)])
def test_parameters_of_an_initial_algorithm(tmp_path: Path, p0: float, slope: float) -> None:
    # vLim*V0 = 1800: above P0 = 1200, cp and vLim = P0/V0 = 20; below 2000, v = V0*t
    path = tmp_path / "Supply.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.25, parameters={"P0": p0}, rtol=1e-10,
                              atol=1e-10, error_control="off")
    times = np.asarray(result.time)
    assert np.allclose(np.asarray(result["x"]), slope / 2 * times ** 2, rtol=0, atol=1e-8)
    assert np.allclose(np.asarray(result["v"]), slope * times, rtol=0, atol=1e-8)
