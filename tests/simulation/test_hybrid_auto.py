"""``--solver auto`` on hybrid models (springc.simulation.hybrid_auto): a stiff RC
circuit switched by ``sample`` goes to radau for its counted work, and so does a stiff
mass whose start rings (radau's first probe spends its steps on the ringing), the
bouncing ball and a long sampled oscillator keep dop853 with its very steps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from simulation.test_hybrid import BALL, ball_exact, write

TAU = 1e-5
RC = f"""
model StiffRC
  parameter Real tau = {TAU};
  Real v(start = 0, fixed = true);
  discrete Real u(start = 0);
equation
  der(v) = (u - v) / tau;
  when sample(0.05, 0.1) then
    u = 1 - pre(u);
  end when;
end StiffRC;
"""

OSCILLATOR = """
model SampledOscillator
  Real x(start = 1, fixed = true);
  Real y(start = 0, fixed = true);
  discrete Integer n(start = 0);
equation
  der(x) = y;
  der(y) = -x;
  when sample(0.5, 1) then
    n = pre(n) + 1;
  end when;
end SampledOscillator;
"""


RINGING = """
model RingingStart
  Real x(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
  Real y(start = 0, fixed = true);
  discrete Integer n(start = 0);
equation
  der(x) = v;
  der(v) = -1e8 * x - 5e3 * v;
  der(y) = 1 - y;
  when sample(1, 1) then
    n = pre(n) + 1;
  end when;
end RingingStart;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def rc_exact(t: np.ndarray) -> np.ndarray:
    """v of the RC circuit: u toggles at 0.05 + 0.1 k, v follows with time constant
    TAU from the level before (reached to within exp(-0.1 / TAU))."""
    k = np.floor((t - 0.05) / 0.1 + 1e-9)  # events up to t (-1: none yet)
    u = np.where(k >= 0, (k + 1) % 2, 0.0)
    before = np.where(k >= 1, k % 2, 0.0)
    since = np.maximum(t - (0.05 + 0.1 * np.maximum(k, 0)), 0.0)
    return np.where(k >= 0, u + (before - u) * np.exp(-since / TAU), 0.0)


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_a_stiff_switched_circuit_goes_to_radau(tmp_path: Path, engine: str) -> None:
    model = springc.compile_model(write(tmp_path, RC))
    runs = {solver: springc.simulate(model, solver=solver, engine=engine, stop=1.0,
                                     interval=1e-5, error_control="off")
            for solver in ("auto", "radau", "dop853")}
    auto, radau, dop853 = runs["auto"], runs["radau"], runs["dop853"]
    assert auto.stats.solver == "radau"
    assert auto.stats.reason.startswith(
        "stiff: fastest time scale 1/1e+05 s is 1e+05x shorter than the 1 s span; "
        "counted: radau ~")
    assert "RHS evaluations to go, dop853 ~" in auto.stats.reason
    # auto runs radau afresh: the very run of --solver radau, in a tenth of dop853's steps
    assert auto.stats.steps == radau.stats.steps < dop853.stats.steps / 10
    assert np.array_equal(auto["v"], radau["v"])
    # the closed form, transients included (1e5 rows, 10 switchings)
    assert np.max(np.abs(auto["v"] - rc_exact(auto.time))) < 2e-4


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_the_bouncing_ball_keeps_dop853(tmp_path: Path, engine: str) -> None:
    model = springc.compile_model(write(tmp_path, BALL))
    auto, dop853 = (springc.simulate(model, solver=solver, engine=engine, stop=1.0,
                                     error_control="off") for solver in ("auto", "dop853"))
    assert (auto.stats.solver, auto.stats.reason) == (
        "dop853", "a hybrid model: dop853 with event location")
    assert auto.stats.steps == dop853.stats.steps
    assert np.array_equal(auto.values, dop853.values)
    h, _, _ = ball_exact(auto.time, 3)
    assert np.max(np.abs(auto["h"] - h)) < 1e-6


def test_a_long_non_stiff_run_keeps_dop853_after_its_probe(tmp_path: Path) -> None:
    model = springc.compile_model(write(tmp_path, OSCILLATOR))
    auto, dop853 = (springc.simulate(model, solver=solver, engine="scipy", stop=1000.0,
                                     interval=0.5, error_control="off")
                    for solver in ("auto", "dop853"))
    assert auto.stats.solver == "dop853"
    assert dop853.stats.steps > 500  # past the probe: the estimate decided
    assert auto.stats.reason == ("non-stiff: spectral radius 1 1/s over 1000 s "
                                 "(rho*T = 1e+03 <= 2000)")
    assert auto.stats.steps == dop853.stats.steps
    assert np.array_equal(auto.values, dop853.values)
    assert auto["n"][-1] == 1000
    assert np.max(np.abs(auto["x"] - np.cos(auto.time))) < 1e-3  # 160 periods at rtol 1e-6


def test_a_stiff_start_that_rings_goes_to_radau_past_its_first_probe(tmp_path: Path) -> None:
    """radau's first 100 steps cover under 1e-3 s of the ringing (omega 1e4 1/s, damping
    ratio 0.25): at that rate its projection is dearer than dop853's; the longer probes,
    projected at the rate of the steps each added, find the run cheap (Translational.
    PreLoad's start, where dop853 took 8e5 steps)."""
    model = springc.compile_model(write(tmp_path, RINGING))
    auto, radau = (springc.simulate(model, solver=solver, engine="scipy", stop=100.0,
                                    interval=0.1, error_control="off")
                   for solver in ("auto", "radau"))
    assert radau.step_times[99] < 1e-3
    assert auto.stats.solver == "radau"
    assert auto.stats.reason.startswith(
        "stiff: fastest time scale 1/1e+04 s is 1e+06x shorter than the 100 s span; "
        "counted: radau finished the run in its 1600 trial steps, dop853 ~")
    assert auto.stats.steps == radau.stats.steps < 1600
    assert np.array_equal(auto.values, radau.values)
    zeta, w0 = 0.25, 1e4
    wd = w0 * np.sqrt(1 - zeta**2)
    t = auto.time
    x = np.exp(-zeta * w0 * t) * (np.cos(wd * t) + zeta * w0 / wd * np.sin(wd * t))
    assert np.max(np.abs(auto["x"] - x)) < 1e-6
    assert np.max(np.abs(auto["y"] - (1 - np.exp(-t)))) < 1e-5
    assert np.array_equal(auto["n"], np.floor(t + 1e-9))


def test_dop853_is_probed_again_where_radaus_stretch_reaches_further(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A run quiet for its first second, busy after (CauerLowPassSC's input steps at 1 s):
    dop853's probe of 500 steps ends at 1.0 and projects the quiet rate; radau's second
    stretch reaches 1.1, so dop853 runs again 4x longer and is projected from the steps
    it added past 1.0. Counted reaches and work (13 RHS a dop853 step, 40 a radau step)
    give the projections in closed form."""
    from types import SimpleNamespace

    from springc.simulation import hybrid_auto
    from springc.simulation.limits import OverLimit
    from springc.simulation.solvers import AutoChoice

    stop, per_step = 60.0, {"dop853": 13.0, "radau": 40.0}

    def reach(solver: str, steps: int) -> float:
        if solver == "dop853":  # 500 steps a second, then 1e5
            return steps / 500 if steps <= 500 else 1.0 + (steps - 500) * 1e-5
        return 0.008 * steps if steps <= 100 else 0.8 + (steps - 100) * 1e-3

    made: list[tuple[str, int | None]] = []

    def attempt(solver: str, cap: int | None) -> hybrid_auto.Attempt:
        made.append((solver, cap))
        problem = SimpleNamespace(solver=solver, jac=lambda t, y: np.eye(1))
        loop = SimpleNamespace(steps=cap or 0)
        capped = None if cap is None else OverLimit("cap", reach(solver, cap), np.zeros(1),
                                                    solver)
        return hybrid_auto.Attempt(problem, loop, True, 0.0, capped)

    monkeypatch.setattr(hybrid_auto, "_work", lambda probe, implicit: probe.loop.steps
                        * per_step["radau" if implicit else "dop853"])
    monkeypatch.setattr(hybrid_auto, "estimate", lambda jac, span: AutoChoice(
        "race", "stiff", 1e6, span))
    run, reason = hybrid_auto.choose(attempt, np.zeros(1), 0.0, stop, 10**9)
    assert made == [("dop853", 500), ("radau", 100), ("radau", 400), ("dop853", 2000),
                    ("radau", None)]
    assert run.problem.solver == "radau" and run.capped is None
    radau = (stop - 1.1) * 300 / 0.3  # the marginal rate of radau's second stretch
    dop853 = (stop - 1.015) * 1500 / 0.015  # of the 1,500 steps dop853 added past 1.0
    assert reason == (f"stiff; counted: radau ~{radau:.2g} steps x 40 = ~{radau * 40:.2g} "
                      f"RHS evaluations to go, dop853 ~{dop853:.2g} steps x 13 = "
                      f"~{dop853 * 13:.2g}")
