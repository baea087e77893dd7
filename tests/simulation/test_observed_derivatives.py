"""Observed variables defined through a derivative agree with the trajectory they are
derived from (issue 28, point 4).

For every model of the bundled library (models/), the event scenes (BouncingBall has
no such variable: its derivatives are states) and a Zener clamp
of our own (models/ZenerClamp.mo here: MSL's OvervoltageProtection in small), every
flat equation that holds ``der(x)`` of an output ``x`` together with an observed
variable (``i = C*der(v)``, ``m*der(v) = f``, ``a = der(v)``) is solved for
``der(x)`` from the written outputs at each output time and compared with two
references:

- exact: the generated ``rhs`` at the written states, with the discrete values in
  force there (the last event's), its Newton iterations checked converged; within
  1e-6 of the derivative's range (Newton stops at 1e-10 relative);
- independent: a central difference of the written ``x``, at rows away from events
  (none within two output intervals) where the difference resolves the derivative
  (``|D_h - D_2h| <= 0.1 max|D_h|``, ``D_h`` and ``D_2h`` the central differences
  over one and two intervals), within ``|D_h - D_2h| + 2 delta / h + 1e-3 max|D_h|``:
  the truncation error of ``D_h`` is a third of ``|D_h - D_2h|``; ``delta``, ten times
  the run's tolerance on ``x`` (``rtol max|x| + atol``), is the written states' error,
  divided by the spacing ``h`` in a difference; and the derivative at a written state
  differs from the true one by the Jacobian times the state's error, which for a stiff
  component integrated explicitly reaches 1e-3 of the derivative's range.

Before the fix, a hybrid run's output rows were solved with the Newton warm starts of
the end of their kernel run, and a row that did not converge was written as it was:
the Zener clamp wrote ``i`` = 5.3e5 A at 92 of 576 rows where ``C*der(v)`` is below
0.25 A.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import springc
from springc.ir import expr as x
from springc.ir.dae import derivative_name

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
CLAMP = Path(__file__).resolve().parent / "models" / "ZenerClamp.mo"

# file, model, stop time and output interval (None: the experiment's): the interval
# resolves the fastest motion for the difference
CASES = [
    (MODELS / "SpringMass.mdl", "SpringMass", 2.0, 1e-3),
    (MODELS / "Scenes.mdl", "Scenes.SpringMassConnected", 2.0, 1e-3),
    (MODELS / "Scenes.mdl", "Scenes.DampedSpringMass", 2.0, 1e-3),
    (MODELS / "Scenes.mdl", "Scenes.Chain", 2.0, 1e-3),
    (MODELS / "Scenes.mdl", "Scenes.Oscillator", 2.0, 1e-3),
    (MODELS / "Scenes.mdl", "Scenes.Pendulum", 2.0, 1e-3),
    (MODELS / "Scenes.mdl", "Scenes.RigidPair", 2.0, 1e-3),
    (MODELS / "EventScenes.mdl", "EventScenes.WallContact", None, None),
    (MODELS / "EventScenes.mdl", "EventScenes.NewtonsCradle", None, 1e-5),
    (MODELS / "EventScenes.mdl", "EventScenes.FloorBounce", None, None),
    (CLAMP, "ZenerClamp", None, None),
]
EXACT = 1e-6
"""Of the derivative's range: the written outputs against the rhs at the written states."""
RELATIVE_FLOOR = 1e-3
"""Of the derivative's range: what a derivative at a written state may be off by."""
RESOLVED = 0.1
"""Rows where ``|D_h - D_2h|`` exceeds this fraction of the range are not resolved."""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@dataclass(frozen=True)
class Relation:
    """A flat equation ``residual = 0`` that holds ``der(state)`` and observed outputs."""

    state: str
    residual: x.Expr
    text: str


def _named_derivatives(e: x.Expr) -> x.Expr:
    """``e`` with every ``der(v)`` of a plain variable as the variable ``der(v)``."""
    if isinstance(e, x.Der) and isinstance(e.arg, x.Var):
        return x.Var(derivative_name(e.arg.name))
    return x.map_children(e, _named_derivatives)


def derivative_relations(model: springc.CompiledModel, outputs: set[str],
                         parameters: set[str]) -> list[Relation]:
    """The flat equations of ``model`` with exactly one ``der(v)``, ``v`` an output,
    at least one observed output besides, and nothing but outputs and parameters."""
    flat_model = model.derive().flat_model
    observed = outputs - set(model.states)
    found = []
    for eq in flat_model.equations:
        residual = x.sub(eq.lhs, eq.rhs)
        ders = x.derivatives(residual)
        if len(ders) != 1 or not ders <= outputs:
            continue
        names = x.variables(residual)
        if not names & observed or not names <= outputs | parameters:
            continue
        text = f"{x.to_text(eq.lhs)} = {x.to_text(eq.rhs)}"
        found.append(Relation(ders.pop(), _named_derivatives(residual), text))
    return found


def implied_derivatives(relation: Relation, result: springc.SimulationResult) -> np.ndarray:
    """``der(state)`` solved at every row from the relation with the outputs written
    there (the relation is linear in it: checked)."""
    env: dict[str, object] = dict(result.parameters)
    key = derivative_name(relation.state)
    out = np.empty(len(result.time))
    for row in range(len(result.time)):
        env.update(zip(result.names, result.values[row].tolist()))
        values = []
        for d in (0.0, 1.0, 2.0):
            env[key] = d
            values.append(float(x.evaluate(relation.residual, env, float(result.time[row]))))
        r0, r1, r2 = values
        assert abs(r2 - 2 * r1 + r0) <= 1e-9 * max(abs(r0), abs(r1), abs(r2), 1.0)
        out[row] = -r0 / (r1 - r0)
    return out


def rhs_at_rows(model: springc.CompiledModel, result: springc.SimulationResult
                ) -> np.ndarray:
    """The derivatives of the states from the generated rhs at every written row, with
    the ``z`` of the last event at or before it; each row's Newton iterations warm
    started from the row before, else from the start guesses, and checked converged."""
    mod: Any = model.module
    p = np.asarray(mod.parameters(), dtype=float)
    states = np.column_stack([result[s] for s in model.states])
    events = [(e.time, e.z_right) for e in result.events]
    n = len(mod.GUESSES)
    guesses = np.asarray(mod.guesses(p), dtype=float)
    warm = guesses[:n].copy()
    out = np.empty_like(states)
    for row, t in enumerate(result.time):
        held = [z for time, z in events if time <= t]
        z = np.array(held[-1] if held else guesses, dtype=float)
        for start in (warm, guesses[:n]):
            z[:n], z[-1] = start, 0.0
            out[row] = mod.rhs(float(t), states[row], p, z)
            if z[-1] == 0.0:
                break
        assert z[-1] == 0.0, f"the reference rhs does not converge at t = {t}"
        warm = z[:n].copy()
    return out


def _away_from_events(result: springc.SimulationResult) -> list[int]:
    t = result.time
    events = np.array([e.time for e in result.events if e.kind in ("state", "time")])
    return [i for i in range(2, len(t) - 2)
            if not ((events >= t[i - 2]) & (events <= t[i + 2])).any()]


def difference_ratio(implied: np.ndarray, s: np.ndarray, t: np.ndarray, rows: list[int],
                     delta: float) -> tuple[int, float]:
    """Resolved rows among ``rows`` and the worst ratio of ``|implied - D_h|`` to its
    bound there (see the module docstring)."""
    d_h = np.array([(s[i + 1] - s[i - 1]) / (t[i + 1] - t[i - 1]) for i in rows])
    d_2h = np.array([(s[i + 2] - s[i - 2]) / (t[i + 2] - t[i - 2]) for i in rows])
    h = np.array([(t[i + 1] - t[i - 1]) / 2 for i in rows])
    scale = np.max(np.abs(d_h))
    resolved = np.abs(d_h - d_2h) <= RESOLVED * scale
    bound = np.abs(d_h - d_2h) + 2 * delta / h + RELATIVE_FLOOR * scale
    ratio = np.abs(implied[rows] - d_h) / bound
    return int(resolved.sum()), float(np.max(ratio[resolved], initial=0.0))


@pytest.mark.parametrize(("path", "name", "stop", "interval"), CASES,
                         ids=[case[1] for case in CASES])
def test_observed_derivatives_agree_with_the_trajectory(
        path: Path, name: str, stop: float | None, interval: float | None) -> None:
    model = springc.compile_model(str(path), name)
    result = springc.simulate(model, stop=stop, interval=interval)
    tolerance = model.module.EXPERIMENT.get("tolerance")
    rtol = 1e-6 if tolerance is None else float(tolerance)
    relations = derivative_relations(model, set(result.names), set(result.parameters))
    assert relations, f"{name}: no observed variable defined through a derivative"
    exact = rhs_at_rows(model, result)
    rows = _away_from_events(result)
    for relation in relations:
        implied = implied_derivatives(relation, result)
        s = result[relation.state]
        if relation.state in model.states:
            reference = exact[:, model.states.index(relation.state)]
            scale = max(np.max(np.abs(reference)), 1e-300)
            worst_exact = float(np.max(np.abs(implied - reference)))
            assert worst_exact <= EXACT * scale, \
                f"{name}: {relation.text}: off by {worst_exact:.3g} (range {scale:.3g})"
        delta = 10 * (rtol * np.max(np.abs(s)) + rtol / 1000)
        resolved, worst = difference_ratio(implied, s, result.time, rows, delta)
        assert resolved >= len(result.time) // 2, f"{relation.text}: {resolved} rows"
        assert worst <= 1.0, f"{name}: {relation.text}: {worst:.3g} times the bound"
