"""The GPU ensemble engine's throughput (``--device gpu``): seed runs, final values only.

Run it on a machine with an NVIDIA GPU and CuPy (``pip install cupy-cuda12x``):
``PYTHONPATH=src python benchmarks/bench_gpu.py`` (under 10 minutes on one H100 or
H200; ``--runs`` to choose the sizes). The seed over N stiffness values (``spring.k``
log-spaced from 1e3 to 1e5, issue 29's diffrax anchor: 58,600 runs/s on one H200 for
10^6 runs), rtol 1e-6, atol 1e-9, from 0 to ``--stop`` (10 s) with one output interval.
Per N, in the same process:

- ``gpu``: one call of the GPU engine on all N runs (the kernel compiled by NVRTC on a
  first, untimed call; the timed call includes the copies to and from the device):
  seconds and runs/s;
- ``cpu``: the C engine on every core (OpenMP) on the first ``--cpu-runs`` of them
  (default: all up to 10^5): seconds, runs/s, and the largest relative difference of
  the GPU's final states from the CPU's (issue 29 asks for 1e-6);
- ``end to end``: :func:`springc.studies.run_ensemble` with ``device="gpu"`` on the
  largest N (parameters, the kernel in chunks of 10^6, the Parquet table): runs/s.
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
    parser.add_argument("--runs", type=int, nargs="+", default=[10**4, 10**5, 10**6])
    parser.add_argument("--cpu-runs", type=int, default=10**5,
                        help="the most runs compared with the CPU engine")
    parser.add_argument("--stop", type=float, default=10.0, help="stop time [s]")
    args = parser.parse_args()
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-bench-"))
    import springc
    from springc.integrate.gpu_ensemble import GpuEnsemble, NoCudaDevice
    from springc.pipeline import c_source
    from springc.studies import EnsembleOptions, parse_parameter, run_ensemble
    from springc.studies.ensemble_engines import Plan, open_engine

    model = springc.compile_model([str(SEED)])
    try:
        device = GpuEnsemble(c_source(model), len(model.states)).device_name()
    except NoCudaDevice as err:
        raise SystemExit(f"bench_gpu: {err}") from None
    print(f"device: {device}; cpus: {os.cpu_count()}; load average "
          f"{os.getloadavg()[0]:.2f}")
    plan = Plan(np.array([0.0, args.stop]), RTOL, ATOL, 0, tuple(range(4)), (), 1)
    engines = {name: open_engine(model, engine, where, ("spring.k",), {}, plan)[1]
               for name, engine, where in (("gpu", None, "gpu"), ("cpu", "c", "cpu"))}
    for run in engines.values():
        run(np.array([[1e3], [1e5]]))  # compiled and loaded before the clock starts
    print("| N | GPU s | GPU runs/s | CPU runs compared | CPU s | CPU runs/s | "
          "largest relative difference |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for n in args.runs:
        values = np.geomspace(1e3, 1e5, n).reshape(-1, 1)
        began = time.perf_counter()
        gpu = engines["gpu"](values)
        gpu_s = time.perf_counter() - began
        assert (gpu.status == 0).all(), np.unique(gpu.status)
        m = min(n, args.cpu_runs)
        began = time.perf_counter()
        cpu = engines["cpu"](values[:m])
        cpu_s = time.perf_counter() - began
        a, b = gpu.summary[:m, :, 0], cpu.summary[:, :, 0]
        worst = float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))
        print(f"| {n:,} | {gpu_s:.2f} | {n / gpu_s:,.0f} | {m:,} | {cpu_s:.2f} | "
              f"{m / cpu_s:,.0f} | {worst:.1e} |")
    n = max(args.runs)
    with tempfile.TemporaryDirectory() as folder:
        options = EnsembleOptions((parse_parameter(f"spring.k=1e3:1e5:log:{n}"),),
                                  stop=args.stop, interval=args.stop, rtol=RTOL, atol=ATOL,
                                  variables=tuple(model.states), device="gpu")
        began = time.perf_counter()
        summary = run_ensemble(model, options, str(Path(folder) / "e.parquet"))
        total = time.perf_counter() - began
    assert summary.failed == 0
    print(f"end to end (run_ensemble, device gpu, Parquet): {n:,} runs in {total:.2f} s "
          f"= {n / total:,.0f} runs/s (issue 29: over 100,000; diffrax 58,600 on an H200)")


if __name__ == "__main__":
    main()
