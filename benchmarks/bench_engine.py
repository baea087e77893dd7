"""The compiled integration loops (springc.integrate) against scipy on the seed ODE.

The seed (models/SpringMass.mdl: a 1 kg mass on a 2-D spring, k = 1e4, rest length 1,
under gravity, from (1, -1) at rest) written by hand as a numba model function,
0..10 s, rtol 1e-6, atol 1e-9, 500 output intervals:

- warm, in process: springc.integrate.dop853 (scipy arithmetic and plain loops) against
  ``solve_ivp(method="DOP853")`` driving the same numba right-hand side, ratio printed;
  with ``--fused``, also the same DOP853 loop specialised on this right-hand side (what
  a hand-written fused loop compiles to), to show the cost of the function pointer;
- fixed-step: verlet and rk4 at h = 1e-4 against springc.simulation's Python integrators;
- first call in a fresh process: with numba's cache empty (the kernels compile) and
  warm (the kernels load), and the compile of the model function alone (per model).

Run: ``PYTHONPATH=src python benchmarks/bench_engine.py [--quick] [--fused]``.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numba import njit

SEED_P = np.array([1e4, 1.0, 1.0, 9.81])  # k, rest length, mass, g
SEED_X0 = np.array([1.0, -1.0, 0.0, 0.0])
STOP, INTERVALS, RTOL, ATOL = 10.0, 500, 1e-6, 1e-9
NO_Z = np.zeros(0)


@njit(cache=True, error_model="numpy")
def seed_rhs(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """der(pos) = v, der(v) = -k dir (|dir| - l) / |dir| / m + g, dir = pos."""
    r = math.sqrt(x[0] * x[0] + x[1] * x[1])
    pull = -p[0] * (r - p[1]) / r / p[2]
    d = np.empty(4)
    d[0] = x[2]
    d[1] = x[3]
    d[2] = pull * x[0]
    d[3] = pull * x[1] - p[3]
    return d


def best_of(repeats: int, run: Callable[[], object]) -> float:
    """The smallest wall time of ``repeats`` calls (after one warm-up call)."""
    run()
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        run()
        times.append(time.perf_counter() - began)
    return min(times)


def warm(repeats: int, fused: bool) -> None:
    import scipy.integrate

    from springc.integrate import dop853

    grid = np.linspace(0.0, STOP, INTERVALS + 1)
    exact = dop853(seed_rhs, grid, SEED_X0, SEED_P, NO_Z, rtol=RTOL, atol=ATOL)
    rows: list[tuple[str, float, int, int]] = []
    for name, arithmetic in (("springc.integrate dop853 (scipy arithmetic)", True),
                             ("springc.integrate dop853 (plain loops)", False)):
        seconds = best_of(repeats, lambda a=arithmetic: dop853(   # type: ignore[misc]
            seed_rhs, grid, SEED_X0, SEED_P, NO_Z, rtol=RTOL, atol=ATOL,
            scipy_arithmetic=a))
        rows.append((name, seconds, exact.accepted_steps, exact.rhs_evaluations))
    if fused:
        from numba import njit as jit

        from springc.integrate import dop853_steps
        from springc.integrate.loop import specialize  # the shared loop, on DOP853's hooks

        fused_run = specialize("dop853_fused", dop853_steps, False)
        observed = jit(lambda t, x, p, z: np.empty(0))
        atol = np.full(4, ATOL)
        none = np.empty(0, dtype=np.int64)

        def call() -> object:
            return fused_run(seed_rhs, observed, observed, 0, observed, np.empty(0),
                             np.empty(0), grid, SEED_X0.copy(), SEED_P, NO_Z, RTOL, atol,
                             np.inf, 0.0, 0, np.inf, (none, 0, 0, none, none))

        began = time.perf_counter()
        call()
        print(f"fused (specialised) DOP853: compiled in {time.perf_counter() - began:.1f} s "
              f"(in every process: numba cannot reuse its cache for a dispatcher argument)")
        rows.append(("same loop fused on this rhs (plain loops)", best_of(repeats, call),
                     exact.accepted_steps, exact.rhs_evaluations))

    def scipy_run() -> object:
        return scipy.integrate.solve_ivp(lambda t, x: seed_rhs(t, x, SEED_P, NO_Z),
                                         (0.0, STOP), SEED_X0, method="DOP853", rtol=RTOL,
                                         atol=ATOL, t_eval=grid)

    ref = scipy_run()
    np.testing.assert_array_equal(exact.states, ref.y.T)  # bit for bit
    steps = scipy.integrate.solve_ivp(lambda t, x: seed_rhs(t, x, SEED_P, NO_Z), (0.0, STOP),
                                      SEED_X0, method="DOP853", rtol=RTOL, atol=ATOL).t.size - 1
    scipy_seconds = best_of(max(1, repeats // 10), scipy_run)
    rows.append(("scipy solve_ivp DOP853, numba rhs", scipy_seconds, steps, ref.nfev))
    print(f"\nSeed ODE, 0..{STOP:g} s, rtol {RTOL:g}, atol {ATOL:g}, {INTERVALS} output "
          f"intervals, warm, best of {repeats}")
    print(f"{'loop':48s} {'ms':>8s} {'vs scipy':>9s} {'steps':>6s} {'rhs calls':>9s}")
    for name, seconds, steps, nfev in rows:
        print(f"{name:48s} {seconds * 1e3:8.2f} {scipy_seconds / seconds:8.0f}x {steps:6d} "
              f"{nfev:9d}")


def fixed(repeats: int) -> None:
    from springc.integrate import fixed_step
    from springc.simulation.integrators import Pairs, integrate

    grid = np.linspace(0.0, STOP, INTERVALS + 1)
    pairs = [(0, 2), (1, 3)]
    print(f"\nFixed step h = 1e-4 on the seed (100,000 steps), best of {repeats}")
    print(f"{'method':18s} {'compiled ms':>12s} {'python ms':>10s} {'ratio':>7s}")
    for method in ("verlet", "rk4"):
        compiled = best_of(repeats, lambda m=method: fixed_step(  # type: ignore[misc]
            m, seed_rhs, grid, SEED_X0, SEED_P, NO_Z, step=1e-4, pairs=pairs))
        python = best_of(1, lambda m=method: integrate(  # type: ignore[misc]
            m, lambda t, x: seed_rhs(t, x, SEED_P, NO_Z), grid, SEED_X0, 1e-4,
            Pairs.of(pairs)))
        print(f"{method:18s} {compiled * 1e3:12.1f} {python * 1e3:10.0f} "
              f"{python / compiled:6.0f}x")


FIRST_CALL = """
import time
began = time.perf_counter()
import numpy as np
from springc.integrate import dop853
import bench_engine as b
imported = time.perf_counter()
grid = np.linspace(0.0, b.STOP, b.INTERVALS + 1)
dop853(b.seed_rhs, grid, b.SEED_X0, b.SEED_P, b.NO_Z, rtol=b.RTOL, atol=b.ATOL)
done = time.perf_counter()
print(imported - began, done - imported)
"""

MODEL_ONLY = """
import time, math
import numpy as np
from numba import njit
from springc.integrate import dop853
from springc.integrate.signatures import MODEL_FUNCTION_SIGNATURE
import bench_engine as b
grid = np.linspace(0.0, b.STOP, b.INTERVALS + 1)
dop853(b.seed_rhs, grid, b.SEED_X0, b.SEED_P, b.NO_Z, rtol=b.RTOL, atol=b.ATOL)
fresh = njit(error_model="numpy")(b.seed_rhs.py_func)  # a new model: not in any cache
began = time.perf_counter()
dop853(fresh, grid, b.SEED_X0, b.SEED_P, b.NO_Z, rtol=b.RTOL, atol=b.ATOL)
print(time.perf_counter() - began)
"""


def first_calls() -> None:
    here = Path(__file__).resolve().parent
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(here.parent / "src"), str(here), os.environ.get("PYTHONPATH", "")]))
    print("\nFirst call in a fresh process (import + first dop853 run on the seed)")
    with tempfile.TemporaryDirectory(prefix="springc-numba-cache-") as cache:
        env["NUMBA_CACHE_DIR"] = cache
        for label in ("numba cache empty (kernels compile)",
                      "numba cache warm (kernels load)"):
            out = subprocess.run([sys.executable, "-c", FIRST_CALL], env=env, check=True,
                                 capture_output=True, text=True).stdout.split()
            imported, first = float(out[0]), float(out[1])
            print(f"  {label:40s} import {imported:6.2f} s, first run {first:6.2f} s")
        out = subprocess.run([sys.executable, "-c", MODEL_ONLY], env=env, check=True,
                             capture_output=True, text=True).stdout.split()
        print(f"  {'a new model (its rhs compiles)':40s} first run {float(out[0]):6.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, no first calls")
    parser.add_argument("--fused", action="store_true",
                        help="also the loop specialised on the rhs (compiles ~15 s)")
    args = parser.parse_args()
    repeats = 5 if args.quick else 30
    warm(repeats, args.fused)
    fixed(max(1, repeats // 10))
    if not args.quick:
        first_calls()


if __name__ == "__main__":
    main()
