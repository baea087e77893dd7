"""Model names equal to identifiers of the generated module must not shadow them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import CodegenError

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


def test_model_names_that_look_internal_are_sanitized(tmp_path: Path) -> None:
    # _A0, _c1 and _it are names of the generated code's own temporaries; as model
    # names they become identifiers of their own.
    model = tmp_path / "internal.mdl"
    model.write_text("model Internal\n  parameter Real _c1 = 4;\n"
                     "  Real _it(start = 1, fixed = true), _A0(start = 0, fixed = true);\n"
                     "equation\n  der(_it) = _A0;\n  der(_A0) = -_c1 * _it;\nend Internal;\n")
    result = springc.simulate([model], stop=1.0, interval=0.25, rtol=1e-10, atol=1e-12,
                              cache=False)
    assert np.max(np.abs(result["_it"] - np.cos(2 * result.time))) < 1e-8


def test_model_names_the_generated_code_binds_are_refused(tmp_path: Path) -> None:
    model = tmp_path / "reserved.mdl"
    model.write_text("model Reserved\n  Real _r0_1(start = 1, fixed = true);\nequation\n"
                     "  der(_r0_1) = -_r0_1;\nend Reserved;\n")
    with pytest.raises(CodegenError) as caught:
        springc.compile_model([model], cache=False)
    assert caught.value.message == ("the name '_r0_1' is reserved for springc's generated "
                                    "code")
