"""Hybrid models in the C ensemble engine: each run with its own events, located in the
kernel on the dense output and updated by the C model's event functions. A bouncing
ball over a range of restitution coefficients against its closed form (the height and
velocity at the stop time, the bounces and the time of the last one) and against
``springc.simulate`` run by run; a sampled controller (``when sample``) against its
closed form, with the time event at the stop time; chattering recorded per run with the
single run's message; the kernel's CUDA text (compiled as C++ on the CPU) giving the C
kernel's results; delays, switching states and the numba engine refused by name."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import springc
from springc.errors import SimulationError
from springc.integrate.native_ensemble import OPENMP, NativeEnsemble, Runs, kernel_text
from springc.pipeline import CompiledModel, c_source, openmp_flags
from springc.pipeline.c_build import build_library
from springc.studies import EnsembleOptions, parse_parameter, run_ensemble
from springc.studies.ensemble_engines import relation_signs

HERE = Path(__file__).resolve().parents[1] / "integrate"
G = 9.81
BALL = """model Ball
  parameter Real e = 0.8 "restitution";
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
  Integer bounces(start = 0);
  discrete Real tLast(start = 0) "the time of the last bounce";
  Real restitution = e "e read by an equation as well (see the notes: else structural)";
equation
  der(h) = v;
  der(v) = -9.81;
  when h <= 0 then
    reinit(v, -e * pre(v));
    bounces = pre(bounces) + 1;
    tLast = time;
  end when;
end Ball;
"""
SAMPLED = """model Sampled
  parameter Real k = 2 "gain";
  Real x(start = 1, fixed = true);
  discrete Real u(start = 0) "the control, held between samples";
  Real gain = k;
equation
  der(x) = u;
  when sample(0, 0.1) then
    u = -k * x;
  end when;
end Sampled;
"""
STOP, RTOL, ATOL = 1.7, 1e-10, 1e-12


def bounce(e: float, stop: float, h0: float = 1.0) -> tuple[float, float, int, float]:
    """The ball's height and velocity at ``stop``, its bounces and the last one's time."""
    times, up = [math.sqrt(2 * h0 / G)], e * math.sqrt(2 * G * h0)
    while times[-1] + 2 * up / G <= stop:
        times.append(times[-1] + 2 * up / G)
        up *= e
    tau = stop - times[-1]
    return up * tau - G * tau * tau / 2, up - G * tau, len(times), times[-1]


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="module")
def ball(cache: None) -> CompiledModel:
    return springc.load_model_from_string(BALL)


def _table(model: CompiledModel, path: Path, spec: str, **options: object) -> dict[str, list]:
    run_ensemble(model, EnsembleOptions((parse_parameter(spec),), rtol=RTOL, atol=ATOL,
                                        **options), str(path))  # type: ignore[arg-type]
    return pq.read_table(path).to_pydict()


def test_bounce_times_and_final_states_equal_the_closed_form(ball: CompiledModel,
                                                             tmp_path: Path) -> None:
    # e from 0.6 (the bounces accumulate at 1.81 s) to 0.95, 1 to 9 bounces by 1.7 s
    table = _table(ball, tmp_path / "e.parquet", "e=0.6:0.95:36", stop=STOP,
                   interval=0.01, chunk=7)
    assert table["status"] == ["ok"] * 36
    for run, e in enumerate(np.linspace(0.6, 0.95, 36)):
        h, v, count, last = bounce(float(e), STOP)
        assert table["bounces.final"][run] == count
        assert table["bounces.max"][run] == count and table["bounces.min"][run] == 0
        assert abs(table["tLast.final"][run] - last) <= 1e-9
        assert abs(table["h.final"][run] - h) <= 1e-8
        assert abs(table["v.final"][run] - v) <= 1e-8


def test_each_run_equals_a_single_simulate_run(ball: CompiledModel, tmp_path: Path) -> None:
    table = _table(ball, tmp_path / "e.parquet", "e=0.62:0.92:7", stop=STOP,
                   interval=0.01)
    for run, e in enumerate(np.linspace(0.62, 0.92, 7)):
        single = springc.simulate(ball, stop=STOP, interval=0.01, solver="dop853",
                                  rtol=RTOL, atol=ATOL, error_control="off",
                                  parameters={"e": float(e)})
        assert table["steps"][run] >= single.stats.steps  # accepted and rejected
        for j, name in enumerate(single.names):
            values, t = single.values[:, j], single.time
            got = [table[f"{name}.{s}"][run] for s in ("final", "min", "max", "mean")]
            expected = [values[-1], values.min(), values.max(),
                        np.trapezoid(values, t) / (t[-1] - t[0])]
            np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-11, err_msg=name)
            assert table[f"{name}.time_of_max"][run] == t[values.argmax()], name


def test_a_sampled_controller_equals_its_closed_form(cache: None, tmp_path: Path) -> None:
    sampled = springc.load_model_from_string(SAMPLED)
    table = _table(sampled, tmp_path / "s.parquet", "k=1:5:9", stop=1.0, interval=0.05)
    assert table["status"] == ["ok"] * 9
    for run, k in enumerate(np.linspace(1.0, 5.0, 9)):
        # u = -k x at t = 0, 0.1, ..., 1.0 (the sample at t = 0 fires at the event after
        # the initialization, 3.7.5; the last is the time event at the stop time):
        # x(n T) = (1 - k T)^n, and u rises from -k to -k x(1)
        x = (1 - 0.1 * k) ** 10
        assert abs(table["x.final"][run] - x) <= 1e-12
        assert abs(table["u.final"][run] + k * x) <= 1e-12
        assert abs(table["u.min"][run] + k) <= 1e-12
        assert abs(table["u.max"][run] + k * x) <= 1e-12
        single = springc.simulate(sampled, stop=1.0, interval=0.05, solver="dop853",
                                  rtol=RTOL, atol=ATOL, error_control="off",
                                  parameters={"k": float(k)})
        values = single.values[:, single.names.index("x")]
        np.testing.assert_allclose(table["x.mean"][run],
                                   np.trapezoid(values, single.time), rtol=1e-12)


SLIDE = """model Slide
  parameter Real c = 1 "the rate below 0: > 0 pushes back (a sliding mode: chattering)";
  Real x(start = 1, fixed = true);
equation
  der(x) = if x > 0 then -1 else c;
end Slide;
"""


def test_chattering_fails_its_run_with_the_single_runs_message(cache: None,
                                                               tmp_path: Path) -> None:
    slide = springc.load_model_from_string(SLIDE)
    table = _table(slide, tmp_path / "z.parquet", "c=-0.5,0.5,0.5", stop=2.0, explain=1)
    assert table["status"] == ["ok", "failed", "failed"]
    # c = -0.5: x = 1 - t up to t = 1, then -(t - 1) / 2; its mean over [0, 2] is 1/8
    assert abs(table["x.final"][0] + 0.5) <= 1e-9 and abs(table["x.mean"][0] - 0.125) <= 1e-9
    with pytest.raises(SimulationError) as single:
        springc.simulate(slide, stop=2.0, solver="dop853", rtol=RTOL, atol=ATOL,
                         error_control="off", parameters={"c": 0.5})
    assert table["error"][1] == str(single.value)
    assert str(single.value).startswith("error: chattering: 100 events in ")
    assert table["error"][2] == ("dop853 failed at time 1: chattering (more than 100 "
                                 "events within 1e-6 of the simulated span)")
    assert table["x.final"][1:] == [None, None]


CUDA_STAND_IN = """#include <math.h>
#define __global__
#define __device__
#define __forceinline__ inline
struct sc_dim3 { unsigned x; };
static sc_dim3 threadIdx, blockIdx, blockDim, gridDim;
#define SC_EMULATE_CUDA "cuda_emulation.h"
"""
"""As in tests/integrate/test_native_ensemble.py: the launch run on the CPU."""


def test_the_cuda_text_runs_the_events_as_the_c_kernel(ball: CompiledModel,
                                                       tmp_path: Path) -> None:
    signs, text = relation_signs(ball), c_source(ball)
    assert signs == (False,)  # h <= 0
    folder = tmp_path / "c"
    folder.mkdir()
    cpu = NativeEnsemble(build_library(kernel_text(text, positive=signs), folder,
                                       openmp_flags(OPENMP)), 2)
    system = shutil.which("c++") or shutil.which("g++")  # the CUDA text is C++
    cxx = [system] if system else [sys.executable, "-m", "ziglang", "c++"]
    source, library = tmp_path / "cuda.cpp", tmp_path / "cuda.so"
    source.write_text(CUDA_STAND_IN + kernel_text(text, cuda=True, positive=signs),
                      encoding="utf-8")
    subprocess.run([*cxx, "-O1", "-ffp-contract=off", "-fPIC", "-shared", f"-I{HERE}",
                    str(source), "-o", str(library)], check=True)
    gpu = NativeEnsemble(library.read_bytes(), 2, entry="sc_emulated_launch")
    index = ball.parameter_names.index("e")
    given = np.zeros(len(ball.parameter_names), dtype=np.int32)
    given[index] = 1
    runs = Runs(np.linspace(0.6, 0.95, 200).reshape(-1, 1), np.array([index]),
                np.asarray(ball.module.parameters({}), dtype=float), given)
    grid = np.linspace(0.0, STOP, 171)
    settings = {"rtol": RTOL, "atol": np.full(2, ATOL), "max_step": np.inf,
                "max_steps": 0, "columns": [0, 1, 3, 4], "traj_columns": [0], "every": 5}
    on_gpu = gpu.run(runs, grid, threads=128, **settings)  # type: ignore[arg-type]
    on_cpu = cpu.run(runs, grid, **settings)  # type: ignore[arg-type]
    assert on_cpu.status.tolist() == [0] * 200
    assert on_gpu.counts.tolist() == on_cpu.counts.tolist()
    np.testing.assert_allclose(on_gpu.finals, on_cpu.finals, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(on_gpu.summary, on_cpu.summary, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(on_gpu.trajectories, on_cpu.trajectories, rtol=1e-12,
                               atol=1e-15)
    h, v, count, _ = bounce(0.6, STOP)
    assert ball.observed.index("bounces") == 1  # column 3 of [states | observed]
    assert on_cpu.summary[0, 2, 0] == count  # bounces.final of e = 0.6
    np.testing.assert_allclose(on_cpu.finals[0], [h, v], rtol=0, atol=1e-8)


DELAYED = """model Feedback
  parameter Real tau = 1;
  Real x(start = 1, fixed = true);
equation
  der(x) = -delay(x, tau);
end Feedback;
"""


def test_delays_switching_states_and_the_numba_engine_are_refused_by_name(
        ball: CompiledModel, tmp_path: Path) -> None:
    from pendulum_text import PENDULUM

    path = tmp_path / "e.parquet"
    delayed = springc.load_model_from_string(DELAYED)
    with pytest.raises(SimulationError) as refused:
        run_ensemble(delayed, EnsembleOptions((parse_parameter("tau=1,2"),)), str(path))
    assert refused.value.message == ("Feedback has delay(...), which the ensemble engine "
                                     "does not run yet")
    assert refused.value.hint == "use springc sweep (one run at a time)"
    pendulum = springc.load_model_from_string(PENDULUM, backend="python")
    assert pendulum.module.SWITCHABLE
    with pytest.raises(SimulationError) as refused:
        run_ensemble(pendulum, EnsembleOptions((parse_parameter("L=1,2"),)), str(path))
    assert refused.value.message == ("Pendulum has states that switch (dynamic state "
                                     "selection), which the ensemble engine does not "
                                     "run yet")
    with pytest.raises(SimulationError) as refused:
        run_ensemble(ball, EnsembleOptions((parse_parameter("e=0.5,0.6"),), engine="numba"),
                     str(path))
    assert refused.value.message == ("Ball has events (the relation h <= 0), which the "
                                     "numba ensemble engine does not run")
    assert not path.exists()


DRAIN = """model Drain
  parameter Real k = 1;
  Real x(start = 1, fixed = true);
equation
  der(x) = -k * x;
  when x < 0.5 then
    terminate("half drained");
  end when;
end Drain;
"""
LAST = """model Last
  parameter Real k = 1;
  Real x(start = 1, fixed = true);
  discrete Real atEnd(start = 0) "x at the terminal event";
equation
  der(x) = -k * x;
  when time >= 0.35 then
    reinit(x, 2 * pre(x));
  end when;
  when terminal() then
    atEnd = x;
  end when;
end Last;
"""


def _against_simulate(model: CompiledModel, table: dict[str, list], spec: str,
                      values: np.ndarray, **settings: float) -> None:
    name = spec.split("=")[0]
    for run, value in enumerate(values):
        single = springc.simulate(model, solver="dop853", rtol=RTOL, atol=ATOL,
                                  error_control="off", parameters={name: float(value)},
                                  **settings)
        t = single.time
        for j, variable in enumerate(single.names):
            series = single.values[:, j]
            got = [table[f"{variable}.{s}"][run] for s in ("final", "min", "max", "mean")]
            expected = [series[-1], series.min(), series.max(),
                        np.trapezoid(series, t) / (t[-1] - t[0])]
            np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12,
                                       err_msg=variable)


def test_terminate_ends_each_run_at_its_own_time(cache: None, tmp_path: Path) -> None:
    drain = springc.load_model_from_string(DRAIN)
    table = _table(drain, tmp_path / "d.parquet", "k=0.5:3:6", stop=2.0, interval=0.1)
    # ok: terminate() is the model's own end (x = 0.5 at t = ln 2 / k, before 2 s for
    # k > 0.35); the statistics run to that time, as the single run's result does
    assert table["status"] == ["ok"] * 6
    np.testing.assert_allclose(table["x.final"], 0.5, rtol=1e-9)
    _against_simulate(drain, table, "k=0.5:3:6", np.linspace(0.5, 3.0, 6), stop=2.0,
                      interval=0.1)


def test_a_time_event_and_the_terminal_event(cache: None, tmp_path: Path) -> None:
    last = springc.load_model_from_string(LAST)
    table = _table(last, tmp_path / "l.parquet", "k=0.5:2:4", stop=1.0, interval=0.05)
    for run, k in enumerate(np.linspace(0.5, 2.0, 4)):
        x = 2 * math.exp(-k)  # doubled at 0.35 s
        assert abs(table["x.final"][run] - x) <= 1e-8
        assert table["atEnd.final"][run] == table["x.final"][run]
        assert table["atEnd.min"][run] == 0.0  # 0 up to the last row
    _against_simulate(last, table, "k=0.5:2:4", np.linspace(0.5, 2.0, 4), stop=1.0,
                      interval=0.05)
