"""Unit strings and the unit check of flat models (warnings; errors with --strict-units)."""

from __future__ import annotations

import math
import re
from fractions import Fraction
from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.errors import render
from springc.pipeline import CompileOptions, compile_files, flatten_files
from springc.units import UnitSyntaxError, canonical, check_units, parse_unit

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"


def unit(text: str) -> tuple[tuple[Fraction, ...], float]:
    parsed = parse_unit(text)
    assert parsed is not None
    return parsed.exponents, parsed.scale


def si(scale: float = 1.0, **exponents: int) -> tuple[tuple[Fraction, ...], float]:
    return (tuple(Fraction(exponents.get(b, 0)) for b in
                  ("kg", "m", "s", "A", "K", "mol", "cd")), scale)


@pytest.mark.parametrize(("text", "expected"), [
    ("N", si(kg=1, m=1, s=-2)), ("kg.m/s2", si(kg=1, m=1, s=-2)),
    ("J", si(kg=1, m=2, s=-2)), ("N.m", si(kg=1, m=2, s=-2)),
    ("W", si(kg=1, m=2, s=-3)), ("V", si(kg=1, m=2, s=-3, A=-1)),
    ("Ohm", si(kg=1, m=2, s=-3, A=-2)), ("Pa", si(kg=1, m=-1, s=-2)),
    ("Hz", si(s=-1)), ("s-1", si(s=-1)), ("1/s", si(s=-1)), ("rad/s", si(s=-1)),
    ("1", si()), ("rad", si()), ("m/s", si(m=1, s=-1)),
    ("W/(m2.K)", si(kg=1, s=-3, K=-1)), ("J/(kg.K)", si(m=2, s=-2, K=-1)),
    ("mm", si(1e-3, m=1)), ("kN", si(1e3, kg=1, m=1, s=-2)), ("ms", si(1e-3, s=1)),
    ("kg", si(kg=1)), ("g", si(1e-3, kg=1)), ("min", si(60, s=1)),
    ("kmol", si(1e3, mol=1)), ("mm2", si(1e-6, m=2)), ("dam", si(10, m=1)),
])
def test_unit_strings(text: str, expected: tuple[tuple[Fraction, ...], float]) -> None:
    dims, scale = unit(text)
    assert dims == expected[0]
    assert math.isclose(scale, expected[1], rel_tol=1e-12)


def test_unit_text_and_canonical_form() -> None:
    n = parse_unit("N")
    assert n is not None and str(n) == "N"
    assert canonical(n) == "kg.m/s2"
    pa = parse_unit("Pa")
    assert pa is not None and canonical(pa) == "kg/(m.s2)"
    mm = parse_unit("mm")
    assert mm is not None and canonical(mm) == "0.001*m"
    assert parse_unit("") is None


@pytest.mark.parametrize("text", ["Nm", "m//s", "(m", "furlong", "m.", "m*s"])
def test_unit_strings_refused(text: str) -> None:
    with pytest.raises(UnitSyntaxError):
        parse_unit(text)


def warnings_of(tmp_path: Path, declarations: str, equations: str) -> list[str]:
    path = tmp_path / "M.mo"
    path.write_text(f"model M\n{declarations}equation\n{equations}end M;\n")
    return [render(w, kind="warning") for w in check_units(flatten_files([path]))]


MECH = ('  parameter Real m(unit = "kg") = 2;\n'
        '  parameter Real T(unit = "s") = 1;\n'
        '  Real x(unit = "m", start = 1);\n'
        '  Real v(unit = "m/s");\n'
        '  Real f(unit = "N");\n')


def test_consistent_units_pass(tmp_path: Path) -> None:
    # kg*m/s^2 = N; der(x) in m/s equals v; literals take any unit; sqrt halves
    # exponents; sin of a dimensionless ratio; abs, min and max keep units.
    assert warnings_of(tmp_path, MECH + '  Real y;\n',
                       "  der(x) = v;\n"
                       "  f = m*x/T^2 + abs(m*v/T) - min(f, 2*m*v/T);\n"
                       "  der(v) = f/m + 3*sin(time/T)*x/T^2 + 0*sqrt(x*x)/T^2;\n"
                       "  y = (max(x, 1) + 2)*atan2(x, 2*x);\n") == []


def test_force_plus_length_warns(tmp_path: Path) -> None:
    assert warnings_of(tmp_path, MECH + '  Real y;\n',
                       "  der(x) = v;\n  der(v) = f/m;\n  f = -m*x/T^2;\n"
                       "  y = f + x;\n") == [
        f"{tmp_path / 'M.mo'}:12:3: warning: unit mismatch: 'N' + 'm'\n"
        "   12 |   y = f + x;\n"
        "      |   ^^^^^^^^^\n"
        "note: in `y = f + x`"]


def test_derivative_of_a_length_is_not_a_length(tmp_path: Path) -> None:
    found = warnings_of(tmp_path, MECH, "  der(x) = x/T;\n  der(v) = x;\n  f = m*v/T;\n")
    assert [w.splitlines()[0].split(": ", 1)[1] for w in found] == [
        "warning: unit mismatch: 'm/s2' = 'm'"]


def test_prefixes_are_different_units(tmp_path: Path) -> None:
    found = warnings_of(tmp_path, '  Real a(unit = "mm");\n  Real b(unit = "m");\n'
                        '  Real c(unit = "kN");\n  Real d(unit = "kg.m/s2");\n',
                        "  a = b;\n  b = time;\n  c = 1000*d;\n  d = c;\n")
    assert [w.splitlines()[0].split(": ", 1)[1] for w in found] == [
        "warning: unit mismatch: 'mm' = 'm'",
        "warning: unit mismatch: 'm' = 's'",
        "warning: unit mismatch: 'kg.m/s2' = 'kN'"]


def test_functions_of_dimensionless_arguments(tmp_path: Path) -> None:
    found = warnings_of(tmp_path, '  Real x(unit = "m");\n  Real w(unit = "rad/s");\n'
                        '  Real y;\n',
                        "  x = time;\n  w = 1;\n  y = sin(w*time) + exp(x) + cos(time);\n")
    assert [w.splitlines()[0].split(": ", 1)[1] for w in found] == [
        "warning: unit mismatch: 'm' = 's'",
        "warning: unit mismatch: 'm' given to exp, which takes a dimensionless argument "
        "('1' or 'rad')"]


def test_bindings_starts_relations_and_branches(tmp_path: Path) -> None:
    found = warnings_of(tmp_path,
                        '  parameter Real l(unit = "m") = 1;\n'
                        '  parameter Real k(unit = "N/m") = l;\n'
                        '  Real x(unit = "m", start = k);\n'
                        '  Real y(unit = "m");\n',
                        "  der(x) = if x > k then 0 else 1;\n"
                        "  y = if time > 1 then x else k;\n")
    assert [w.splitlines()[0].split(": ", 1)[1] for w in found] == [
        "warning: unit mismatch: 'N/m' = 'm'",
        "warning: unit mismatch: 'm' = 'N/m'",
        "warning: unit mismatch: 'm' > 'N/m'",
        "warning: unit mismatch: if-branches 'm' and 'N/m'"]


def run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args), prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    return result.exit_code, result.stdout, result.stderr


BAD = ('model M\n  Real x(unit = "m");\n  Real f(unit = "N");\n  Real y;\nequation\n'
       '  der(x) = -x;\n  f = 2;\n  y = f + x;\nend M;\n')


def test_check_warns_and_strict_units_exit_1(tmp_path: Path) -> None:
    path = tmp_path / "M.mo"
    path.write_text(BAD)
    warning = (f"{path}:6:3: warning: unit mismatch: 'm/s' = 'm'\n"
               "    6 |   der(x) = -x;\n      |   ^^^^^^^^^^^\nnote: in `der(x) = -x`\n\n"
               f"{path}:8:3: warning: unit mismatch: 'N' + 'm'\n"
               "    8 |   y = f + x;\n      |   ^^^^^^^^^\nnote: in `y = f + x`\n")
    assert run("check", str(path)) == (0, "M: 3 unknowns, 3 equations, 0 parameters: "
                                       "balanced\n", warning)
    code, out, err = run("check", "--strict-units", str(path))
    assert (code, out) == (1, "")
    assert err == warning.replace("warning:", "error:") + "\n2 errors\n"


def test_warnings_survive_the_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "M.mo"
    path.write_text(BAD)
    options = CompileOptions((str(path),), backend="python")
    first = compile_files(options)
    again = compile_files(options)
    assert (first.cached, again.cached) == (False, True)
    texts = [render(w, kind="warning") for w in again.warnings]
    assert texts == [render(w, kind="warning") for w in first.warnings]
    assert [t.splitlines()[0] for t in texts] == [
        f"{path}:6:3: warning: unit mismatch: 'm/s' = 'm'",
        f"{path}:8:3: warning: unit mismatch: 'N' + 'm'"]


def bundled_models() -> list[str]:
    names = []
    for path in sorted(MODELS.glob("*.mdl")):
        text = path.read_text(encoding="utf-8")
        package = re.match(r"\s*package (\w+)", text)
        names += [f"{package[1]}.{name}" if package else name
                  for name in re.findall(r"^\s*model (\w+)", text, re.M)]
    return names


def test_bundled_models_have_no_unit_warnings() -> None:
    files = sorted(MODELS.glob("*.mdl"))
    names = bundled_models()
    assert len(names) == 29 and "EventScenes.BouncingBall" in names
    assert {name: [str(w) for w in check_units(flatten_files(files, name))]
            for name in names} == {name: [] for name in names}


def test_an_expression_deeper_than_the_stack_is_left_unchecked() -> None:
    from springc.errors import Span
    from springc.ir import expr as x
    from springc.ir import flat

    def span(line: int) -> Span:
        return Span("m.mo", line, 1, line, 2)

    def variable(name: str, unit: str) -> flat.Variable:
        return flat.Variable(name, "Real", "continuous", "", False, None,
                             flat.Attributes(unit=unit), "", "", span(1))

    deep: x.Expr = x.Var("f")
    for _ in range(50_000):
        deep = x.Neg(deep)
    origin = flat.Origin("equation", "")
    model = flat.FlatModel("M", (variable("f", "N"), variable("y", "m")),
                           (flat.Equation(x.Var("y"), deep, span(2), origin),
                            flat.Equation(x.Var("y"), x.Var("f"), span(3), origin)),
                           (), flat.Experiment(), span(1))
    assert [(str(w.span), w.message) for w in check_units(model)] == [
        ("m.mo:3:1", "unit mismatch: 'm' = 'N'")]


def library_models() -> list[str]:
    """The models and blocks of the bundled Modelica library (none is partial)."""
    names = []
    for path in sorted((MODELS / "Modelica").rglob("*.mo")):
        parts = path.relative_to(MODELS).with_suffix("").parts
        package = ".".join(parts[:-1] if path.name == "package.mo" else parts)
        names += [f"{package}.{m[2]}" for m in re.finditer(
            r"^\s*(partial\s+)?(?:model|block)\s+(\w+)", path.read_text(encoding="utf-8"),
            re.M) if not m[1]]
    return names


def test_bundled_library_has_no_unit_warnings(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_PATH", "")
    monkeypatch.setenv("MODELICAPATH", "")
    user = tmp_path / "Use.mo"
    user.write_text("model Use\nend Use;\n")
    names = library_models()
    assert len(names) == 54 and "Modelica.Blocks.Sources.Sine" in names
    assert {name: [str(w) for w in check_units(flatten_files([user], name))]
            for name in names} == {name: [] for name in names}
