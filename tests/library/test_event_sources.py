"""The bundled library's classes whose equations switch on a relation (time < startTime,
mod(time, period), the contact of ElastoGap), and the Standard Library examples that use
them, against closed forms. They need state and time events: the `events` branch makes
relations on time and variables simulatable (until it is merged, flattening them reports
"relations on variables generate events, which are not supported yet")."""

from __future__ import annotations

import math

import numpy as np
import pytest

import springc


@pytest.fixture(autouse=True)
def _no_environment_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("MODELICAPATH", raising=False)


def simulate(text: str, stop: float, points: int = 400) -> springc.SimulationResult:
    compiled = springc.load_model_from_string(text, cache=False)
    return springc.simulate(compiled, stop=stop, interval=stop / points, rtol=1e-10,
                            atol=1e-12)


def away_from(t: np.ndarray, jumps: list[float], band: float = 1e-6) -> np.ndarray:
    """The grid points not within ``band`` of a discontinuity."""
    mask = np.ones_like(t, dtype=bool)
    for jump in jumps:
        mask &= np.abs(t - jump) > band
    return mask


S = "Modelica.Blocks.Sources"

SOURCES = f"""
model Sources
  {S}.Step step(height = 2, offset = 1, startTime = 0.5);
  {S}.Ramp ramp(height = 2, duration = 1, offset = 0.5, startTime = 0.25);
  {S}.Sine sine(amplitude = 2, f = 1.5, phase = 0.3, offset = 1, startTime = 0.2);
  {S}.Cosine cosine(amplitude = 2, f = 1.5, phase = 0.3, offset = 1, startTime = 0.2);
  {S}.ExpSine expSine(amplitude = 2, f = 1.5, phase = 0.3, damping = 0.7, startTime = 0.2);
  {S}.Pulse pulse(amplitude = 3, width = 40, period = 0.5, offset = -1,
    startTime = 0.1, nperiod = 3);
  {S}.Trapezoid trapezoid(amplitude = 2, rising = 0.1, width = 0.2, falling = 0.1,
    period = 0.5, startTime = 0.1);
  Real x(start = 0, fixed = true) "integral of the step";
equation
  der(x) = step.y;
end Sources;
"""


def test_signal_sources_against_their_definitions() -> None:
    r = simulate(SOURCES, 2.0)
    t = r.time
    ok = away_from(t, [0.5])
    assert np.max(np.abs((r["step.y"] - np.where(t < 0.5, 1, 3))[ok])) < 1e-12
    assert np.max(np.abs(r["x"] - np.where(t < 0.5, t, 0.5 + 3 * (t - 0.5)))) < 1e-8
    ramp = 0.5 + np.clip((t - 0.25) * 2, 0, 2)
    assert np.max(np.abs(r["ramp.y"] - ramp)) < 1e-12
    wave = 2 * np.pi * 1.5 * (t - 0.2) + 0.3
    on = away_from(t, [0.2])
    assert np.max(np.abs((r["sine.y"] - (1 + np.where(t < 0.2, 0, 2 * np.sin(wave))))[on])) \
        < 1e-12
    assert np.max(np.abs((r["cosine.y"] - (1 + np.where(t < 0.2, 0, 2 * np.cos(wave))))[on])) \
        < 1e-12
    damped = np.where(t < 0.2, 0, 2 * np.exp(-0.7 * (t - 0.2)) * np.sin(wave))
    assert np.max(np.abs((r["expSine.y"] - damped)[on])) < 1e-12
    # Pulse: high for 40 % of each 0.5 s period from 0.1, three periods.
    phase = np.mod(t - 0.1, 0.5)
    pulse = np.where((t < 0.1) | (t >= 1.6), -1, np.where(phase < 0.2, 2, -1))
    edges = [0.1 + 0.5 * k for k in range(4)] + [0.3 + 0.5 * k for k in range(3)]
    assert np.max(np.abs((r["pulse.y"] - pulse)[away_from(t, edges)])) < 1e-12
    # Trapezoid: rise 0.1, stay 0.2, fall 0.1, zero 0.1, in each period from 0.1.
    trap = np.interp(phase, [0, 0.1, 0.3, 0.4, 0.5], [0, 2, 2, 0, 0])
    trap = np.where(t < 0.1, 0, trap)
    assert np.max(np.abs(r["trapezoid.y"] - trap)) < 1e-9


T = "Modelica.Mechanics.Translational"

GAP = f"""
model Gap "a mass bouncing off a linear elastic gap"
  {T}.Components.Fixed fixed;
  {T}.Components.ElastoGap gap(c = 100, d = 0, s_rel0 = 0.5);
  {T}.Components.Mass mass(m = 1, s(start = 1, fixed = true), v(start = -1, fixed = true));
equation
  connect(fixed.flange, gap.flange_a);
  connect(gap.flange_b, mass.flange_a);
end Gap;
"""


def test_elasto_gap_contact() -> None:
    r = simulate(GAP, 1.5)
    t = r.time
    leave = 0.5 + math.pi / 10
    s = np.where(t < 0.5, 1 - t,
                 np.where(t < leave, 0.5 - np.sin(10 * (t - 0.5)) / 10, 0.5 + (t - leave)))
    assert np.max(np.abs(r["mass.s"] - s)) < 1e-7
    assert np.all(r["gap.contact"][t < 0.5 - 1e-6] == 0)


OSCILLATOR = f"""
model Oscillator "Modelica.Mechanics.Translational.Examples.Oscillator, with full names"
  extends Modelica.Icons.Example;
  {T}.Components.Mass mass1(L = 1, s(start = -0.5, fixed = true), v(start = 0, fixed = true),
    m = 1);
  {T}.Components.Spring spring1(s_rel0 = 1, c = 10000);
  {T}.Components.Fixed fixed1(s0 = 1);
  {T}.Sources.Force force1;
  Modelica.Blocks.Sources.Sine sine1(f = 15.9155);
  {T}.Components.Mass mass2(L = 1, s(start = -0.5, fixed = true), v(start = 0, fixed = true),
    m = 1);
  {T}.Components.Spring spring2(s_rel0 = 1, c = 10000);
  {T}.Components.Fixed fixed2(s0 = 1);
  {T}.Sources.Force force2;
  Modelica.Blocks.Sources.Sine sine2(f = 15.9155);
  {T}.Components.Damper damper1(d = 10);
equation
  connect(mass1.flange_b, spring1.flange_a);
  connect(spring2.flange_a, damper1.flange_a);
  connect(mass2.flange_b, spring2.flange_a);
  connect(damper1.flange_b, spring2.flange_b);
  connect(sine1.y, force1.f);
  connect(sine2.y, force2.f);
  connect(spring1.flange_b, fixed1.flange);
  connect(force2.flange, mass2.flange_a);
  connect(force1.flange, mass1.flange_a);
  connect(spring2.flange_b, fixed2.flange);
end Oscillator;
"""


def test_oscillator_example() -> None:
    r = simulate(OSCILLATOR, 1.0, 1000)
    t = r.time
    w0, w = 100.0, 2 * math.pi * 15.9155
    # Undamped: y'' + w0^2 y = sin(w t), y(0) = y'(0) = 0 (y = s + 0.5).
    y1 = (np.sin(w * t) - (w / w0) * np.sin(w0 * t)) / (w0 ** 2 - w ** 2)
    assert np.max(np.abs(r["mass1.s"] - (y1 - 0.5))) < 1e-7
    # Damped: y'' + 10 y' + w0^2 y = sin(w t): steady part A sin + B cos, plus the
    # decaying homogeneous part fitted to y(0) = y'(0) = 0.
    den = (w0 ** 2 - w ** 2) ** 2 + (10 * w) ** 2
    a, b = (w0 ** 2 - w ** 2) / den, -10 * w / den
    wd = math.sqrt(w0 ** 2 - 25)
    c1 = -b
    c2 = (5 * c1 - a * w) / wd
    y2 = a * np.sin(w * t) + b * np.cos(w * t) \
        + np.exp(-5 * t) * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
    assert np.max(np.abs(r["mass2.s"] - (y2 - 0.5))) < 1e-9
