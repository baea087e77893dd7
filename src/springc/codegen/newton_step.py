"""The Newton correction of a torn nonlinear block in generated Python and numba code.

``J d = r`` is solved by numpy; where ``J`` is singular but the equations are
consistent (two stuck friction elements in series: a gear and its bearing friction
both locked carry a torque only their sum determines, and the torn system has a
zero row), the correction is the basic solution of Gaussian elimination with
complete pivoting whose free unknowns become 0 (their new values ``t - d`` are 0),
as a linear solver's particular solution sets them: the whole torque goes to the
elements whose unknowns the pivots chose, the others carry none. An inconsistent
singular system gives NaN, which the run reports as a failure at that time.
"""

from __future__ import annotations

SINGULAR_PIVOT = 1e-13
"""A pivot below this times the largest entry of ``J`` counts as zero."""

INCONSISTENT = 1e-9
"""A residual left after elimination above this times ``1 + max |r|``: inconsistent."""

NEWTON_SOLVE = f'''def _newton_solve(a, r, t):
    try:
        return np.linalg.solve(a, r)
    except Exception:
        pass
    n = r.shape[0]
    a = a.copy()
    b = r.copy()
    cols = np.arange(n)
    scale = np.max(np.abs(a)) if n > 0 else 0.0
    rank = 0
    for k in range(n):
        bi, bj, bv = k, k, -1.0
        for i in range(k, n):
            for j in range(k, n):
                if abs(a[i, j]) > bv:
                    bi, bj, bv = i, j, abs(a[i, j])
        if bv <= {SINGULAR_PIVOT!r} * scale:
            break
        for j in range(n):
            a[k, j], a[bi, j] = a[bi, j], a[k, j]
        b[k], b[bi] = b[bi], b[k]
        for i in range(n):
            a[i, k], a[i, bj] = a[i, bj], a[i, k]
        cols[k], cols[bj] = cols[bj], cols[k]
        for i in range(k + 1, n):
            f = a[i, k] / a[k, k]
            for j in range(k, n):
                a[i, j] -= f * a[k, j]
            b[i] -= f * b[k]
        rank += 1
    big = 1.0 + np.max(np.abs(r))
    y = np.zeros(n)
    for k in range(rank, n):
        if abs(b[k]) > {INCONSISTENT!r} * big:
            return np.full(n, np.nan)
        y[k] = t[cols[k]]
    for k in range(rank - 1, -1, -1):
        s = b[k]
        for j in range(k + 1, n):
            s -= a[k, j] * y[j]
        y[k] = s / a[k, k]
    d = np.empty(n)
    for k in range(n):
        d[cols[k]] = y[k]
    return d
'''
"""The helper generated modules define when a block calls it (module docstring)."""


def newton_solve(result: str, matrix: str, rhs: str, values: str, size: int) -> str:
    """``result = _newton_solve(matrix, rhs, values)`` (``values``: the tearing
    variables now), or NaN where an entry of ``matrix`` or ``rhs`` is not finite."""
    return (f"{result} = _newton_solve({matrix}, {rhs}, {values}) if "
            f"np.isfinite({matrix}).all() and np.isfinite({rhs}).all() else "
            f"np.full({size}, np.nan)")
