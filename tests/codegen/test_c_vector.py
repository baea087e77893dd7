"""The C model in the vector layout (codegen/c_vector.py): loops over index tables give
the values of the scalar C file and of the Python module, and the exact text of a
small grouped file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.codegen import generate_c
from springc.pipeline import CompiledModel
from springc.pipeline.c_build import CLibrary, build_library

ROOT = Path(__file__).resolve().parents[2]
SCENES = str(ROOT / "models" / "Scenes.mdl")
RTOL = 1e-12
"""Grouped and scalar C compute the same operations in the same order; the Python
module too (numpy's slices and C's loops: the same double operations)."""
STRICT = ("-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror", "-Wno-unused-parameter",
          "-Wno-unused-variable", "-Wno-unused-const-variable", "-Wno-unused-function",
          "-Wno-unused-but-set-variable")
ROW = """model Row
  parameter Integer n = 4;
  parameter Real k = 2;
  parameter Real x0[n] = {i / 2 for i in 1:n};
  Real x[n](start = x0, each fixed = true);
  Real f[n];
equation
  for i in 1:n loop
    f[i] = k * x[i] * x[i];
    der(x[i]) = -f[i] + sin(time);
  end for;
end Row;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def _library(tmp_path: Path, model: CompiledModel, vector: bool | None) -> CLibrary:
    derived = model.compiled_from or model.derive()
    text = generate_c(derived.system, derived.flat_model, model.observed, vector).text
    folder = tmp_path / f"lib-{vector}"
    folder.mkdir()
    return CLibrary(text, build_library(text, folder))


def _close(a: np.ndarray, b: np.ndarray) -> None:
    np.testing.assert_allclose(a, b, rtol=RTOL, atol=1e-300)


def _compare(tmp_path: Path, model: CompiledModel, given: dict[str, float]) -> str:
    """The grouped file (by size) against the scalar file and the Python module:
    parameters (some given), start, rhs and observed at random points."""
    grouped, scalar = _library(tmp_path, model, None), _library(tmp_path, model, False)
    mod = model.module
    index = {name: i for i, name in enumerate(mod.PARAMETERS)}
    p = mod.parameters(given)
    for lib in (grouped, scalar):
        _close(lib.parameters({index[n]: v for n, v in given.items()}), p)
        _close(lib.start(p)[0], mod.start(p))
    rng = np.random.default_rng(3)
    for t in (0.0, 0.4, 1.7):
        x = mod.start(p) * (1 + 0.1 * rng.standard_normal(len(model.states)))
        z = mod.guesses(p)
        for lib in (grouped, scalar):
            code, dx = lib.rhs(t, x, p, z.copy())
            assert code == 0
            _close(dx, mod.rhs(t, x, p, z.copy()))
            code, out = lib.observed(t, x, p, z.copy())
            assert code == 0
            _close(out, mod.observed(t, x, p, z.copy()))
    assert "for (int _q" not in scalar.source
    return grouped.source


def test_a_chain_in_loops_equals_the_scalar_file_and_the_python_module(
        tmp_path: Path) -> None:
    model = springc.compile_model(SCENES, "Scenes.Chain", backend="python",
                                  parameters={"N": 64})
    source = _compare(tmp_path, model, {"k": 37.0, "L": 1.25})
    # one loop per shape: 63 springs between masses, 64 velocities (319 steps)
    assert "    /* 63 x s[2].s_rel := m[2].s - m[1].s " in source
    assert "    for (int _q = 0; _q < 64; _q++) {\n        dx[2 * _q] = x[1 + 2 * _q];\n" \
        in source


def test_a_cloth_grid_in_two_level_loops_equals_the_scalar_file(tmp_path: Path) -> None:
    model = springc.compile_model(SCENES, "Scenes.Cloth", backend="python",
                                  parameters={"N": 6, "M": 5})
    source = _compare(tmp_path, model, {"h": 0.12, "k_shear": 150.0})
    assert "for (int _r = 0; _r < " in source  # rows of the grid, each a run of columns


def test_a_group_with_one_member_left_over_from_its_runs_is_indexed_directly(
        tmp_path: Path) -> None:
    # the 8x8 cloth's parameters leave one member of a group outside its affine runs:
    # printed without a loop, its index read from a table at `_q` (no such variable:
    # the C compiler refused the file, and the 20x20 cloth ran on numba's loop)
    model = springc.compile_model(SCENES, "Scenes.Cloth", backend="python",
                                  parameters={"N": 8, "M": 8})
    source = _compare(tmp_path, model, {"h": 0.12, "k_shear": 150.0})
    body = source[source.index("springc_parameters(double *p"):]
    body = body[:body.index("\n}\n")]
    loops = body.count("for (int _q")
    assert loops and body.count("_q]") > 0
    assert all("for (int _q" in line or line.startswith("        ")
               for line in body.splitlines() if "_q" in line)


def test_the_text_of_a_small_grouped_file(tmp_path: Path) -> None:
    model = springc.load_model_from_string(ROW, "Row", backend="python", outputs=["f[2]"])
    derived = model.compiled_from or model.derive()
    text = generate_c(derived.system, derived.flat_model, model.observed, True).text
    start = text.index("SPRINGC_DATA int springc_pindex")
    assert text[start:text.index("SPRINGC_FN void springc_jacobian_pattern")] == GROUPED
    assert "#define SPRINGC_WORK_DOUBLES 4\n" in text
    # strict C99 with no mutable file-scope data (the tables are SPRINGC_DATA: const)
    scope = ("#", "/* ", "static const ", "SPRINGC_FN ", "SPRINGC_DATA ", "{", "}", "    ")
    assert all(line.startswith(scope) for line in text.splitlines() if line)
    assert build_library(text, tmp_path, STRICT)[:4] == b"\x7fELF"
    lib = CLibrary(text, build_library(text, tmp_path))
    p = lib.parameters({1: 3.0})  # k given; n and x0 from their bindings
    assert p.tolist() == [4.0, 3.0, 0.5, 1.0, 1.5, 2.0]
    x, z = lib.start(p)
    code, dx = lib.rhs(0.5, x, p, z)
    assert code == 0
    _close(dx, -3.0 * x * x + np.sin(0.5))


GROUPED = """SPRINGC_DATA int springc_pindex[4] = {
    1, 0, 1, 0,
};
SPRINGC_DATA double springc_pfloats[10] = {
    4.0, 2.0, 1.0, 2.0, 2.0, 2.0, 3.0, 2.0, 4.0, 2.0,
};
SPRINGC_DATA int springc_sindex[1] = {
    0,
};
SPRINGC_DATA double springc_sfloats[1] = {
    0.0,
};

SPRINGC_DATA int springc_index[2] = {
    1, 0,
};

SPRINGC_FN void springc_parameters(double *p, const int *given)
{
    /* 2 x k := 2  <string>:3 */
    for (int _q = 0; _q < 2; _q++) {
        p[springc_pindex[0 + _q]] = (given != 0 && given[springc_pindex[0 + _q]] != 0) \
? p[springc_pindex[0 + _q]] : springc_pfloats[springc_pindex[2 + _q]];
    }
    /* 4 x x0[1] := 1 / 2  <string>:4 */
    for (int _q = 0; _q < 4; _q++) {
        p[2 + _q] = (given != 0 && given[2 + _q] != 0) ? p[2 + _q] : \
springc_pfloats[2 + 2 * _q] / springc_pfloats[3 + 2 * _q];
    }
}

SPRINGC_FN void springc_default_parameters(double *p)
{
    springc_parameters(p, 0);
}

SPRINGC_FN int springc_start(const double *p, double *x, double *z)
{
    int _code = 0;
    for (int _i = 0; _i < 1; _i++) z[_i] = 0.0;
    /* 4 x x[1] := x0[1]  <string>:5 */
    for (int _q = 0; _q < 4; _q++) {
        x[_q] = p[2 + _q];
    }
    return _code;
}

SPRINGC_FN int springc_rhs(double t, const double *x, const double *p, double *z, double *dx)
{
    int _code = 0;
    double w[4];
    /* 4 x f[1] := k %2A x[1] %2A x[1]  <string>:9 */
    for (int _q = 0; _q < 4; _q++) {
        w[_q] = p[1] * x[_q] * x[_q];
    }
    /* 4 x der(x[1]) := -f[1] + sin(time)  <string>:10 */
    for (int _q = 0; _q < 4; _q++) {
        dx[_q] = -w[_q] + sin(t);
    }
    return _code;
}

SPRINGC_FN int springc_observed(double t, const double *x, const double *p, double *z, \
double *out)
{
    int _code = 0;
    double w[4];
    /* f[2] := k %2A x[2] %2A x[2]  <string>:9 */
    w[1] = p[1] * x[1] * x[1];
    for (int _q = 0; _q < 1; _q++) out[springc_index[1 + _q]] = w[springc_index[0 + _q]];
    return _code;
}

"""
