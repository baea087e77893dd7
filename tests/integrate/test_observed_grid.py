"""``observed_grid``: a model's observed variables at given states on a grid, compiled."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from springc.integrate import observed_grid


def test_rows_are_the_observed_function_at_each_time(odes: SimpleNamespace) -> None:
    w = 2.0
    ts = np.linspace(0.0, 1.0, 7)
    states = np.column_stack([np.cos(w * ts), -w * np.sin(w * ts)])  # q, v
    p, z = np.array([w]), np.zeros(0)
    out = observed_grid(odes.oscillator_energy, ts, states, p, z)
    assert out.shape == (7, 2)
    one_by_one = np.array([odes.oscillator_energy(t, x, p, z) for t, x in zip(ts, states)])
    np.testing.assert_array_equal(out, one_by_one)  # the same compiled function
    np.testing.assert_allclose(out[:, 0], 0.5 * w * w, rtol=1e-15)  # E = w^2 / 2
    np.testing.assert_array_equal(out[:, 1], ts)


def test_rows_from_a_failed_evaluation_on_are_nan(failing: SimpleNamespace) -> None:
    ts = np.linspace(0.0, 1.0, 11)
    z = np.zeros(1)
    out = observed_grid(failing.flags_after_half, ts, np.zeros((11, 1)), np.zeros(0), z)
    assert z[-1] == 7.0  # the model's failure flag stays set for the caller
    np.testing.assert_array_equal(out[:6, 0], 1.0)  # t <= 0.5
    assert np.isnan(out[6:]).all()


def test_an_empty_grid_gives_no_rows(odes: SimpleNamespace) -> None:
    out = observed_grid(odes.oscillator_energy, np.empty(0), np.empty((0, 2)),
                        np.array([2.0]), np.zeros(0))
    assert out.shape == (0, 2)


def test_bad_arguments_are_refused(odes: SimpleNamespace) -> None:
    with pytest.raises(TypeError, match="observed must be a numba-jitted function, got "
                                        "function"):
        observed_grid(lambda t, x, p, z: x, np.zeros(2), np.zeros((2, 2)), np.zeros(1),
                      np.zeros(0))
    with pytest.raises(ValueError, match=r"states must hold a row per time: shapes \(3,\) "
                                         r"and \(2, 2\)"):
        observed_grid(odes.oscillator_energy, np.zeros(3), np.zeros((2, 2)), np.ones(1),
                      np.zeros(0))
