"""cat, matrix, outerProduct, skew, diagonal, linspace, semiLinear, matrix power and
'[:]' dimensions sized by the binding: exact flat equations and located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.ir import expr as x
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, body: str) -> FlatModel:
    path = tmp_path / "m.mo"
    path.write_text(f"model M\n{body}end M;\n")
    return flatten_files([path], None)


def rhs(tmp_path: Path, declaration: str) -> list[str]:
    """The right-hand sides of the binding equations of ``declaration``."""
    m = flat_of(tmp_path, f"  Real v[3] = {{1, 2, time}};\n  {declaration}\n")
    return [x.to_text(e.rhs) for e in m.equations[3:]]


def parameter_values(m: FlatModel) -> dict[str, object]:
    """Every parameter's value through the bindings of the others."""
    bindings = {v.name: v.binding for v in m.parameters if v.binding is not None}
    values: dict[str, object] = {}
    while len(values) < len(bindings):
        for name, binding in bindings.items():
            if name not in values and x.variables(binding) <= values.keys():
                values[name] = x.evaluate(binding, values)
    return values


def error_of(tmp_path: Path, body: str) -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flat_of(tmp_path, body)
    (err,) = errors_of(info.value)
    assert err.span is not None
    return f"{err.span.line}:{err.span.column}: {err.message}"


@pytest.mark.parametrize(("declaration", "expected"), [
    ("Real c[5] = cat(1, {1, 2}, v);", ["1", "2", "v[1]", "v[2]", "v[3]"]),
    ("Real c[2, 3] = cat(2, [1; 2], [3, 4; 5, v[3]]);", ["1", "3", "4", "2", "5", "v[3]"]),
    ("Real m[3, 1] = matrix(v);", ["v[1]", "v[2]", "v[3]"]),
    ("Real o[2, 3] = outerProduct({1, 2}, v);",
     ["v[1]", "v[2]", "v[3]", "2 * v[1]", "2 * v[2]", "2 * v[3]"]),
    ("Real s[3, 3] = skew(v);",
     ["0", "-v[3]", "v[2]", "v[3]", "0", "-v[1]", "-v[2]", "v[1]", "0"]),
    ("Real d[2, 2] = diagonal({v[1], 7});", ["v[1]", "0", "0", "7"]),
    ("Real l[4] = linspace(1, v[3], 4);",
     ["1", "1 + (v[3] - 1) / 3", "1 + 2 * (v[3] - 1) / 3", "v[3]"]),
    ("Real y = semiLinear(v[3] - 1, 2, 3);",
     ["noEvent(if v[3] - 1 >= 0 then 2 * (v[3] - 1) else 3 * (v[3] - 1))"]),
    ("Real y[2] = semiLinear({-2, 4}, 2, 3);", ["-6", "8"]),
    ("Real P[2, 2] = [1, 2; 3, v[3]] ^ 2;",
     ["7", "2 + 2 * v[3]", "3 + v[3] * 3", "6 + v[3] * v[3]"]),
    ("Real P[2, 2] = [1, 2; 3, v[3]] ^ 0;", ["1", "0", "0", "1"]),
    ("Real y = max(v);", ["max(max(v[1], v[2]), v[3])"]),
    ("Real z[2, 2] = zeros(2, 2) + fill(v[3], 2, 2);", ["v[3]", "v[3]", "v[3]", "v[3]"]),
    ("Real w[:] = {v[3], 5};", ["v[3]", "5"]),
])
def test_builtin_values(tmp_path: Path, declaration: str, expected: list[str]) -> None:
    assert rhs(tmp_path, declaration) == expected


def test_linspace_of_constants_is_exact(tmp_path: Path) -> None:
    m = flat_of(tmp_path, "  parameter Real l[5] = linspace(0, 1, 5);\n")
    assert [x.evaluate(v.binding, {}) for v in m.parameters] == [0, 0.25, 0.5, 0.75, 1]


def test_colon_dimensions_of_parameters_and_matrices(tmp_path: Path) -> None:
    m = flat_of(tmp_path, "  parameter Real a[:] = {1, 2, 3};\n"
                          "  parameter Real A[:, :] = [1, 2; 3, 4];\n"
                          "  Real y[size(a, 1)] = a * time;\n")
    assert [v.name for v in m.variables] == ["a[1]", "a[2]", "a[3]", "A[1,1]", "A[1,2]",
                                             "A[2,1]", "A[2,2]", "y[1]", "y[2]", "y[3]"]


@pytest.mark.parametrize(("body", "message"), [
    ("  Real x[:];\nequation\n  x = {1};\n",
     "2:10: the size of dimension 1 of 'x' ('[:]') is not given by a binding"),
    ("  Real x[2, :] = {1, 2};\n",
     "2:18: 'x' has '[:]' as dimension 2, but its value has size [2]"),
    ("  Real c[3] = cat(1, {1}, 2);\n", "2:27: the arguments of 'cat' must be arrays, found "
     "a scalar"),
    ("  Real c[3] = cat(2, {1}, {1, 2});\n", "2:19: dimension 2 does not exist: the arrays "
     "have 1"),
    ("  Real s[3, 3] = skew({1, 2});\n", "2:23: 'skew' needs a vector of size 3"),
    ("  Real l[1] = linspace(0, 1, 1);\n", "2:30: 'linspace' needs at least 2 points, "
     "found 1"),
    ("  Real P[2, 3] = [1, 2, 3; 4, 5, 6] ^ 2;\n", "2:18: '^' of an array needs a square "
     "matrix, found [2, 3]; use '.^' for element-wise powers"),
    ("  Real P[2, 2] = [1, 2; 3, 4] ^ 1.5;\n", "2:18: the exponent of a matrix power must "
     "be a constant Integer >= 0"),
])
def test_misuse_is_located(tmp_path: Path, body: str, message: str) -> None:
    assert error_of(tmp_path, body) == message


def test_symmetric_block_subscripts_and_logical_arrays(tmp_path: Path) -> None:
    m = flat_of(tmp_path, "  parameter Integer x[3, 3] = [1, 2, 3; 4, 5, 6; 7, 8, 9];\n"
                          "  parameter Integer y[:, :] = x[2:3, 1:2];\n"
                          "  parameter Integer s[3, 3] = symmetric(x);\n"
                          "  parameter Boolean b[2] = {true, false} and {true, true};\n")
    values = parameter_values(m)
    assert [values[f"y[{i},{j}]"] for i in (1, 2) for j in (1, 2)] == [4, 5, 7, 8]
    assert [values[f"s[{i},{j}]"] for i in (1, 2, 3) for j in (1, 2, 3)] == \
        [1, 2, 3, 2, 5, 6, 3, 6, 9]
    assert [values["b[1]"], values["b[2]"]] == [True, False]


def test_flexible_function_output_grows_by_cat(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  function positive
    input Integer u[:];
    output Integer p[:];
  algorithm
    for i in 1:size(u, 1) loop
      if u[i] > 0 then
        p := cat(1, p, u[i:i]);
      end if;
    end for;
  end positive;
  parameter Integer a[:] = {-2, 1, 0, -1, 2};
  parameter Integer q[:] = positive(a);
""")
    assert [v.name for v in m.parameters][-2:] == ["q[1]", "q[2]"]
    values = parameter_values(m)
    assert [values["q[1]"], values["q[2]"]] == [1, 2]
