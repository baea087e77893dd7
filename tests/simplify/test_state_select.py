"""stateSelect honoured after state selection (Modelica 3.6 section 4.8.7.1): valid
models (their states) and invalid ones (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

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
""", ("'v' has stateSelect = StateSelect.always but is not a state: its derivative does "
      "not appear in the equations, which determine it directly", 2,
      "StateSelect.always requires the variable to be a state; remove the attribute, or "
      "write the model with der() of the variable (Modelica 3.6, section 4.8.7.1)")),
])
def test_contradicted(tmp_path: Path, text: str, expected: tuple[str, int, str]) -> None:
    with pytest.raises(SimplifyError) as info:
        _states(tmp_path, text)
    err = info.value
    assert (err.message, err.span.line if err.span else 0, err.hint) == expected
