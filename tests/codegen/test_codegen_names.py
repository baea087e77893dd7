"""Model names equal to identifiers of the generated module must not shadow them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc

# An undamped oscillator whose names are the generated code's own identifiers.
CLASHING = """model Clash
  parameter Real x0 = 0.5, n = 4, values = 1, rhs = 0, start = 2, given = 1, X = 1;
  Real out(start = x0), dx(start = rhs);
equation
  der(out) = dx;
  der(dx) = -n*out*values*given*X;
end Clash;
"""


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_generated_identifiers_are_not_shadowed(tmp_path: Path, backend: str) -> None:
    model = tmp_path / "clash.mdl"
    model.write_text(CLASHING)
    result = springc.simulate([model], stop=1.0, interval=0.25, rtol=1e-10, atol=1e-12,
                              backend=backend, cache=False)
    times = result.time
    # out(0) = 0.5, dx(0) = 0, omega = sqrt(n) = 2: out = 0.5 cos(2 t).
    assert np.max(np.abs(result["out"] - 0.5 * np.cos(2 * times))) < 1e-8
