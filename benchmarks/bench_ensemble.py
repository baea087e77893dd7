"""The compiled ensemble engine's throughput: N seed runs, final values only.

The seed over N stiffness values (``spring.k`` log-spaced from 1e3 to 1e5, the spread
of issue 29's diffrax anchor), rtol 1e-6, atol 1e-9, from 0 to the stop time (default
10 s) with one output interval (final values only), measured in the same process:

- ``single``: one compiled DOP853 run (``springc.integrate.dop853``, the same kernel and
  plain-loop sums) per value of a sample of 200, one at a time: seconds per run;
- ``kernel``: ``springc.integrate.ensemble`` on all N runs (parameter matrix built
  beforehand): runs/s, and the ratio to ``cores / single`` (the ideal: every core
  busy with single runs, no overhead), with ``cores`` the numba threads;
- ``end to end``: ``springc.studies.run_ensemble`` (parameter vectors and start
  states in Python per run, the kernel in chunks of 10^4, the Parquet table): runs/s.

The load average is printed before and after (other jobs on a shared machine take
cores, which the ratio does not know about). 10^6 runs are extrapolated from the
measured rate only when ``--runs`` is smaller, and labelled so.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SEED = ROOT / "models" / "SpringMass.mdl"
RTOL, ATOL = 1e-6, 1e-9


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=10_000, help="number of runs (10^4)")
    parser.add_argument("--stop", type=float, default=10.0, help="stop time [s]")
    args = parser.parse_args()
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-bench-"))
    import numba

    import springc
    from springc.integrate import dop853, ensemble
    from springc.studies import EnsembleOptions, parse_parameter, run_ensemble

    print(f"load average before: {os.getloadavg()[0]:.2f}; numba threads: "
          f"{numba.get_num_threads()}; cpus: {os.cpu_count()}")
    model = springc.compile_model([str(SEED)])
    mod = model.module
    ks = np.geomspace(1e3, 1e5, args.runs)
    grid = np.array([0.0, args.stop])
    P = np.array([mod.parameters({"spring.k": float(k)}) for k in ks])
    X0 = np.array([mod.start(p) for p in P])
    Z = np.array([mod.guesses(p) for p in P])
    ensemble(mod.rhs, grid, X0[:2], P[:2], Z[:2], rtol=RTOL, atol=ATOL)  # load the kernel
    sample = np.linspace(0, args.runs - 1, min(200, args.runs)).astype(int)
    dop853(mod.rhs, grid, X0[0], P[0], Z[0].copy(), rtol=RTOL, atol=ATOL,
           scipy_arithmetic=False)
    began = time.perf_counter()
    singles = [dop853(mod.rhs, grid, X0[r], P[r], Z[r].copy(), rtol=RTOL, atol=ATOL,
                      scipy_arithmetic=False) for r in sample]
    single = (time.perf_counter() - began) / len(sample)
    began = time.perf_counter()
    result = ensemble(mod.rhs, grid, X0, P, Z, rtol=RTOL, atol=ATOL)
    kernel = time.perf_counter() - began
    assert result.ok().all()
    worst = max(float(np.max(np.abs(result.finals[r] - s.states[-1])
                             / np.maximum(np.abs(s.states[-1]), 1e-300)))
                for r, s in zip(sample, singles))
    cores = numba.get_num_threads()
    rate = args.runs / kernel
    print(f"single compiled run: {single * 1e3:.3f} ms (mean of {len(sample)})")
    print(f"kernel: {args.runs} runs in {kernel:.2f} s = {rate:,.0f} runs/s; ideal "
          f"{cores} / single = {cores / single:,.0f} runs/s; ratio {rate * single / cores:.2f}")
    print(f"largest relative difference of the final states from the single runs: "
          f"{worst:.1e}")
    with tempfile.TemporaryDirectory() as folder:
        options = EnsembleOptions((parse_parameter(f"spring.k=1e3:1e5:log:{args.runs}"),),
                                  stop=args.stop, interval=args.stop, rtol=RTOL, atol=ATOL,
                                  variables=tuple(model.states))
        began = time.perf_counter()
        summary = run_ensemble(model, options, str(Path(folder) / "e.parquet"))
        total = time.perf_counter() - began
    assert summary.failed == 0
    print(f"end to end (run_ensemble, Parquet): {args.runs} runs in {total:.2f} s = "
          f"{args.runs / total:,.0f} runs/s")
    if args.runs < 1_000_000:
        print(f"extrapolated (not measured) 10^6 runs end to end: "
              f"{1e6 / (args.runs / total):.0f} s at this rate")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
