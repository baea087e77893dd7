"""``delay`` while flattening (3.7.4.1): the flat call kept, and the errors of a delay
time that is not a parameter expression without delayMax, a delayMax that is not
one, and a delay time above delayMax."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import SpringcError
from springc.ir import expr as x
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def test_delay_stays_a_call_of_the_flat_model(tmp_path: Path) -> None:
    path = tmp_path / "M.mo"
    path.write_text("model M\n  parameter Real tau = 1;\n  Real x(start = 1, fixed = true);\n"
                    "  Real y;\nequation\n  der(x) = -delay(x, tau);\n"
                    "  y = delay(2 * x, 0.5 * tau, 1.0);\nend M;\n")
    m = flatten_files([path], None)
    assert [x.to_text(e.rhs) for e in m.equations] == [
        "-delay(x, tau)", "delay(2 * x, 0.5 * tau, 1.0)"]


ERRORS = {
    "variable delay time": (
        "y = delay(x, a);",
        "M.mo:7:16: error: the delay time of delay(expr, delayTime) must be a parameter "
        "expression\n"
        "    7 |   y = delay(x, a);\n"
        "      |                ^\n"
        "help: give a bound for a delay time that varies: delay(expr, delayTime, "
        "delayMax) (Modelica 3.6, section 3.7.4.1)"),
    "variable delayMax": (
        "y = delay(x, a, b);",
        "M.mo:7:19: error: delayMax of delay(expr, delayTime, delayMax) must be a "
        "parameter expression\n"
        "    7 |   y = delay(x, a, b);\n"
        "      |                   ^\n"
        "help: bound the delay time by a parameter or constant (Modelica 3.6, section "
        "3.7.4.1)"),
    "delay time above delayMax": (
        "y = delay(x, 5.5, 1.0);",
        "M.mo:7:7: error: the delay time (5.5) exceeds delayMax (1)\n"
        "    7 |   y = delay(x, 5.5, 1.0);\n"
        "      |       ^^^^^^^^^^^^^^^^^^\n"
        "help: delayTime must lie between 0 and delayMax (Modelica 3.6, section 3.7.4.1)"),
}


@pytest.mark.parametrize("name", ERRORS)
def test_bad_delay_arguments_are_located(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                         name: str) -> None:
    equation, expected = ERRORS[name]
    monkeypatch.chdir(tmp_path)
    Path("M.mo").write_text("model M\n  Real x, y;\n  Real a = 1.0, b = 2.0;\n"
                            "equation\n  x = sin(time);\n\n"
                            f"  {equation}\nend M;\n")
    with pytest.raises(SpringcError) as info:
        flatten_files([Path("M.mo")], None)
    assert str(info.value) == expected
