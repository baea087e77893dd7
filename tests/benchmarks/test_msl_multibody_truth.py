"""The independent rolling-wheel model of benchmarks/msl_multibody_truth.py (the truth that
settled MultiBody.Examples.Elementary.RollingWheel as the reference's error, docs/msl.md,
branch mbody) against closed forms: an upright wheel rolls straight at constant spin,
x = r w t cos(psi), y = r w t sin(psi); the angular velocity is the one of the rotation
matrix (skew(w_a) = -dT/dt T'); a wheel rolling without slip keeps its energy."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "msl_multibody_truth.py"
_SPEC = importlib.util.spec_from_file_location("msl_multibody_truth", _PATH)
assert _SPEC is not None and _SPEC.loader is not None
truth = importlib.util.module_from_spec(_SPEC)
sys.modules["msl_multibody_truth"] = truth
_SPEC.loader.exec_module(truth)


def test_an_upright_wheel_rolls_straight_at_constant_spin() -> None:
    psi, spin = 0.3, 4.0
    s0 = np.array([psi, 0, 0, 0, spin, 0, 0.1, -0.2])
    sol = solve_ivp(truth.wheel_rhs, (0, 1), s0, method="DOP853", rtol=1e-12, atol=1e-14)
    end = sol.y[:, -1]
    road = truth.WHEEL_RADIUS * spin
    assert np.allclose(end[[0, 2, 3, 4, 5]], [psi, 0, 0, spin, 0], atol=1e-10)
    assert abs(end[1] - spin) < 1e-10
    assert abs(end[6] - (0.1 + road * np.cos(psi))) < 1e-10
    assert abs(end[7] - (-0.2 + road * np.sin(psi))) < 1e-10


def test_the_angular_velocity_is_the_rotation_matrix_s() -> None:
    angles, rates = np.array([0.4, -1.1, 0.7]), np.array([2.0, -3.0, 0.5])
    tdot = np.imag(truth.wheel_t(angles + 1e-20j * rates)) / 1e-20
    spin = -tdot @ truth.wheel_t(angles).T
    w_a = truth.wheel_jac(angles) @ rates
    assert np.allclose([spin[2, 1], spin[0, 2], spin[1, 0]], w_a, atol=1e-12)
    assert np.allclose(spin, -spin.T, atol=1e-12)


def test_the_example_s_wheel_keeps_its_energy() -> None:
    s0 = np.array([0, 0, 0, 0, 5, 1, 0.2, 0.2], float)
    sol = solve_ivp(truth.wheel_rhs, (0, 0.5), s0, method="DOP853", rtol=1e-11, atol=1e-13,
                    t_eval=np.linspace(0, 0.5, 11))
    energy = truth.wheel_energy(sol.y[:3], sol.y[3:6])
    # m g r + m |r w|^2 / 2 + (I_axis 5^2 + I_long 1^2) / 2 = 9.03399 J at the start
    assert abs(energy[0] - (2 * 9.80665 * 0.3 + 0.5 * 2 * (1.5**2 + 0.3**2)
                            + 0.5 * (0.06 * 25 + 0.12))) < 1e-12
    assert np.abs(energy - energy[0]).max() < 1e-8
    height = -truth.wheel_delta(sol.y[:3, -1])[2]  # leaned: 1.35 J of height became motion
    assert 0.2 < height < 0.25
