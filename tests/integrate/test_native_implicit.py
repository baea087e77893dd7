"""Radau IIA and BDF in the compiled engine's C loop (``radau_steps.c``,
``bdf_steps.c``) against the numba loop on the same generated model: the same steps,
rejections, right-hand-side and Jacobian evaluations, and states within 1e-10
relative (on this machine they are equal: the C hooks do the numba hooks' operations
in the same order, but the C math library may round pow/hypot otherwise than
numba's); against the analytic solution of a linear stiff model, with the analytic
Jacobian and with the forward differences of a C model printed without one; and the
status of a failing Newton iteration."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.codegen import c_model
from springc.integrate import Status, bdf, radau
from springc.pipeline import loop_library
from springc.simulation.native import band_order

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "models" / "Scenes.mdl"
VAN_DER_POL = """
model VanDerPol
  parameter Real mu = 1000;
  Real x(start = 2, fixed = true);
  Real y(start = 0, fixed = true);
equation
  der(x) = y;
  der(y) = mu * (1 - x * x) * y - x;
end VanDerPol;
"""
LINEAR = """
model Linear
  parameter Real k = 10000;
  Real a(start = 1, fixed = true);
  Real b(start = 1, fixed = true);
equation
  der(a) = -k * (a - cos(time));
  der(b) = -b;
end Linear;
"""
ROOT_MODEL = """
model Root
  Real x(start = 1, fixed = true);
equation
  der(x) = -sqrt(x);
end Root;
"""
IMPLICIT = {"radau": radau, "bdf": bdf}


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))


def _model(text: str, tmp_path: Path) -> springc.CompiledModel:
    name = text.split()[1]
    path = tmp_path / f"{name}.mo"
    path.write_text(text, encoding="utf-8")
    return springc.compile_model([path], name, backend="numba")  # type: ignore[arg-type]


def _start(model: springc.CompiledModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    mod = model.module
    p = np.asarray(mod.parameters(), dtype=float)
    return p, np.asarray(mod.start(p), dtype=float), np.asarray(mod.guesses(p), dtype=float)


def _both(model: springc.CompiledModel, method: str, grid: np.ndarray, **options: object
          ) -> tuple[object, object]:
    mod = model.module
    p, x0, z = _start(model)
    numba_run = IMPLICIT[method](mod.rhs, mod.jacobian_values, mod.JAC_INDPTR,
                                 mod.JAC_INDICES, grid, x0, p, z.copy(), **options)
    c_run = loop_library(model).run(method, grid, x0, p, z.copy(), order=band_order(mod),
                                    **options)  # type: ignore[arg-type]
    return numba_run, c_run


def _same_run(numba_run: object, c_run: object) -> None:
    n = numba_run.states.shape[1]  # type: ignore[attr-defined]
    names = ("status", "filled", "accepted_steps", "rejected_steps", "rhs_evaluations",
             "jacobian_evaluations")
    assert [getattr(c_run, k) for k in names] == [getattr(numba_run, k) for k in names]
    filled = c_run.filled  # type: ignore[attr-defined]  (the rows after it: unwritten)
    states = np.frombuffer(c_run.states).reshape(-1, n)[:filled]  # type: ignore[attr-defined]
    expected = numba_run.states[:filled]  # type: ignore[attr-defined]
    scale = max(float(np.abs(expected).max()), 1.0)
    assert float(np.abs(states - expected).max()) <= 1e-10 * scale
    assert np.allclose(c_run.failure_state, numba_run.failure_state,  # type: ignore[attr-defined]
                       rtol=1e-10, atol=1e-10 * scale)
    assert math.isclose(c_run.next_step, numba_run.next_step,  # type: ignore[attr-defined]
                        rel_tol=1e-9)


@pytest.mark.parametrize("method", ["radau", "bdf"])
def test_van_der_pol_takes_the_numba_loops_steps(tmp_path: Path, method: str) -> None:
    model = _model(VAN_DER_POL, tmp_path)
    numba_run, c_run = _both(model, method, np.linspace(0.0, 3000.0, 301), rtol=1e-6,
                             atol=1e-9)
    assert c_run.status == Status.SUCCESS  # type: ignore[attr-defined]
    assert c_run.accepted_steps > 1000  # type: ignore[attr-defined]  (mu = 1000: stiff)
    _same_run(numba_run, c_run)


@pytest.mark.parametrize("method", ["radau", "bdf"])
def test_a_chain_over_64_states_is_banded_in_the_numba_loops_order(method: str) -> None:
    model = springc.compile_model(SCENES, "Scenes.Chain", parameters={"N": 40},
                                  backend="numba")
    assert len(model.states) == 80 and band_order(model.module) is not None
    numba_run, c_run = _both(model, method, np.linspace(0.0, 3.0, 61), rtol=1e-6,
                             atol=1e-9)
    _same_run(numba_run, c_run)


def _linear(t: np.ndarray, k: float = 1e4) -> np.ndarray:
    """The exact solution of LINEAR: a' = -k (a - cos t), a(0) = 1; b' = -b, b(0) = 1."""
    r = k * k + 1
    a = (k * k * np.cos(t) + k * np.sin(t)) / r + np.exp(-k * t) / r
    return np.column_stack((a, np.exp(-t)))


@pytest.mark.parametrize("method", ["radau", "bdf"])
@pytest.mark.parametrize("analytic", [True, False])
def test_a_linear_stiff_model_meets_its_exact_solution(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, method: str, analytic: bool) -> None:
    if not analytic:  # a C model printed without springc_jacobian: forward differences
        monkeypatch.setattr(c_model, "JACOBIAN_LIMIT", 0)
    model = _model(LINEAR, tmp_path)
    grid = np.linspace(0.0, 5.0, 51)
    p, x0, z = _start(model)
    run = loop_library(model).run(method, grid, x0, p, z, rtol=1e-8, atol=1e-10)
    assert (run.status, run.filled) == (Status.SUCCESS, len(grid))
    states = np.frombuffer(run.states).reshape(len(grid), 2)
    assert float(np.abs(states - _linear(grid)).max()) <= 2e-6
    assert run.jacobian_evaluations >= 1
    if analytic:
        numba_run = IMPLICIT[method](
            model.module.rhs, model.module.jacobian_values, model.module.JAC_INDPTR,
            model.module.JAC_INDICES, grid, x0, p, z.copy(), rtol=1e-8, atol=1e-10)
        _same_run(numba_run, run)


@pytest.mark.parametrize("method", ["radau", "bdf"])
def test_a_newton_iteration_that_cannot_converge_stops_as_numbas(tmp_path: Path,
                                                                 method: str) -> None:
    model = _model(ROOT_MODEL, tmp_path)  # x reaches 0 at t = 2: sqrt of a negative x
    numba_run, c_run = _both(model, method, np.linspace(0.0, 3.0, 31), rtol=1e-6,
                             atol=1e-9)
    assert c_run.status == numba_run.status  # type: ignore[attr-defined]
    assert c_run.status in (Status.STEP_TOO_SMALL,  # type: ignore[attr-defined]
                            Status.NON_FINITE_DERIVATIVE)
    assert c_run.failure_time == pytest.approx(  # type: ignore[attr-defined]
        numba_run.failure_time, rel=1e-12)  # type: ignore[attr-defined]
    assert 1.9 < c_run.failure_time < 2.001  # type: ignore[attr-defined]
    _same_run(numba_run, c_run)


def test_a_chain_without_a_c_jacobian_is_differenced_by_groups_of_columns(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # 80 states, no springc_jacobian: the loop differences the module's pattern (158
    # non-zeros) by greedy colouring, 3 groups (each mass's position and velocity rows
    # are shared by at most its neighbours'), 1 + 3 evaluations per Jacobian against
    # 81 for dense differences; radau then takes the analytic run's steps
    monkeypatch.setattr(c_model, "JACOBIAN_LIMIT", 0)
    model = springc.compile_model(SCENES, "Scenes.Chain", parameters={"N": 40},
                                  backend="numba")
    assert len(model.module.JAC_ROWS) == 158
    numba_run, c_run = _both(model, "radau", np.linspace(0.0, 3.0, 61), rtol=1e-6,
                             atol=1e-9)
    names = ("status", "filled", "accepted_steps", "rejected_steps", "jacobian_evaluations")
    assert [getattr(c_run, k) for k in names] == [getattr(numba_run, k) for k in names]
    assert c_run.rhs_evaluations == (  # type: ignore[attr-defined]
        numba_run.rhs_evaluations + 4 * numba_run.jacobian_evaluations)  # type: ignore[attr-defined]
    states = np.frombuffer(c_run.states).reshape(61, 80)  # type: ignore[attr-defined]
    scale = float(np.abs(numba_run.states).max())  # type: ignore[attr-defined]
    assert float(np.abs(states - numba_run.states).max()) <= 1e-8 * scale  # type: ignore[attr-defined]
