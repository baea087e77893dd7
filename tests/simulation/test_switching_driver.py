"""The dynamic-state-selection driver ``simulate_switching`` (``solve_ivp`` with a
conditioning event) on the rigid pair and the pendulum."""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files
from springc.simplify.state_choice import THRESHOLD
from springc.simulation.switching import EvaluatorFunctions, simulate_switching

SCENES = Path(__file__).resolve().parents[2] / "models" / "Scenes.mdl"
G = 9.81
P1 = {"p1.pos[1]", "p1.pos[2]", "p1.v[1]", "p1.v[2]"}


@cache
def scene(name: str) -> FlatModel:
    return flatten_files([SCENES], f"Scenes.{name}")


def energy_of_rigid_pair(v: dict[str, np.ndarray]) -> np.ndarray:
    """Kinetic + spring + gravity (m1 = m2 = 1, k = 1000, rest length 1)."""
    kinetic = sum(0.5 * (v[f"{p}.v[1]"] ** 2 + v[f"{p}.v[2]"] ** 2) for p in ("p1", "p2"))
    gravity = sum(G * v[f"{p}.pos[2]"] for p in ("p1", "p2"))
    return kinetic + gravity + 0.5 * 1e3 * (v["spring.len"] - 1.0) ** 2


def test_rigid_pair_switches_before_the_rod_turns_vertical() -> None:
    """0-5 s at rtol 1e-8: the static choice fails at t = 0.556 s (rod vertical);
    with switching the rod length holds to 1e-6 and the energy to 1e-5 J (of 19.6 J)."""
    built: list[set[str]] = []

    def make_functions(choice, params, guess):  # type: ignore[no-untyped-def]
        built.append(set(choice.states))
        return EvaluatorFunctions(choice, params, guess)

    times = np.linspace(0.0, 5.0, 251)
    result = simulate_switching(scene("RigidPair"), (0.0, 5.0), times, rtol=1e-8,
                                atol=1e-10, make_functions=make_functions)
    np.testing.assert_allclose(result.t, times, rtol=0, atol=1e-12)
    v = result.values
    rod = np.hypot(v["p2.pos[1]"] - v["p1.pos[1]"], v["p2.pos[2]"] - v["p1.pos[2]"])
    assert np.max(np.abs(rod - 1.0)) < 1e-6
    energy = energy_of_rigid_pair(v)
    assert energy[0] == pytest.approx(-2 * G)
    assert np.max(np.abs(energy - energy[0])) < 1e-5
    assert len(result.switches) >= 1
    first = result.switches[0]
    assert 0.3 < first.time < 0.556
    assert first.conditioning == pytest.approx(THRESHOLD, rel=1e-3)
    assert {"p2.pos[2]", "p2.v[2]"} <= set(first.old_states)
    assert set(first.new_states) == P1 | {"p2.pos[1]", "p2.v[1]"}
    assert built[:4] == [set(first.old_states)] * 2 + [set(first.new_states)] * 2
    assert len(built) == 2 * (len(result.switches) + 1)  # integration and output


def test_pendulum_runs_without_switching() -> None:
    """|phi| <= 45 degrees: y stays the better coordinate to solve; no switch."""
    times = np.linspace(0.0, 10.0, 101)
    result = simulate_switching(scene("Pendulum"), (0.0, 10.0), times, rtol=1e-8,
                                atol=1e-10)
    assert result.switches == ()
    v = result.values
    assert np.max(np.abs(np.hypot(v["x"], v["y"]) - 1.0)) < 1e-12


def test_pendulum_over_the_horizontal_switches_back_and_forth() -> None:
    """phi0 = 2 rad: x is singular at the horizontal, y at the bottom; the angle
    matches theta'' = -g sin(theta) to 1e-4 over 5 s with alternating switches."""
    times = np.linspace(0.0, 5.0, 101)
    result = simulate_switching(scene("Pendulum"), (0.0, 5.0), times, rtol=1e-8,
                                atol=1e-10, parameters={"phi0": 2.0})
    chosen = [set(s.new_states) for s in result.switches]
    assert len(chosen) >= 6
    assert all(c == ({"y", "vy"} if k % 2 == 0 else {"x", "vx"}) for k, c in enumerate(chosen))
    v = result.values
    theta = np.arctan2(v["x"], -v["y"])
    ref = solve_ivp(lambda t, s: [s[1], -G * math.sin(s[0])], (0.0, 5.0), [2.0, 0.0],
                    method="DOP853", rtol=1e-12, atol=1e-12, t_eval=times)
    assert np.max(np.abs(theta - ref.y[0])) < 1e-4
    energy = 0.5 * (v["vx"] ** 2 + v["vy"] ** 2) + G * v["y"]
    assert np.max(np.abs(energy - energy[0])) < 1e-4


def test_loose_tolerance_steps_past_the_singularity_are_rejected_not_fatal() -> None:
    """At rtol 1e-3 DOP853 tries stages beyond the vertical rod, where Newton fails:
    the driver turns the failure into a rejected step and still switches in time."""
    result = simulate_switching(scene("RigidPair"), (0.0, 1.0), [0.0, 0.5, 1.0], rtol=1e-3,
                                atol=1e-5)
    assert [round(s.time, 2) for s in result.switches] == [0.51]
    v = result.values
    rod = np.hypot(v["p2.pos[1]"] - v["p1.pos[1]"], v["p2.pos[2]"] - v["p1.pos[2]"])
    assert np.max(np.abs(rod - 1.0)) < 1e-9


def test_without_t_eval_every_step_is_output_once_with_the_switch_times() -> None:
    result = simulate_switching(scene("Pendulum"), (0.0, 1.0), rtol=1e-6, atol=1e-8,
                                parameters={"phi0": 2.0})
    assert np.all(np.diff(result.t) > 0) and result.t[-1] == 1.0
    assert len(result.switches) >= 2
    assert all(s.time in result.t for s in result.switches)


def test_a_run_that_fails_before_its_first_output_time_says_where(
        capsys: pytest.CaptureFixture[str]) -> None:
    """g = 1e300 overflows at once: the failure names the time the integrator reached
    (no output time was reached, so there is no last output to name), with no warnings."""
    import springc
    from springc.errors import SimulationError

    with pytest.raises(SimulationError) as caught:
        springc.simulate(str(SCENES), model_name="Scenes.Pendulum", stop=1.0,
                         interval=0.5, parameters={"g": 1e300})
    message = caught.value.message
    assert message.startswith("the integration failed at t = ")
    reached = float(message.removeprefix("the integration failed at t = ").split(":")[0])
    assert 0.0 <= reached < 0.5  # before the first output time after the start
    assert "Warning" not in capsys.readouterr().err


# A switching pendulum with a discrete output (an Integer, as a MultiBody shape's colour).
COLOURED = """model Coloured
  parameter Real L = 1, g = 9.81;
  parameter Integer colour[3] = {0, 128, 255};
  Real x(start = 0.6), y(start = -0.8);
  Real vx(start = 0), vy, F;
  Integer c = colour[2];
equation
  der(x) = vx;
  der(y) = vy;
  der(vx) = -F*x;
  der(vy) = -F*y - g;
  x^2 + y^2 = L^2;
end Coloured;
"""


def test_a_discrete_variable_is_an_output_of_a_switching_run(tmp_path: Path) -> None:
    import springc

    path = tmp_path / "coloured.mo"
    path.write_text(COLOURED)
    result = springc.simulate(str(path), stop=0.2, interval=0.1, rtol=1e-8)
    assert result.stats.reason == "dynamic state selection, no switch in this run"
    assert list(result["c"]) == [128.0, 128.0, 128.0]
    # the rod keeps its length
    assert np.max(np.abs(result["x"] ** 2 + result["y"] ** 2 - 1.0)) < 1e-6
