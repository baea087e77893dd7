"""The compiled implicit methods on a 10,000-mass chain against scipy's BDF (same run).

A chain of N masses (20,000 states for N = 10,000): springs k = 1e4 between neighbours
and to a wall, dampers c = 1, unit masses, started with a linear velocity profile; its
right-hand side and the non-zeros of its Jacobian (CSC, 5N - 2 of them) written in numba
as the generated modules write them. Compared, warm and in one process, 0..T s at rtol
1e-6 (atol rtol/1000):

- springc.integrate.radau and .bdf (banded LU after a reverse Cuthill-McKee ordering);
- ``scipy.integrate.solve_ivp(method="BDF")`` and ``"Radau"`` with the same Jacobian as a
  ``scipy.sparse.csc_matrix`` (SuperLU), the same right-hand side;
- the error of each against a compiled DOP853 run at rtol 1e-11.

Run: ``PYTHONPATH=src python benchmarks/bench_implicit.py [--masses N] [--stop T]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.integrate
import scipy.sparse as sp
from numba import njit

NO_Z = np.zeros(0)
P = np.array([1e4, 1.0, 1.0])  # k, c, m


@njit(cache=True, error_model="numpy")
def chain(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    n = x.size // 2
    d = np.empty(x.size)
    for i in range(n):
        s, v = x[2 * i], x[2 * i + 1]
        left = x[2 * i - 2] if i > 0 else 0.0
        force = -p[0] * (s - left) - p[1] * v
        if i + 1 < n:
            force += p[0] * (x[2 * i + 2] - s)
        d[2 * i] = v
        d[2 * i + 1] = force / p[2]
    return d


@njit(cache=True, error_model="numpy")
def chain_jacobian(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    n = x.size // 2
    out = np.empty(5 * n - 2)
    k = 0
    for i in range(n):
        if i > 0:
            out[k] = p[0] / p[2]
            k += 1
        out[k] = -(2.0 if i + 1 < n else 1.0) * p[0] / p[2]
        k += 1
        if i + 1 < n:
            out[k] = p[0] / p[2]
            k += 1
        out[k] = 1.0
        out[k + 1] = -p[1] / p[2]
        k += 2
    return out


def pattern(n: int) -> tuple[np.ndarray, np.ndarray]:
    indices: list[int] = []
    indptr = [0]
    for i in range(n):
        indices += ([2 * i - 1] if i > 0 else []) + [2 * i + 1] + \
            ([2 * i + 3] if i + 1 < n else [])
        indptr.append(len(indices))
        indices += [2 * i, 2 * i + 1]
        indptr.append(len(indices))
    return np.array(indptr), np.array(indices)


def main() -> None:
    from springc.integrate import bdf, dop853, radau

    parser = argparse.ArgumentParser()
    parser.add_argument("--masses", type=int, default=10_000)
    parser.add_argument("--stop", type=float, default=1.0)
    args = parser.parse_args()
    n, stop, rtol = args.masses, args.stop, 1e-6
    indptr, indices = pattern(n)
    x0 = np.zeros(2 * n)
    x0[1::2] = np.linspace(1.0, 0.0, n)
    grid = np.linspace(0.0, stop, 101)
    shape = (2 * n, 2 * n)

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        return chain(t, x, P, NO_Z)

    def jac(t: float, x: np.ndarray) -> sp.csc_matrix:
        return sp.csc_matrix((chain_jacobian(t, x, P, NO_Z), indices, indptr), shape=shape)

    rhs(0.0, x0), jac(0.0, x0)  # compile the model functions before timing
    radau(chain, chain_jacobian, indptr, indices, grid[:2], x0, P, NO_Z, rtol=rtol,
          atol=rtol * 1e-3)
    reference = dop853(chain, grid, x0, P, NO_Z, rtol=1e-11, atol=1e-14,
                       scipy_arithmetic=False).states
    rows = []
    for name, run in (
            ("springc radau (compiled, banded LU)",
             lambda: radau(chain, chain_jacobian, indptr, indices, grid, x0, P, NO_Z,
                           rtol=rtol, atol=rtol * 1e-3).states),
            ("springc bdf (compiled, banded LU)",
             lambda: bdf(chain, chain_jacobian, indptr, indices, grid, x0, P, NO_Z,
                         rtol=rtol, atol=rtol * 1e-3).states),
            ("scipy BDF, sparse Jacobian (SuperLU)",
             lambda: scipy.integrate.solve_ivp(rhs, (0.0, stop), x0, method="BDF",
                                               rtol=rtol, atol=rtol * 1e-3, jac=jac,
                                               t_eval=grid).y.T),
            ("scipy Radau, sparse Jacobian (SuperLU)",
             lambda: scipy.integrate.solve_ivp(rhs, (0.0, stop), x0, method="Radau",
                                               rtol=rtol, atol=rtol * 1e-3, jac=jac,
                                               t_eval=grid).y.T)):
        began = time.perf_counter()
        states = run()
        seconds = time.perf_counter() - began
        error = float(np.abs(states - reference).max() / np.abs(reference).max())
        rows.append((name, seconds, error))
        print(f"{name:40s} {seconds:8.3f} s   max error {error:.1e}", flush=True)
    base = rows[2][1]
    print(f"\n{2 * n} states, 0..{stop:g} s, rtol {rtol:g}: radau {base / rows[0][1]:.1f}x "
          f"and bdf {base / rows[1][1]:.1f}x faster than scipy's BDF (same run)")


if __name__ == "__main__":
    main()
