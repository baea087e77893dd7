"""initial(), pre() and der() where values are computed outside the event code
(parameter bindings, start values, initial equations, when-equations): a value, or a
located error naming the model element; never an internal error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import CodegenError, SimulationError


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def write(tmp_path: Path, text: str) -> str:
    path = tmp_path / "m.mo"
    path.write_text(text)
    return str(path)


def test_initial_holds_in_bindings_and_start_values(tmp_path: Path) -> None:
    """Parameters and start values are computed in initialization: initial() is true."""
    model = write(tmp_path, "model I\n  parameter Real p = if initial() then 1 else 2;\n"
                  "  Real x(start = if initial() then p else 5, fixed = true);\n"
                  "equation\n  der(x) = -x;\nend I;\n")
    result = springc.simulate(model, stop=1.0, interval=0.5, rtol=1e-10, atol=1e-12)
    assert np.allclose(result["x"], np.exp(-np.array([0.0, 0.5, 1.0])), rtol=1e-8)


def test_initial_holds_in_an_initial_equation(tmp_path: Path) -> None:
    model = write(tmp_path, "model E\n  parameter Real p = 2;\n  Real x(start = 1);\n"
                  "  Real w;\ninitial equation\n  w = if initial() then p else 0;\n"
                  "equation\n  der(x) = -x;\n  der(w) = 0;\nend E;\n")
    result = springc.simulate(model, stop=1.0, interval=0.5)
    assert result["w"].tolist() == [2.0, 2.0, 2.0]


def test_der_in_a_when_equation_is_located(tmp_path: Path) -> None:
    """A sampled speed sensor (w = der(phi) in a when-clause, as ModelicaBook's
    SampleHold writes it): the code generator names the equation it cannot compute."""
    model = write(tmp_path, "model SH\n  Real phi(start = 0, fixed = true);\n"
                  "  Real om(start = 1, fixed = true);\n  discrete Real w;\nequation\n"
                  "  der(phi) = om;\n  der(om) = -phi;\n  when sample(0, 0.125) then\n"
                  "    w = der(phi);\n  end when;\nend SH;\n")
    with pytest.raises(CodegenError) as caught:
        springc.compile_model(model, backend="python")
    err = caught.value
    assert err.message == ("cannot generate code for Der expressions: der(phi) in the "
                           "when-equation of 'w'")
    assert err.span is not None and (err.span.line, err.span.column) == (9, 5)


@pytest.mark.parametrize("backend", ["numba", "python"])
def test_nan_in_a_linear_system_is_a_located_failure(tmp_path: Path, backend: str) -> None:
    """c = sqrt(1 - time) is NaN after t = 1 and enters a 3x3 linear system: the compiled
    loop used to stop with numba's LinAlgError; both loops name the time and variable."""
    model = write(tmp_path, "model LN\n  Real x(start = 1, fixed = true);\n  Real c;\n"
                  "  Real a;\n  Real b;\n  Real d;\nequation\n  der(x) = -a;\n"
                  "  c = sqrt(1 - time);\n  c*a + b + d = 1;\n  a - c*b + d = x;\n"
                  "  a + b - c*d = 2;\nend LN;\n")
    with pytest.raises(SimulationError) as caught:
        springc.simulate(model, stop=2.0, interval=0.5, backend=backend, solver="dop853")
    message = caught.value.message
    assert message.startswith(f"math domain error while computing c ({model}:9) at time 1")
    assert 1.0 <= float(message.rsplit("at time ", 1)[1]) < 1.1


def test_a_latch_through_pre_is_no_algebraic_loop(tmp_path: Path) -> None:
    """``y = a or (not c and pre(y))``: ``pre(y)`` is the value held from before the
    event, not an unknown of the equation, so there is no loop to solve (a loop solved
    as linear once replaced pre(y) by 0: the MSL's LogicalNetwork1 lost its latch)."""
    model = write(tmp_path, """model Latch
  Boolean a = time >= 0.5 and time < 1;
  Boolean c = time >= 1.5;
  Boolean held;
  Boolean y;
equation
  held = pre(y);
  y = a or (not c and held);
end Latch;
""")
    result = springc.simulate(model, backend="python", engine="scipy", stop=2.0,
                              interval=0.25, error_control="off")
    # set at 0.5 by a, held after a falls at 1, cleared by c at 1.5
    assert np.asarray(result["y"]).tolist() == [0, 0, 1, 1, 1, 1, 0, 0, 0]


def test_an_rs_flip_flop_latches_within_the_event(tmp_path: Path) -> None:
    """Two Nor gates and a ``pre`` (the MSL's Logical.RSFlipFlop): the event iteration
    goes on until ``pre(p) = p`` for the equation-defined ``p`` too (section 8.6), so a
    set pulse (a sample, true only at its instant) latches; the initial event too."""
    model = write(tmp_path, """model RS
  Boolean S = sample(0, 0.5);
  Boolean R = sample(0.25, 0.5);
  Boolean p;
  Boolean q;
initial equation
  pre(p) = true;
equation
  p = not (S or q);
  q = not (pre(p) or R);
end RS;
""")
    result = springc.simulate(model, backend="python", engine="scipy", stop=1.0,
                              interval=0.125, error_control="off")
    # set at 0, 0.5 and 1 (S), reset at 0.25 and 0.75 (R)
    assert np.asarray(result["q"]).tolist() == [1, 1, 0, 0, 1, 1, 0, 0, 1]
