"""An independent reference for the hybrid tests: the wall-contact model integrated by
scipy alone, one smooth piece at a time."""

from __future__ import annotations

import numpy as np


def wall_reference(stop: float) -> tuple[np.ndarray, np.ndarray, int]:
    """The Wall model by scipy alone: free flight and contact integrated separately,
    stopping at each crossing of x = xw (solve_ivp's terminal events)."""
    import scipy.integrate

    m, k, kw, dw, xw = 1.0, 100.0, 1e4, 10.0, 0.05

    def free(t: float, y: np.ndarray) -> list[float]:
        return [y[1], -k * y[0] / m]

    def contact(t: float, y: np.ndarray) -> list[float]:
        return [y[1], (-k * y[0] - kw * (y[0] - xw) - dw * y[1]) / m]

    def enter(t: float, y: np.ndarray) -> float:
        return y[0] - xw

    def leave(t: float, y: np.ndarray) -> float:
        return y[0] - xw

    enter.terminal = leave.terminal = True  # type: ignore[attr-defined]
    enter.direction, leave.direction = 1.0, -1.0  # type: ignore[attr-defined]
    t, y, touching, crossings = 0.0, np.array([0.0, 2.0]), False, 0
    pieces = []
    while t < stop:
        sol = scipy.integrate.solve_ivp(contact if touching else free, (t, stop), y,
                                        method="DOP853", rtol=1e-12, atol=1e-14,
                                        events=leave if touching else enter,
                                        dense_output=True)
        pieces.append((t, sol.t[-1], sol.sol))
        t, y = float(sol.t[-1]), sol.y[:, -1]
        if sol.status == 1:
            touching = not touching
            crossings += 1
    grid = np.linspace(0.0, stop, 401)
    out = np.empty((len(grid), 2))
    for i, s in enumerate(grid):
        for a, b, sol in pieces:
            if a <= s <= b:
                out[i] = sol(s)
                break
    return grid, out, crossings
