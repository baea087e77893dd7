"""Hybrid models on the C loop (a python module, the compiled engine: the runs between
events in C, their crossings and time events located there, the event update in Python)
against closed forms; the engine a run takes depends on its options only."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc
from simulation.test_newton_warm_starts import MODEL as WARM_MODEL
from simulation.test_newton_warm_starts import charge, diode_voltage, source
from springc.simulation.compiled import engine_reason

G, E = 9.81, 0.8
BALL = f"""model Ball
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -{G};
  when h < 0 then
    reinit(v, -{E} * pre(v));
  end when;
end Ball;
"""
SWITCHED_RC = """model SwitchedRC
  Real v(start = 0, fixed = true);
  Boolean on(start = true, fixed = true);
  Boolean late(start = false, fixed = true);
equation
  der(v) = if on then 1 - v else (if late then 2 - v else -v);
  when v > 0.5 then
    on = false;
  end when;
  when time >= 2.5 then
    late = true;
  end when;
end SwitchedRC;
"""
C_REASON = ("{} ran in the compiled loop (C, no Python per step: a C compiler was "
            "found; SPRINGC_LOOP=numba runs numba's)")


@pytest.fixture(autouse=True)
def _c_loop(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("SPRINGC_LOOP", "c")


def _impacts(count: int) -> list[float]:
    """The ball's impact times: t1 = sqrt(2 h0 / g), then flights of 2 e^k v1 / g."""
    v1 = math.sqrt(2 * G)
    times = [math.sqrt(2 / G)]
    for k in range(1, count):
        times.append(times[-1] + 2 * E ** k * v1 / G)
    return times


@pytest.mark.parametrize("solver", ["dop853", "radau", "bdf"])
def test_a_bouncing_ball_in_the_c_loop_bounces_at_the_closed_form_times(solver: str) -> None:
    model = springc.load_model_from_string(BALL, backend="python")
    result = springc.simulate(model, solver=solver, engine="compiled", stop=3.0,
                              rtol=1e-10, error_control="off")
    assert result.stats.engine == "compiled"
    # each impact: h < 0 becomes true (the reinit), then false again just after it
    falls = [e.time for e in result.events if e.kind == "state"
             and e.x_left[1] < 0 < e.x_right[1]]
    expected = _impacts(len(falls))
    assert len(falls) == 6  # 0.45, 1.17, 1.75, 2.21, 2.58, 2.88 s
    assert np.allclose(falls, expected, rtol=0, atol=1e-8)
    # between impacts the flight is exact for any solver: h(3) from the last impact
    last, speed = expected[-1], E ** len(falls) * math.sqrt(2 * G)
    h3 = speed * (3.0 - last) - G / 2 * (3.0 - last) ** 2
    assert abs(result["h"][-1] - h3) <= 1e-7


def _switched_rc(t: np.ndarray) -> np.ndarray:
    """v of SwitchedRC: charging to 1 until v = 0.5 (t = ln 2), discharging to 0 until
    the time event at 2.5 s, then charging to 2."""
    t_on = math.log(2.0)
    v_late = 0.5 * math.exp(-(2.5 - t_on))
    return np.where(t <= t_on, 1 - np.exp(-t),
                    np.where(t < 2.5, 0.5 * np.exp(-(t - t_on)),
                             2 - (2 - v_late) * np.exp(-(t - 2.5))))


@pytest.mark.parametrize("solver", ["dop853", "radau"])
def test_an_rc_switched_at_a_state_and_a_time_event_follows_its_closed_form(
        solver: str) -> None:
    model = springc.load_model_from_string(SWITCHED_RC, backend="python")
    result = springc.simulate(model, solver=solver, engine="compiled", stop=4.0,
                              interval=0.01, rtol=1e-10, error_control="off")
    assert result.stats.engine == "compiled"
    state = [e.time for e in result.events if e.kind == "state"]
    assert abs(state[0] - math.log(2.0)) <= 1e-9
    assert [e.time for e in result.events if e.kind == "time"] == [2.5]
    assert np.abs(result["v"] - _switched_rc(result.time)).max() <= 1e-8
    assert result["on"][-1] == 0.0 and result["late"][-1] == 1.0


def test_the_engine_of_a_hybrid_run_follows_its_options_only() -> None:
    model = springc.load_model_from_string(SWITCHED_RC, backend="python")
    runs = [springc.simulate(model, engine=engine, stop=4.0, error_control="off")
            for engine in ("auto", "auto", "scipy")]
    first, again, scipy = runs
    assert first.stats.engine == again.stats.engine == "compiled"
    solver = first.stats.solver  # auto's choice, by counts
    assert again.stats.solver == solver and first.stats.steps == again.stats.steps
    assert first.stats.engine_reason == again.stats.engine_reason == C_REASON.format(solver)
    assert np.array_equal(first.values, again.values)  # the same run, bit for bit
    assert scipy.stats.engine == "scipy"
    assert engine_reason("auto", solver, model.module, True) == C_REASON.format(solver)
    # both engines solve the same model: within their tolerances of one another
    assert np.abs(first["v"] - scipy["v"]).max() <= 1e-5


@pytest.mark.parametrize("solver", ["dop853", "rk45"])
def test_newton_warm_starts_in_the_c_loop_come_from_accepted_points(
        tmp_path: Path, solver: str) -> None:
    """test_newton_warm_starts' diode on the C loop: the first step's probe after the
    time event at 1 s evaluates at 15.1 s (source held at -105 V) and must not leave
    its warm start, and a block that does not converge is solved again from the
    step's start (before: "did not converge at time 1", as HeatingNPN_NORGate at
    79.88 s)."""
    path = tmp_path / "ProbeWarmStart.mo"
    path.write_text(WARM_MODEL)
    result = springc.simulate(str(path), backend="python", engine="compiled", stop=20.0,
                              interval=0.25, solver=solver, rtol=1e-9, atol=1e-9,
                              error_control="off")
    assert result.stats.engine == "compiled"
    times = [float(t) for t in result.time]
    assert times[-1] == 20.0
    expected_v = [diode_voltage(source(t)) for t in times]
    assert np.allclose(np.asarray(result["v"]), expected_v, rtol=0, atol=1e-11)
    assert np.allclose(np.asarray(result["q"]), [charge(t) for t in times], rtol=0,
                       atol=5e-5)
    assert [e.cause for e in result.events if e.kind == "state"] == ["c < 1002"]
