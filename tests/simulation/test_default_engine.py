"""The default engine: with neither ``backend`` nor ``engine`` given, springc generates
the numba module and runs the compiled loop; its runs say why in the summary, and its
failures (a solver's, an assertion's, a torn system's Newton, a hybrid model's) read
exactly as on the scipy engine, each checked against a successful shorter run that
shows the default really is compiled."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from float_text import assert_same_text
from same_method import assert_same_method
from springc.cli import main
from springc.errors import SimulationError

pytest.importorskip("numba")  # numba is a base dependency; without it the default is scipy

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")

MODELS = """
model Blowup
  Real x(start = 1, fixed = true);
equation
  der(x) = x * x;
end Blowup;

model TornCircle "w = 1 - x^2 has no real y past x = 1: a torn system's Newton fails"
  Real x(start = 0, fixed = true);
  Real y(start = -1);
  Real w;
  Real v;
equation
  der(x) = 1;
  w = y^2 + 0.1*sin(v);
  v = 0.5*w*y;
  x^2 + w = 1;
end TornCircle;

model Decay
  Real x(start = 1, fixed = true);
equation
  der(x) = -2 * x;
  assert(x > 0.5, "x fell below the bound");
  annotation(experiment(StopTime = 1, Interval = 0.01));
end Decay;

model Ball
  parameter Real bound = 0.5;
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  assert(h > bound, "h fell below the bound");
  when h <= 0 then
    reinit(v, -0.8 * pre(v));
  end when;
end Ball;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def models(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("default_engine") / "models.mo"
    path.write_text(MODELS)
    return str(path)


def test_the_default_is_the_numba_module_on_the_compiled_loop() -> None:
    default = springc.simulate(SEED, error_control="off")  # the run itself: no rerun
    scipy_run = springc.simulate(SEED, engine="scipy", error_control="off")
    assert default.stats.engine == "compiled" and scipy_run.stats.engine == "scipy"
    assert springc.compile_model(SEED).module.BACKEND == "numba"
    # the same 972 dop853 steps (the compiled loop takes scipy's), values within rounding
    assert default.stats.steps == scipy_run.stats.steps == 972
    assert_same_method(default, scipy_run, 1e-6)
    summary = default.stats.summary("SpringMass")
    assert summary.startswith("SpringMass: auto -> dop853 (compiled) (non-stiff: ")
    assert "; dop853 ran in the compiled loop (numba, no Python per step))" in summary


@pytest.mark.parametrize(("keywords", "engine", "why"), [
    ({"solver": "lsoda"}, "scipy", "lsoda ran in scipy's loop: springc has no compiled "
                                   "loop for it"),
    ({"solver": "dop853", "backend": "python"}, "scipy",
     "dop853 ran in scipy's loop: the model was generated for the python backend (asked "
     "for, or springc's choice for code too long for numba to compile quickly)"),
    ({"solver": "dop853", "engine": "scipy"}, "scipy", ""),
    ({"solver": "radau"}, "compiled", ""),
])
def test_runs_off_the_compiled_loop_say_why(keywords: dict[str, str], engine: str,
                                            why: str) -> None:
    result = springc.simulate(SEED, stop=0.5, **keywords)  # type: ignore[arg-type]
    solver = keywords["solver"]
    assert result.stats.engine == engine
    assert result.stats.engine_reason == why
    shown = f"{solver} ({engine}) ({why})," if why else f"{solver} ({engine}),"
    assert result.stats.summary("SpringMass").startswith(f"SpringMass: {shown}")


FAILURES = [
    # (model, keywords, stop of a run that succeeds, the start of the message, help)
    ("Blowup", {"solver": "dop853"}, 0.5, "the step size of dop853 collapsed at time 1",
     "the system looks stiff or unstable: try --solver radau (or bdf)"),
    ("Blowup", {"solver": "radau"}, 0.5, "the step size of radau collapsed at time 1",
     None),
    ("TornCircle", {"solver": "dop853"}, 0.9,
     "the nonlinear system for y did not converge at time 1", "singular configuration"),
    ("TornCircle", {"solver": "radau"}, 0.9,
     "the nonlinear system for y did not converge at time 1", "singular configuration"),
    ("Blowup", {"solver": "rk4", "step": 0.01, "interval": 0.01}, 0.5,
     "der(x) is infinite at time 1.02\n", None),
]


@pytest.mark.parametrize(("name", "keywords", "fine", "message", "remedy"), FAILURES,
                         ids=[f"{m}-{k.get('solver', 'auto')}" for m, k, *_ in FAILURES])
def test_failures_on_the_default_engine_read_as_on_scipy(
        models: str, name: str, keywords: dict[str, object], fine: float, message: str,
        remedy: str | None) -> None:
    shorter = springc.simulate(models, model_name=name, stop=fine, **keywords)  # type: ignore[arg-type]
    assert shorter.stats.engine == "compiled"
    errors = []
    for engine in ("auto", "scipy"):
        with pytest.raises(SimulationError) as info:
            springc.simulate(models, model_name=name, stop=2.0, engine=engine,
                             **keywords)  # type: ignore[arg-type]
        errors.append(info.value)
    # the same message, remedy and quantities (radau's last state differs in rounding
    # near the singularity: the compiled Radau is scipy's method, not its code)
    compiled, scipy_error = errors
    assert (compiled.message, compiled.hint) == (scipy_error.message, scipy_error.hint)
    assert [n.message.split(" = ")[0] for n in compiled.notes] == \
        [n.message.split(" = ")[0] for n in scipy_error.notes]
    assert str(compiled).startswith(f"error: {message}")
    assert any(note.message.startswith("x = ") for note in errors[0].notes)  # the quantity
    if remedy is not None:
        assert remedy in (errors[0].hint or "")


@pytest.mark.parametrize(("solver", "step", "when"), [
    ("dop853", None, "0.346573591"), ("radau", None, "0.34657359"),
    ("rk4", 0.001, "0.347"), ("verlet", 0.001, "0.347")])
def test_assertion_failures_are_located_as_on_scipy(models: str, solver: str,
                                                    step: float | None, when: str) -> None:
    """exp(-2 t) = 0.5 at t = ln(2)/2 = 0.34657359: the adaptive solvers locate it
    inside the step (rtol 1e-8), the fixed-step ones report the first step past it,
    0.347; the compiled run finds the output interval (0.34, 0.35], and scipy's loop
    run over it again locates the time as the scipy engine does."""
    shorter = springc.simulate(models, model_name="Decay", solver=solver, step=step,
                               rtol=1e-8, stop=0.3)
    assert shorter.stats.engine == "compiled"
    errors = []
    for engine in ("auto", "scipy"):
        with pytest.raises(SimulationError) as info:
            springc.simulate(models, model_name="Decay", solver=solver, step=step,
                             rtol=1e-8, engine=engine)
        errors.append(info.value)
    assert_same_text(str(errors[0]), str(errors[1]), 1e-8)  # (two compiled paths)
    assert errors[0].message == f"assertion failed at t = {when}: x fell below the bound"
    assert abs(float(when) - math.log(2) / 2) < (1e-3 if step else 1e-8)
    line = MODELS.splitlines().index('  assert(x > 0.5, "x fell below the bound");') + 1
    assert errors[0].span is not None and (errors[0].span.line, errors[0].span.column) \
        == (line, 3)


def test_hybrid_model_on_the_default_engine(models: str) -> None:
    """The ball dropped from 1 m bounces at sqrt(2/g); with a bound it never crosses it
    runs compiled through both crossings of h <= 0 to h(1) of the closed form; with the
    bound 0.5 it stops at the first output time past h = 0.5 (t = 0.3193: 0.32), as on
    scipy."""
    result = springc.simulate(models, model_name="Ball", stop=1, interval=0.002,
                              rtol=1e-8, parameters={"bound": -0.01})
    assert result.stats.engine == "compiled"
    assert result.stats.state_events == 2
    impact = math.sqrt(2 / 9.81)
    up, after = 0.8 * 9.81 * impact, 1 - impact
    assert abs(result["h"][-1] - (up * after - 9.81 / 2 * after**2)) < 1e-6
    errors = []
    for engine in ("auto", "scipy"):
        with pytest.raises(SimulationError) as info:
            springc.simulate(models, model_name="Ball", stop=1, interval=0.002, rtol=1e-8,
                             engine=engine)
        errors.append(info.value)
    assert_same_text(str(errors[0]), str(errors[1]), 1e-8)  # (two compiled paths)
    assert errors[0].message == "assertion failed at t = 0.32: h fell below the bound"


def test_cli_defaults_to_the_compiled_engine(tmp_path: Path) -> None:
    out = tmp_path / "seed.csv"
    result = CliRunner().invoke(main, ["simulate", SEED, "--stop", "0.5", "-o", str(out),
                                       "-v"])
    assert result.exit_code == 0, result.output
    assert "SpringMass: auto -> dop853 (compiled) (" in result.output
    scipy_run = CliRunner().invoke(main, ["simulate", SEED, "--stop", "0.5", "--engine",
                                          "scipy", "-o", str(tmp_path / "scipy.csv"), "-v"])
    assert scipy_run.exit_code == 0, scipy_run.output
    assert "auto -> dop853 (scipy) (" in scipy_run.output
    assert "dop853 ran in scipy's loop, as --engine scipy asks" in scipy_run.output
    generated = CliRunner().invoke(main, ["compile", SEED])
    assert generated.exit_code == 0 and "\nfrom numba import njit\n" in generated.output


def test_without_numba_the_default_is_scipy_and_says_so(monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    from springc.simulation import compiled

    monkeypatch.setattr(compiled, "numba_available", lambda: False)
    result = springc.simulate(SEED, solver="dop853", stop=0.5)
    assert result.stats.engine == "scipy"
    assert result.stats.engine_reason == ("dop853 ran in scipy's loop: numba is not "
                                          "installed (pip install numba: the compiled "
                                          "loop runs it)")
    assert springc.compile_model(SEED).module.BACKEND == "python"


def test_a_short_auto_run_is_dop853_compiled_from_the_start() -> None:
    """auto on the compiled engine: 10 compiled dop853 steps; where they leave at most
    500 to go (the seed over 2 s), dop853 goes on with no estimate, else (10 s) after a
    non-stiff estimate: either way the same run as dop853's (the same steps, in two
    calls of the compiled loop)."""
    for stop, reason in ((2.0, "non-stiff: dop853 needs ~"),
                         (10.0, "non-stiff: spectral radius 100 1/s over 10 s")):
        auto = springc.simulate(SEED, stop=stop)
        direct = springc.simulate(SEED, stop=stop, solver="dop853")
        assert auto.stats.reason.startswith(reason)
        assert auto.stats.steps == direct.stats.steps
        np.testing.assert_array_equal(auto.values, direct.values)


def test_code_too_long_for_numba_is_generated_for_python(monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    """springc's choice of numba yields to python for a module over NUMBA_LINES lines
    (the seed has 256: a limit of 100 makes it too long); a backend asked for stays."""
    import springc.api

    assert springc.compile_model(SEED).module.BACKEND == "numba"
    monkeypatch.setattr(springc.api, "NUMBA_LINES", 100)
    assert springc.compile_model(SEED).module.BACKEND == "python"
    assert springc.compile_model(SEED, backend="numba").module.BACKEND == "numba"
    result = springc.simulate(SEED, solver="dop853", stop=0.5)
    assert result.stats.engine == "scipy"
    assert "generated for the python backend (asked for, or springc's choice" in \
        result.stats.summary("SpringMass")
