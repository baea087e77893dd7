"""Models for notebooks: compiled from a string (errors in ``<string>``), and their
simplified and flat equations as LaTeX."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import FlattenError, ParseError, UsageError

ROOT = Path(__file__).resolve().parents[2]
SEED = ROOT / "models" / "SpringMass.mdl"

ACCEL = (r"g_{%d} - \frac{\mathrm{spring.dir}_{%d} \mathrm{spring.k} \left(- \mathrm{spring.l}"
         r" + \mathrm{spring.x}\right)}{\mathrm{mass.m} \mathrm{spring.x}}")
POS = [r"\dot{\mathrm{mass.pos}}_{1} &= \mathrm{mass.v}_{1} \\",
       r"\dot{\mathrm{mass.pos}}_{2} &= \mathrm{mass.v}_{2} \\"]
LENGTH = r"\mathrm{spring.x} &= \sqrt{\mathrm{spring.dir}_{1}^{2} + \mathrm{spring.dir}_{2}^{2}} \\"
DIR = [r"\mathrm{spring.dir}_{1} &= - \mathrm{center}_{1} + \mathrm{mass.pos}_{1} \\",
       r"\mathrm{spring.dir}_{2} &= - \mathrm{center}_{2} + \mathrm{mass.pos}_{2} \\"]
ACCELS = [r"\dot{\mathrm{mass.v}}_{1} &= " + ACCEL % (1, 1) + r" \\",
          r"\dot{\mathrm{mass.v}}_{2} &= " + ACCEL % (2, 2)]


def test_a_string_simulates_as_its_file() -> None:
    text = SEED.read_text(encoding="utf-8")
    from_string = springc.load_model_from_string(text, cache=False)
    from_file = springc.compile_model(SEED, cache=False)
    assert from_string.name == "SpringMass"
    assert from_string.options.files == ()
    a = springc.simulate(from_string, stop=2.0, parameters={"spring.k": 50.0})
    b = springc.simulate(from_file, stop=2.0, parameters={"spring.k": 50.0})
    assert a.names == b.names
    assert np.array_equal(a.time, b.time) and np.array_equal(a.values, b.values)


def test_a_string_is_cached_by_its_text(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    text = "model A\n  Real x(start = 1, fixed = true);\nequation\n  der(x) = -x;\nend A;\n"
    first = springc.load_model_from_string(text)
    again = springc.load_model_from_string(text)
    other = springc.load_model_from_string(text.replace("-x", "-2 * x"))
    assert (first.cached, again.cached, other.cached) == (False, True, False)
    assert again.path == first.path and other.path != first.path
    result = springc.simulate(other, stop=1.0, interval=0.5, solver="rk4", step=1e-3)
    assert abs(result["x"][-1] - np.exp(-2.0)) < 1e-12


def test_a_syntax_error_is_located_in_the_string() -> None:
    text = "model A\n  Real x;\nequation\n  der(x) = -x +;\nend A;\n"
    with pytest.raises(ParseError) as info:
        springc.load_model_from_string(text)
    assert str(info.value) == (
        "<string>:4:16: error: unexpected ';', expected one of: '(', '[', identifier, "
        "'{', 'false', ...\n"
        "    4 |   der(x) = -x +;\n"
        "      |                ^")


def test_a_flatten_error_is_located_in_the_string() -> None:
    text = "model A\n  Real x;\n  Sprung s;\nequation\n  der(x) = -x;\nend A;\n"
    with pytest.raises(FlattenError) as info:
        springc.load_model_from_string(text, "A")
    assert str(info.value) == ("<string>:3:3: error: unknown class 'Sprung'\n"
                               "    3 |   Sprung s;\n"
                               "      |   ^^^^^^\n"
                               "help: did you mean 'Spring'? (searched the files named, "
                               "then the bundled models)")


def test_the_text_must_be_a_string() -> None:
    with pytest.raises(UsageError, match="the model text must be a str, not bytes"):
        springc.load_model_from_string(b"model A end A;")  # type: ignore[arg-type]


def test_equations_render_as_latex() -> None:
    model = springc.compile_model(SEED)
    simplified = model.equations()._repr_latex_()
    assert simplified == "$$" + "\n".join([
        r"\begin{aligned}", *POS, *DIR, LENGTH, *ACCELS, r"\end{aligned}"]) + "$$"
    flat = model.flat_equations()._repr_latex_()
    assert flat == "$$" + "\n".join([
        r"\begin{aligned}", *POS, LENGTH, *DIR, *ACCELS, r"\end{aligned}"]) + "$$"
    assert model.flat_equations().latex() == "\n".join([
        r"\begin{align}", *POS, LENGTH, *DIR, *ACCELS, r"\end{align}"]) + "\n"
    assert str(model.flat_equations()).startswith("model SpringMass\n")
    text = str(model.equations()).splitlines()
    assert text[0] == "model SpringMass: 4 states, 3 observed, 11 parameters"
    assert text[7:10] == ["  der(mass.pos[1]) := mass.v[1]", "  der(mass.pos[2]) := mass.v[2]",
                          "  spring.dir[1] := mass.pos[1] - center[1]"]
    assert repr(model.equations()) == str(model.equations())
