"""The C model (codegen/c_model.py) computes what the Python module computes: every C
function of the seed, a 100-mass chain, a linear block, the index-3 pendulum (Newton
blocks) and the bouncing ball (events) against the generated Python module of the same
model at several (t, x, p), within 1e-12 relative (the seed also built by zig cc);
located errors for what C cannot compute."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from pendulum_text import PENDULUM
from springc.errors import CodegenError
from springc.pipeline import CLibrary, CompiledModel, c_library, find_compiler
from springc.pipeline.c_build import build_library

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")
EVENTS = str(ROOT / "models" / "EventScenes.mdl")
RTOL = 1e-12

LINEAR = """model Lin "three unknowns in one linear system, its matrix changing in time"
  parameter Real a = 2, b = 3;
  parameter Real c = a + b "bound to a and b";
  Real x(start = 1, fixed = true);
  Real u, w, v;
equation
  der(x) = -u + w + c*v;
  a*u + w + time*v = x;
  u - b*w + v = sin(x);
  u + w - 4*v = 1;
end Lin;
"""


SAMPLER = """model Sampler "sample, a time event, when/elsewhen, edge and terminate"
  parameter Real T = 0.1;
  Real x(start = 1, fixed = true);
  discrete Real y(start = 0);
  Integer n(start = 0);
  Boolean high(start = false);
equation
  der(x) = -x + y + (if time > 0.35 then 1 else 0);
  when sample(0, T) then
    y = pre(y) + 0.5*x;
    n = pre(n) + 1;
  end when;
  when x > 1.2 then
    high = true;
  elsewhen x < 0.8 then
    high = false;
  end when;
  when time > 1.0 then
    terminate("enough");
  end when;
end Sampler;
"""

BUILTINS = """model Builtins "floor, mod, sign, div, abs, max, min, integer, rem, noEvent"
  Real x(start = 0.2, fixed = true);
  Real k;
  Real w(start = 0.3, fixed = true);
equation
  der(x) = 1 + 0.5*floor(x*3) - 0.1*mod(x, 0.7) + sign(x - 1) + div(x, 0.3);
  der(w) = if noEvent(w > 0.5) then -abs(w) else max(w, 0.1) + min(x, 2);
  k = integer(3*time) + rem(x, 0.4);
end Builtins;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def close(c: np.ndarray, py: np.ndarray) -> None:
    """Equal within RTOL relative to each value (exact zeros stay exact)."""
    np.testing.assert_allclose(c, py, rtol=RTOL, atol=1e-300)


def compiled(tmp_path: Path, text: str | None, files: str, model: str,
             **kwargs: object) -> tuple[CompiledModel, CLibrary]:
    if text is not None:
        path = tmp_path / f"{model}.mo"
        path.write_text(text, encoding="utf-8")
        files = str(path)
    m = springc.compile_model([files], model, backend="python", **kwargs)  # type: ignore[arg-type]
    return m, c_library(m)


def points(x0: np.ndarray, count: int = 4) -> list[tuple[float, np.ndarray]]:
    rng = np.random.default_rng(7)
    return [(t, x0 * (1 + 0.1 * rng.standard_normal(x0.shape)) + 0.05 * rng.standard_normal(
        x0.shape)) for t in (0.0, 0.37, 1.5, 2.5)[:count]]


def check_continuous(m: CompiledModel, lib: CLibrary, given: dict[str, float]) -> None:
    """parameters, start, rhs and observed of C and Python agree (z included)."""
    mod = m.module
    index = {name: i for i, name in enumerate(mod.PARAMETERS)}
    p = mod.parameters(given)
    close(lib.parameters({index[n]: v for n, v in given.items()}), p)
    x_c, z_c = lib.start(p)
    close(x_c, mod.start(p))
    close(z_c, mod.guesses(p))
    for t, x in points(mod.start(p)):
        z_py, z_cc = mod.guesses(p), mod.guesses(p)
        code, dx = lib.rhs(t, x, p, z_cc)
        close(dx, mod.rhs(t, x, p, z_py))
        assert code == int(z_py[-1]) == 0
        close(z_cc, z_py)
        code, out = lib.observed(t, x, p, z_cc)
        close(out, mod.observed(t, x, p, z_py))
        close(z_cc, z_py)
        if lib.has_jacobian:
            code, jac = lib.jacobian_dense(t, x, p, z_cc)
            close(jac, mod.jacobian_dense(t, x, p, z_py))


def test_seed_functions_equal_the_python_module(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, None, SEED, "SpringMass")
    assert (lib.n_states, lib.n_params, lib.n_observed, lib.n_z) == (4, 11, 3, 1)
    assert lib.has_jacobian and lib.n_jac == len(m.module.JAC_ROWS) == 6
    check_continuous(m, lib, {})
    check_continuous(m, lib, {"spring.k": 250.0, "mass.m": 0.3})


def test_the_seed_built_by_zig_cc_equals_the_python_module(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # a machine with Python and pip only: the compiler is zig cc of the ziglang package
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "zig-cache"))  # built afresh
    monkeypatch.setenv("CC", shlex.join([sys.executable, "-m", "ziglang", "cc"]))
    assert find_compiler() == [sys.executable, "-m", "ziglang", "cc"]
    m, lib = compiled(tmp_path, None, SEED, "SpringMass")
    assert (m.path.parent / "libcmodel.so").read_bytes()[:4] == b"\x7fELF"
    check_continuous(m, lib, {})
    check_continuous(m, lib, {"spring.k": 250.0, "mass.m": 0.3})


def test_a_hundred_mass_chain_equals_the_python_module(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, None, SCENES, "Scenes.Chain", parameters={"N": 100})
    assert lib.n_states == 200 and lib.has_jacobian
    check_continuous(m, lib, {"k": 37.0})


def test_linear_block_and_bound_parameters(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, LINEAR, "", "Lin")
    assert lib.has_jacobian  # through the linear system's matrix (springc_solve)
    check_continuous(m, lib, {})
    # c = a + b follows a given a, unless c is given too
    index = {name: i for i, name in enumerate(m.module.PARAMETERS)}
    assert lib.parameters({index["a"]: 10.0})[index["c"]] == 13.0
    assert lib.parameters({index["a"]: 10.0, index["c"]: 1.5})[index["c"]] == 1.5
    check_continuous(m, lib, {"a": 0.5, "b": -2.0})


def test_pendulum_newton_blocks_equal_the_python_module(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, PENDULUM, "", "Pendulum")
    assert "springc_solve" in lib.source and "_it < 200" in lib.source
    assert lib.has_jacobian
    check_continuous(m, lib, {"L": 1.3})


def test_pendulum_newton_failure_sets_the_flag_and_returns_its_code(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, PENDULUM, "", "Pendulum")
    mod = m.module
    p = mod.parameters()
    x = mod.start(p) * np.nan  # no Newton iteration converges from NaN
    z_py, z_c = mod.guesses(p), mod.guesses(p)
    mod.rhs(0.0, x, p, z_py)
    code, _ = lib.rhs(0.0, x, p, z_c)
    assert code == z_c[-1] == z_py[-1] and code in mod.NEWTON_SYSTEMS


def test_bouncing_ball_events_equal_the_python_module(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, None, EVENTS, "EventScenes.BouncingBall")
    mod = m.module
    assert lib.hybrid and lib.n_crossings == len(mod.ZERO_CROSSINGS) == 1
    p = mod.parameters({"g": 3.7})
    z_py = mod.guesses(p)
    z_c = z_py.copy()
    # the initial event, then an impact at t = 0.45 with h slightly below the floor
    z_py[mod.Z_INITIAL] = z_c[mod.Z_INITIAL] = 1.0
    x0 = mod.start(p)
    close(lib.event_update(0.0, x0, p, z_c)[1], mod.event_update(0.0, x0, p, z_py))
    close(z_c, z_py)
    x = np.array([-1e-3, -3.0])
    close(lib.zero_crossings(0.45, x, p, z_c)[1], mod.zero_crossings(0.45, x, p, z_py))
    assert lib.next_time_event(0.45, x, p, z_c) == mod.next_time_event(0.45, x, p, z_py)
    code, after = lib.event_update(0.45, x, p, z_c)
    close(after, mod.event_update(0.45, x, p, z_py))
    close(after, np.array([-1e-3, 2.4]))  # reinit(v, -e*pre(v))
    assert code == 0
    close(z_c, z_py)
    assert z_c[mod.Z_DISCRETE[0]] == 1.0  # bounces
    close(lib.observed(0.5, after, p, z_c)[1], mod.observed(0.5, after, p, z_py))
    close(lib.rhs(0.5, after, p, z_c)[1], mod.rhs(0.5, after, p, z_py))


def check_hybrid(m: CompiledModel, lib: CLibrary) -> list[int]:
    """The initial event, then at each point rhs, observed, zero crossings, the next
    time event and an event: C and Python agree (z included); the event codes."""
    mod = m.module
    p = mod.parameters()
    z_py = mod.guesses(p)
    z_c = z_py.copy()
    z_py[mod.Z_INITIAL] = z_c[mod.Z_INITIAL] = 1.0
    x0 = mod.start(p)
    codes = [lib.event_update(0.0, x0, p, z_c)[0]]
    mod.event_update(0.0, x0, p, z_py)
    for t, x in points(x0):
        for function in ("rhs", "observed", "zero_crossings"):
            close(getattr(lib, function)(t, x, p, z_c)[1],
                  getattr(mod, function)(t, x, p, z_py))
        assert lib.next_time_event(t, x, p, z_c) == mod.next_time_event(t, x, p, z_py)
        code, after = lib.event_update(t, x, p, z_c)
        close(after, mod.event_update(t, x, p, z_py))
        close(z_c, z_py)
        codes.append(code)
    return codes


def test_samples_time_events_and_terminate_equal_the_python_module(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, SAMPLER, "", "Sampler")
    codes = check_hybrid(m, lib)
    assert codes == [0, 0, 0, -2, -2]  # terminate() at t = 1.5 and 2.5
    assert "springc_terminate_messages" in lib.source and '"enough"' in lib.source


def test_builtin_functions_equal_the_python_module(tmp_path: Path) -> None:
    m, lib = compiled(tmp_path, BUILTINS, "", "Builtins")
    assert "floor(" in lib.source and "springc_max(" in lib.source
    assert check_hybrid(m, lib) == [0] * 5


def test_delay_is_a_located_error(tmp_path: Path) -> None:
    path = tmp_path / "D.mo"
    path.write_text("model D\n  Real x(start = 1, fixed = true);\nequation\n"
                    "  der(x) = -delay(x, 0.5);\nend D;\n", encoding="utf-8")
    m = springc.compile_model([str(path)], "D", backend="python")
    with pytest.raises(CodegenError) as caught:
        c_library(m)
    error = caught.value
    assert error.message == ("cannot generate C code for delay(...) (not supported in "
                             "the C model): delay(x, 0.5) in the equation of 'der(x)'")
    assert error.span is not None and (error.span.line, error.span.column) == (4, 3)


STRICT = ("-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror", "-Wno-unused-parameter",
          "-Wno-unused-variable", "-Wno-unused-const-variable", "-Wno-unused-function",
          "-Wno-unused-but-set-variable")
FILE_SCOPE = ("#", "/* ", "static const ", "SPRINGC_FN ", "{", "}", "    ")


@pytest.mark.parametrize("text,name", [(PENDULUM, "Pendulum"), (LINEAR, "Lin"),
                                       (SAMPLER, "Sampler")])
def test_the_file_is_strict_c99_with_no_mutable_global(tmp_path: Path, text: str,
                                                         name: str) -> None:
    _, lib = compiled(tmp_path, text, "", name)
    source = lib.source
    # at file scope only directives, comments, constant tables and SPRINGC_FN functions
    assert all(line.startswith(FILE_SCOPE) for line in source.splitlines() if line)
    assert "malloc" not in source and "#include <math.h>" in source
    assert [line for line in source.splitlines() if line.startswith("#include")] == [
        "#include <math.h>"]
    for extra in ((), ("-DSPRINGC_NO_TABLES",)):
        folder = tmp_path / f"strict{len(extra)}"
        folder.mkdir()
        assert build_library(source, folder, (*STRICT, *extra))[:4] == b"\x7fELF"
