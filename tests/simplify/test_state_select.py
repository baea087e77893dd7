"""stateSelect honoured after state selection (Modelica 3.6 section 4.8.7.1): valid
models (their states) and invalid ones (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimplifyError
from springc.pipeline.files import flatten_files
from springc.simplify import simplify


def _states(folder: Path, text: str) -> list[str]:
    path = folder / "m.mo"
    path.write_text(text)
    return [s.name for s in simplify(flatten_files([path])).ode.states]


def test_never_and_always_honoured(tmp_path: Path) -> None:
    text = """\
model M
  Real x(stateSelect = StateSelect.never);
  Real y(start = 1, fixed = true);
  Real v(stateSelect = StateSelect.always, start = 0, fixed = true);
equation
  der(y) = -y;
  x = 2 * y;
  der(v) = 5;
end M;
"""
    assert _states(tmp_path, text) == ["y", "v"]


ALWAYS = """\
model B
  Real phi(start = 1, fixed = true, stateSelect = StateSelect.always);
  Real w(start = 0, fixed = true);
  Real dphi(stateSelect = StateSelect.always);
  Real y;
equation
  w = der(phi);
  der(w) = -4 * phi;
  dphi = der(phi);
  y = 3 * w;
end B;
"""


def test_always_without_a_derivative_made_a_state(tmp_path: Path) -> None:
    # der(dphi) appears nowhere: index reduction differentiates dphi = der(phi) and
    # keeps dphi as the state in place of w (MultiBody's RollingWheelSet:
    # der_theta1 = der(theta1), StateSelect.always)
    assert _states(tmp_path, ALWAYS) == ["phi", "dphi"]
    path = tmp_path / "m.mo"
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.25, rtol=1e-10, atol=1e-12, error_control="off")
    # phi'' = -4 phi, phi(0) = 1, phi'(0) = w(0) = 0: phi = cos 2t
    t = np.asarray(result.time)
    assert np.allclose(result["phi"], np.cos(2 * t), rtol=0, atol=1e-8)
    assert np.allclose(result["dphi"], -2 * np.sin(2 * t), rtol=0, atol=1e-8)
    assert np.allclose(result["y"], -6 * np.sin(2 * t), rtol=0, atol=1e-8)


@pytest.mark.parametrize(("text", "expected"), [
    ("""\
model M
  Real x(stateSelect = StateSelect.never);
equation
  der(x) = time;
end M;
""", ("'x' has stateSelect = StateSelect.never but must be a state: its derivative "
      "appears and no other variable can be integrated in its place", 2,
      "StateSelect.never forbids a variable as a state; remove the attribute or give the "
      "model another variable to integrate (Modelica 3.6, section 4.8.7.1)")),
    ("""\
model M
  Real v(stateSelect = StateSelect.always) = if time < 1e-5 then 1.0 else 5.0;
end M;
""", ("'v' has stateSelect = StateSelect.always but cannot be a state: the equations "
      "determine it directly, and differentiated they leave no other variable to "
      "compute in its place", 2,
      "StateSelect.always requires the variable to be a state; remove the attribute, or "
      "give the model another variable that these equations determine (Modelica 3.6, "
      "section 4.8.7.1)")),
])
def test_contradicted(tmp_path: Path, text: str, expected: tuple[str, int, str]) -> None:
    with pytest.raises(SimplifyError) as info:
        _states(tmp_path, text)
    err = info.value
    assert (err.message, err.span.line if err.span else 0, err.hint) == expected


def test_always_on_two_variables_of_one_degree_of_freedom(tmp_path: Path) -> None:
    # dphi and y are both w (up to a factor): one of them only can be a state
    text = ALWAYS.replace("Real y;", "Real y(stateSelect = StateSelect.always);")
    with pytest.raises(SimplifyError) as info:
        _states(tmp_path, text)
    assert (info.value.message, info.value.span.line if info.value.span else 0) == (
        "'y' has stateSelect = StateSelect.always but cannot be a state: the equations "
        "determine it directly, and differentiated they leave no other variable to "
        "compute in its place", 5)
