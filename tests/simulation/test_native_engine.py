"""The compiled engine on the C loop (a C compiler found, or ``SPRINGC_LOOP=c``) against
the numba loop (``SPRINGC_LOOP=numba``): the same runs, the same errors, no numba
imported; without a compiler the engine is numba's as before."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError, UsageError
from springc.simulation import c_loop_available, compiled, default_backend

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")
ROOT_MODEL = """model Root
  Real x(start = 1, fixed = true);
equation
  der(x) = -sqrt(x);
end Root;
"""
BALL = """model Ball
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  when h < 0 then
    reinit(v, -0.8 * pre(v));
  end when;
end Ball;
"""
C_REASON = ("dop853 ran in the compiled loop (C, no Python per step: a C compiler was "
            "found; SPRINGC_LOOP=numba runs numba's)")


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))


def _run(monkeypatch: pytest.MonkeyPatch, loop: str, model: str, **options: object
         ) -> springc.SimulationResult:  # type: ignore[name-defined]
    monkeypatch.setenv("SPRINGC_LOOP", loop)
    return springc.simulate(model, **options)  # type: ignore[arg-type]


@pytest.mark.parametrize("solver", ["auto", "dop853", "rk45"])
def test_the_seed_on_the_c_loop_equals_the_numba_loops_run(
        monkeypatch: pytest.MonkeyPatch, solver: str) -> None:
    c_run = _run(monkeypatch, "c", SEED, solver=solver, stop=5.0)
    numba_run = _run(monkeypatch, "numba", SEED, solver=solver, stop=5.0)
    assert c_run.stats.engine == numba_run.stats.engine == "compiled"
    assert c_run.stats.steps == numba_run.stats.steps
    assert c_run.stats.solver == numba_run.stats.solver
    assert c_run.names == numba_run.names
    scale = np.maximum(np.abs(numba_run.values).max(axis=0), 1.0)
    assert (np.abs(c_run.values - numba_run.values) <= 1e-12 * scale).all()
    if solver == "dop853":
        assert c_run.stats.engine_reason == C_REASON


def test_the_default_run_takes_the_c_loop_and_imports_no_numba(tmp_path: Path) -> None:
    code = ("import sys, springc\n"
            f"r = springc.simulate({SEED!r}, stop=1.0)\n"
            "print(r.stats.engine, 'numba' in sys.modules)\n")
    # the default (no SPRINGC_LOOP) where a compiler is found: the venv's ziglang at least
    env = {"SPRINGC_CACHE_DIR": str(tmp_path / "fresh"), "PYTHONPATH": str(ROOT / "src"),
           "PATH": "/usr/bin:/bin", "SPRINGC_QUIET": "1"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["compiled", "False"]


def test_a_large_chain_runs_on_the_c_loop_as_on_numbas(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """600 states (over the old 256-state cap): the C model's loops over index tables
    run on the C loop, states within 1e-12 of numba's loop, the same steps."""
    scenes = str(ROOT / "models" / "Scenes.mdl")
    runs = {}
    for loop in ("c", "numba"):
        monkeypatch.setenv("SPRINGC_LOOP", loop)
        model = springc.compile_model(scenes, "Scenes.Chain", parameters={"N": 300})
        runs[loop] = springc.simulate(model, solver="dop853", stop=2.0, error_control="off")
        backend = model.module.BACKEND
        assert backend == ("python" if loop == "c" else "numba")
    c_run, numba_run = runs["c"], runs["numba"]
    assert c_run.stats.engine_reason == C_REASON
    assert c_run.stats.steps == numba_run.stats.steps
    scale = np.maximum(np.abs(numba_run.values).max(axis=0), 1.0)
    assert (np.abs(c_run.values - numba_run.values) <= 1e-12 * scale).all()


def test_a_model_beyond_the_loops_size_rule_is_generated_for_numba(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from springc.pipeline import c_kernels

    monkeypatch.setenv("SPRINGC_LOOP", "c")
    monkeypatch.setattr(c_kernels, "C_LOOP_CODE_CHARS", 1000)
    before = {name for name in sys.modules if name.startswith("springc_model_")}
    model = springc.compile_model(SEED)
    assert model.module.BACKEND == "numba"
    # the python module it was generated from first is not kept (sys.modules let go);
    # modules earlier tests of this process loaded are not this compile's
    added = [m for name, m in sys.modules.items() if name.startswith("springc_model_")
             and name not in before and getattr(m, "MODEL", "") == "SpringMass"]
    assert "python" not in [getattr(m, "BACKEND", "") for m in added]
    code = int(c_kernels.c_source(model).split("#define SPRINGC_CODE_CHARS ")[1].split()[0])
    assert c_kernels.loop_refusal(c_kernels.c_source(model)) == (
        f"its C functions take {code:,} characters (the C loop takes at most 1,000)")
    monkeypatch.setattr(c_kernels, "C_LOOP_CODE_CHARS", 10**9)
    monkeypatch.setattr(c_kernels, "C_LOOP_STACK_BYTES", 16)
    assert c_kernels.loop_refusal(c_kernels.c_source(model)) == (
        "its C functions need 24 bytes of stack (the C loop takes at most 16)")  # 3 outputs
    monkeypatch.setattr(c_kernels, "C_LOOP_STACK_BYTES", 10**9)
    without = c_kernels.c_source(model).replace("#define SPRINGC_HAS_JACOBIAN 1\n",
                                                "#define SPRINGC_HAS_JACOBIAN 0\n")
    assert c_kernels.loop_refusal(without) is None  # 4 states: differenced in C
    monkeypatch.setattr(c_kernels, "C_LOOP_DIFFERENCED_STATES", 3)
    assert c_kernels.loop_refusal(without) == (
        "it has 4 states and no Jacobian in C (the C loop takes at most 3 states "
        "without one)")


@pytest.mark.parametrize(("masses", "grouped"), [(20, False), (200, True)])
def test_a_refusal_the_module_tells_prints_no_c_and_agrees_with_the_c_file(
        masses: int, grouped: bool, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    # the 10,000-mass chain's case (20,000 states, Jacobian non-zeros in 20,000 rows),
    # scaled down: 2 * masses states, a limit of 10 non-zeros
    from springc.codegen import c_model
    from springc.pipeline import CLoopRefused, c_kernels

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(c_kernels, "C_LOOP_DIFFERENCED_STATES", 8)
    model = springc.compile_model(SCENES, "Scenes.Chain", backend="python",
                                  parameters={"N": masses})
    assert hasattr(model.module, "_I") == grouped  # the vector layout's index table
    assert c_kernels.known_refusal(model) is None  # 2,000 non-zeros: a Jacobian in C
    monkeypatch.setattr(c_kernels, "JACOBIAN_LIMIT", 10)
    monkeypatch.setattr(c_model, "JACOBIAN_LIMIT", 10)
    reason = (f"it has {2 * masses:,} states and no Jacobian in C (the C loop takes at "
              "most 8 states without one)")
    assert c_kernels.known_refusal(model) == reason
    with pytest.raises(CLoopRefused, match="no Jacobian in C"):
        c_kernels.loop_library(model)
    assert not (model.path.parent / "cmodel.c").exists()  # refused without printing C
    text = c_kernels.c_source(model)  # the C file the loop used to print and refuse
    assert "#define SPRINGC_HAS_JACOBIAN 0\n" in text
    assert c_kernels.loop_refusal(text) == reason


def test_a_c_build_the_compiler_refuses_falls_back_to_numba_with_a_note(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    compiler = tmp_path / "brokencc"
    compiler.write_text("#!/bin/sh\necho 'build.c:1:1: warning: odd' >&2\n"
                        "echo 'build.c:9:5: error: broken compiler' >&2\nexit 1\n")
    compiler.chmod(0o755)
    monkeypatch.setenv("CC", str(compiler))
    monkeypatch.delenv("SPRINGC_LOOP", raising=False)
    model = springc.compile_model(SEED)
    assert model.module.BACKEND == "numba"
    assert capsys.readouterr().err.splitlines()[-1] == (
        "note: the C compiler refused the C loop of SpringMass (build.c:9:5: error: "
        "broken compiler); running on numba's loop")
    result = springc.simulate(model, solver="dop853", stop=1.0)
    assert result.stats.engine == "compiled" and result.stats.engine_reason == ""


def test_a_domain_error_is_located_as_on_the_numba_loop(
        monkeypatch: pytest.MonkeyPatch) -> None:
    messages = []
    for loop in ("c", "numba"):
        monkeypatch.setenv("SPRINGC_LOOP", loop)  # (the backend follows it)
        model = springc.load_model_from_string(ROOT_MODEL)
        with pytest.raises(SimulationError) as caught:
            springc.simulate(model, stop=3.0)
        assert ("python" if loop == "c" else "numba") == model.module.BACKEND
        messages.append(caught.value.message)
    prefix = "math domain error while computing der(x) (<string>:4) at time "
    assert all(m.startswith(prefix) for m in messages)
    times = [float(m[len(prefix):]) for m in messages]
    assert abs(times[0] - times[1]) <= 1e-12 * times[1]
    assert 1.99 < times[0] < 2.01  # the root of (1 - t/2)^2


def test_the_step_limit_stops_the_c_loop_where_it_stops_numbas(
        monkeypatch: pytest.MonkeyPatch) -> None:
    messages = []
    for loop in ("c", "numba"):
        with pytest.raises(SimulationError) as caught:
            _run(monkeypatch, loop, SEED, solver="rk45", max_steps=30)
        messages.append(caught.value.message)
    head, tail = "the simulation stopped at time ", " far over the step limit (--max-steps 30)"
    assert all(m.startswith(head) and m.endswith(tail) and " rk45 needs ~" in m
               for m in messages)
    times = [float(m[len(head):].split(":")[0]) for m in messages]
    assert abs(times[0] - times[1]) <= 1e-8 * times[1]  # (printed to 9 digits)
    assert 0.01 < times[0] < 0.2  # 30 steps of about 2 ms (the spring's period: 63 ms)


def test_a_run_in_stretches_fills_every_row_as_one_stretch_does(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # the C loop writes each stretch's rows into the run's own (row 0, the stretch's
    # start, put back): DOP853 resumed takes the steps of one uninterrupted run
    model = springc.compile_model(SEED, backend="python")
    monkeypatch.setenv("SPRINGC_LOOP", "c")
    whole = springc.simulate(model, solver="dop853", stop=2.0, error_control="off")
    monkeypatch.setattr(compiled, "FIRST_CHUNK", 7)  # 7, 70, 700... steps
    stretched = springc.simulate(model, solver="dop853", stop=2.0, error_control="off")
    assert stretched.stats.engine_reason == whole.stats.engine_reason == C_REASON
    assert stretched.stats.steps == whole.stats.steps > 77  # three stretches at least
    assert np.array_equal(stretched.values, whole.values)


def test_a_model_with_events_stays_on_python_for_the_c_loop(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """springc's default backend for a hybrid model is python where the C loop runs
    (its runs between events in C), not numba's (whose compile of the model's functions
    and hybrid kernels took minutes on a loaded machine: SimpleTriacCircuit)."""
    monkeypatch.setenv("SPRINGC_LOOP", "c")
    model = springc.load_model_from_string(BALL)
    assert (model.kind, model.module.BACKEND) == ("hybrid", "python")
    result = springc.simulate(model, stop=1.0, rtol=1e-10, error_control="off")
    assert result.stats.engine == "compiled"
    assert result.stats.engine_reason == C_REASON.replace("dop853", result.stats.solver)
    # the first impact at sqrt(2 / g), the second 2 * 0.8 * sqrt(2 g) / g later (> 1 s)
    impacts = [e.time for e in result.events if e.kind == "state" and e.x_left[1] < 0]
    assert len(impacts) == 1 and abs(impacts[0] - (2 / 9.81) ** 0.5) <= 1e-8


def test_without_a_compiler_the_engine_is_numbas(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_LOOP", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setitem(sys.modules, "ziglang", None)  # find_spec: not installed
    assert not c_loop_available()
    assert default_backend() == "numba"
    result = springc.simulate(SEED, solver="dop853", stop=1.0)
    assert result.stats.engine == "compiled" and result.stats.engine_reason == ""


def test_a_bad_loop_choice_names_the_variable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_LOOP", "fortran")
    with pytest.raises(UsageError) as caught:
        c_loop_available()
    assert caught.value.message == "SPRINGC_LOOP must be c or numba (or unset), not 'fortran'"


def test_a_model_the_c_printer_cannot_print_is_compiled_for_numba(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Where the C model cannot be printed (a CodegenError from the C printer), springc's
    own backend choice regenerates the model for numba, whose compiled loop runs it: the
    run neither fails nor falls to scipy's loop."""
    import springc.pipeline.c_kernels
    from springc.errors import CodegenError

    def refuse(model: object) -> str:
        raise CodegenError("cannot generate C code for the function 'f'")

    monkeypatch.setattr(springc.pipeline.c_kernels, "c_source", refuse)
    monkeypatch.setenv("SPRINGC_LOOP", "c")
    path = tmp_path / "Root.mo"
    path.write_text(ROOT_MODEL, encoding="utf-8")
    model = springc.compile_model(str(path))
    assert model.module.BACKEND == "numba"
    result = springc.simulate(model, solver="dop853", stop=1.0, rtol=1e-10, atol=1e-12)
    assert result.stats.engine == "compiled"
    x = result.values[-1, list(result.names).index("x")]
    assert x == pytest.approx((1.0 - 0.5) ** 2, rel=1e-8)  # x = (1 - t/2)^2


STIFF = """model Stiff
  parameter Real k = 10000;
  Real a(start = 1, fixed = true);
  Real b(start = 0, fixed = true);
equation
  der(a) = -k * (a - cos(time));
  der(b) = a - b;
end Stiff;
"""


@pytest.mark.parametrize("solver", ["auto", "radau", "bdf"])
def test_a_stiff_model_runs_its_implicit_method_in_the_c_loop(
        monkeypatch: pytest.MonkeyPatch, solver: str) -> None:
    runs = []
    for loop in ("c", "numba"):
        monkeypatch.setenv("SPRINGC_LOOP", loop)
        model = springc.load_model_from_string(STIFF)
        assert ("python" if loop == "c" else "numba") == model.module.BACKEND
        runs.append(springc.simulate(model, solver=solver, stop=20.0))
    c_run, numba_run = runs
    method = "radau" if solver == "auto" else solver
    assert c_run.stats.solver == numba_run.stats.solver == method  # auto: stiff -> radau
    assert c_run.stats.engine == numba_run.stats.engine == "compiled"
    assert f"{method} ran in the compiled loop (C, no Python per step" in \
        c_run.stats.engine_reason
    assert (c_run.stats.steps, c_run.stats.rhs_evaluations,
            c_run.stats.jacobian_evaluations) == (
        numba_run.stats.steps, numba_run.stats.rhs_evaluations,
        numba_run.stats.jacobian_evaluations)
    scale = np.maximum(np.abs(numba_run.values).max(axis=0), 1.0)
    assert (np.abs(c_run.values - numba_run.values) <= 1e-10 * scale).all()


@pytest.mark.parametrize("solver", ["radau", "bdf"])
def test_an_implicit_run_fails_on_the_c_loop_as_on_numbas(
        monkeypatch: pytest.MonkeyPatch, solver: str) -> None:
    messages = []
    for loop in ("c", "numba"):
        monkeypatch.setenv("SPRINGC_LOOP", loop)
        model = springc.load_model_from_string(ROOT_MODEL)
        with pytest.raises(SimulationError) as caught:
            springc.simulate(model, solver=solver, stop=3.0)
        messages.append(caught.value.message)
    assert messages[0] == messages[1]
    assert messages[0].startswith("math domain error while computing der(x) (<string>:4) "
                                  "at time 2")
