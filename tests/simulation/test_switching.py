"""``springc.simulate`` switches states for RigidPair when its rod passes vertical."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError

MODELS = Path(__file__).resolve().parents[2] / "models"


def test_rigid_pair_runs_through_the_switch_with_the_rod_length_kept() -> None:
    result = springc.simulate([MODELS / "Scenes.mdl"], model_name="Scenes.RigidPair",
                              stop=1.0, interval=0.01, rtol=1e-8, cache=False)
    length = np.hypot(result["p2.pos[1]"] - result["p1.pos[1]"],
                      result["p2.pos[2]"] - result["p1.pos[2]"])
    assert np.max(np.abs(length - 1.0)) < 1e-9  # Rod(l = 1), solved from the constraint
    assert result.time[-1] == 1.0 and len(result.time) == 101
    reason = result.stats.reason
    assert reason.startswith("dynamic state selection, 1 switch (t = 0.51")


def test_assertions_are_checked_at_output_times_of_a_switching_run(tmp_path: Path) -> None:
    path = tmp_path / "checked.mo"
    path.write_text("model Checked\n  extends Scenes.RigidPair;\nequation\n"
                    '  assert(p2.pos[1] > 0.5, "p2 swung past x = 0.5");\nend Checked;\n')
    free = springc.simulate([MODELS / "Scenes.mdl"], model_name="Scenes.RigidPair",
                            stop=1.0, interval=0.01, rtol=1e-8, cache=False)
    first = free.time[np.flatnonzero(free["p2.pos[1]"] <= 0.5)[0]]
    with pytest.raises(SimulationError) as info:
        springc.simulate([MODELS / "Scenes.mdl", path], model_name="Checked", stop=1.0,
                         interval=0.01, rtol=1e-8, cache=False)
    assert info.value.message == \
        f"assertion failed at t = {first:.9g}: p2 swung past x = 0.5"
    assert info.value.span is not None and info.value.span.line == 4


# A derivative that index reduction makes a state: vx = der(x) with vx avoided leaves
# der(x) (not vx) the state of the velocity level, so 'der(x)' is an output name that no
# flat variable has (MSL's Body: v_0 = der(r_0), v_0 avoided; PointGravityWithPointMasses2).
PENDULUM = """model AvoidedVelocityPendulum
  parameter Real g = 9.81;
  Real x(start = 0.6, fixed = true);
  Real y(start = -0.8);
  Real vx(start = 3.6, fixed = true, stateSelect = StateSelect.avoid);
  Real vy(stateSelect = StateSelect.avoid);
  Real lam;
equation
  vx = der(x);
  vy = der(y);
  der(vx) = -lam*x;
  der(vy) = -lam*y - g;
  x^2 + y^2 = 1;
end AvoidedVelocityPendulum;
"""


def test_a_derivative_made_a_state_is_an_output_of_the_switching_run(
        tmp_path: Path) -> None:
    from scipy.integrate import solve_ivp

    path = tmp_path / "pendulum.mo"
    path.write_text(PENDULUM)
    result = springc.simulate(path, stop=3.0, interval=0.05, rtol=1e-10, atol=1e-12,
                              engine="scipy", error_control="off", cache=False)
    assert result.names[:2] == ("x", "der(x)")
    # It swings past the horizontal (theta' = 4.5 at theta = asin 0.6): x or y must be
    # the state, in turn.
    assert result.stats.reason.startswith("dynamic state selection, 5 switches (t = 0.2204")
    # Independent: theta'' = -g sin(theta), x = sin(theta), der(x) = cos(theta) theta'.
    exact = solve_ivp(lambda t, z: [z[1], -9.81 * np.sin(z[0])], (0.0, 3.0),
                      [np.arcsin(0.6), 4.5], t_eval=result.time, method="DOP853",
                      rtol=1e-12, atol=1e-12)
    theta, rate = exact.y
    assert np.max(np.abs(result["der(x)"] - np.cos(theta) * rate)) < 1e-7
    assert np.max(np.abs(result["vy"] - np.sin(theta) * rate)) < 1e-7
