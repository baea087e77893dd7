"""Masses from 1e-6 to 1e6 on a unit spring: auto (and verlet) against the closed form."""

from __future__ import annotations

import numpy as np
import pytest

import springc
from springc.pipeline.compiler import CompiledModel

from .cases import MASSES, harmonic


@pytest.mark.parametrize("m", MASSES)
def test_auto_within_bound(compiled: dict[str, CompiledModel], m: float) -> None:
    result = springc.simulate(compiled["Harmonic"], parameters={"m": m})
    error = np.max(np.abs(result["x"] - harmonic(result.time, m=m)))
    # 1600 periods for m = 1e-6: the phase error grows with the number of periods.
    assert error < (2e-3 if m < 1 else 5e-6)
    assert result.stats.solver == "dop853"


@pytest.mark.parametrize("m", MASSES)
def test_verlet_within_bound(compiled: dict[str, CompiledModel], m: float) -> None:
    omega = np.sqrt(1 / m)
    period = 2 * np.pi / omega
    stop = min(10.0, 10 * period)
    h = min(period / 200, stop / 500)
    result = springc.simulate(compiled["Harmonic"], parameters={"m": m}, stop=stop,
                              solver="verlet", step=h)
    # Verlet's phase error after time T is about omega^3 h^2 T / 24.
    bound = 2 * omega**3 * h**2 * stop / 24 + 1e-12
    assert np.max(np.abs(result["x"] - harmonic(result.time, m=m))) < bound
