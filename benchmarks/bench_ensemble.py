"""The ensemble engines' throughput: N seed runs, final values only.

The seed over N stiffness values (``spring.k`` log-spaced from 1e3 to 1e5, the spread
of issue 29's diffrax anchor), rtol 1e-6, atol 1e-9, from 0 to the stop time (default
10 s) with one output interval (final values only), measured in the same process:

- ``single``: one compiled DOP853 run (``springc.integrate.dop853``, numba, plain-loop
  sums) per value of a sample of 200, one at a time: seconds per run;
- per engine (``c``: the batched C kernel, OpenMP; ``numba``: the numba ensemble
  kernel, parameters prepared in Python per run) and per N: one chunk of all N runs
  through the engine (:func:`springc.studies.ensemble_engines.open_engine`): wall
  seconds, CPU seconds of the process (every thread), runs/s, CPU ms per run, and the
  ratio of runs/s to ``cores / single`` (issue 29's target: at least 0.70);
- the largest relative difference of the C engine's final states from numba's;
- ``end to end``: :func:`springc.studies.run_ensemble` with the default engine on the
  largest N (chunks, the Parquet table): runs/s.

The load average is printed before and after (other jobs on a shared machine take
cores: compare the CPU seconds, which move far less with the load). 10^6 runs are
projected from the CPU seconds per run only when not measured, and labelled so.

``--ball N``: a hybrid model instead, ``EventScenes.BouncingBall`` (e = 0.8) over N
values of ``g`` from 9 to 10.5 (8 to 10 bounces by 3.5 s; the bounces accumulate
after 3.9 s at g = 10.5), 0..3.5 s, rtol 1e-8, atol 1e-10, final values of
h, v and bounces: ``run_ensemble`` (C engine, events in the kernel) against ``springc
sweep`` of the same runs (dop853, the same tolerances, error control off, local
processes), CPU seconds of this process and its worker processes (``RUSAGE_CHILDREN``),
and the largest difference of their final states. ``--sweep-runs M`` runs the sweep
on the first M of the N values only (its CPU seconds per run are then scaled to N,
and labelled so).
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SEED = ROOT / "models" / "SpringMass.mdl"
EVENTS = ROOT / "models" / "EventScenes.mdl"
RTOL, ATOL = 1e-6, 1e-9


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, nargs="+", default=[10_000],
                        help="numbers of runs (default 10^4)")
    parser.add_argument("--engines", default="c,numba", help="engines (c,numba)")
    parser.add_argument("--stop", type=float, default=10.0, help="stop time [s]")
    parser.add_argument("--ball", type=int, default=0, metavar="N",
                        help="N bouncing-ball runs: the C engine against sweep")
    parser.add_argument("--sweep-runs", type=int, default=None, metavar="M",
                        help="with --ball: sweep the first M runs only")
    args = parser.parse_args()
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-bench-"))
    if args.ball:
        ball(args.ball, args.sweep_runs or args.ball)
        return
    import springc
    from springc.integrate import dop853
    from springc.studies import EnsembleOptions, parse_parameter, run_ensemble
    from springc.studies.ensemble_engines import Plan, open_engine

    cores = os.cpu_count() or 1
    print(f"load average before: {os.getloadavg()[0]:.2f}; cpus: {cores}")
    model = springc.compile_model([str(SEED)])
    mod = model.module
    grid = np.array([0.0, args.stop])
    plan = Plan(grid, RTOL, ATOL, 0, tuple(range(4)), (), 1)
    sample = np.geomspace(1e3, 1e5, 200)
    P = [mod.parameters({"spring.k": float(k)}) for k in sample]
    dop853(mod.rhs, grid, mod.start(P[0]), P[0], mod.guesses(P[0]), rtol=RTOL, atol=ATOL,
           scipy_arithmetic=False)
    began = time.perf_counter()
    for p in P:
        dop853(mod.rhs, grid, mod.start(p), p, mod.guesses(p), rtol=RTOL, atol=ATOL,
               scipy_arithmetic=False)
    single = (time.perf_counter() - began) / len(P)
    print(f"single compiled run (numba): {single * 1e3:.3f} ms (mean of {len(P)}); "
          f"ideal {cores} / single = {cores / single:,.0f} runs/s")
    print("| engine | runs | wall s | CPU s | runs/s | CPU ms/run | ratio to cores/single |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    finals: dict[tuple[str, int], np.ndarray] = {}
    for n in args.runs:
        values = np.geomspace(1e3, 1e5, n).reshape(-1, 1)
        for engine in args.engines.split(","):
            name, run = open_engine(model, engine, "cpu", ("spring.k",), {}, plan)
            run(values[:2])  # loaded (and compiled) before the clock starts
            wall, cpu = time.perf_counter(), time.process_time()
            result = run(values)
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            assert (result.status == 0).all()
            finals[name, n] = result.summary[:, :, 0]
            print(f"| {name} | {n:,} | {wall:.2f} | {cpu:.2f} | {n / wall:,.0f} | "
                  f"{cpu / n * 1e3:.3f} | {n / wall * single / cores:.2f} |")
        if ("c", n) in finals and ("numba", n) in finals:
            c, nb = finals["c", n], finals["numba", n]
            worst = float(np.max(np.abs(c - nb) / np.maximum(np.abs(nb), 1e-300)))
            print(f"N = {n:,}: largest relative difference of the C engine's final states "
                  f"from numba's: {worst:.1e}")
    n = max(args.runs)
    with tempfile.TemporaryDirectory() as folder:
        options = EnsembleOptions((parse_parameter(f"spring.k=1e3:1e5:log:{n}"),),
                                  stop=args.stop, interval=args.stop, rtol=RTOL, atol=ATOL,
                                  variables=tuple(model.states))
        wall, cpu = time.perf_counter(), time.process_time()
        summary = run_ensemble(model, options, str(Path(folder) / "e.parquet"))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    assert summary.failed == 0
    print(f"end to end ({summary.engine} engine, run_ensemble, Parquet): {n:,} runs in "
          f"{wall:.2f} s wall, {cpu:.2f} s CPU = {n / wall:,.0f} runs/s")
    if n < 1_000_000:
        print(f"projected (not measured) 10^6 runs end to end on {cores} idle cores: "
              f"{1e6 * cpu / n / cores:.0f} s (CPU seconds per run x 10^6 / cores)")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def cpu_seconds() -> float:
    """User + system CPU seconds of this process and of its waited-for children."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + children.ru_utime + children.ru_stime


def ball(n: int, m: int) -> None:
    """N bouncing-ball runs: the C engine (events in the kernel) against sweep."""
    import pyarrow.parquet as pq

    import springc
    from springc.studies import EnsembleOptions, parse_parameter, run_ensemble

    print(f"load average before: {os.getloadavg()[0]:.2f}; cpus: {os.cpu_count()}")
    model = springc.compile_model([str(EVENTS)], "EventScenes.BouncingBall")
    values = np.linspace(9.0, 10.5, n)
    settings = {"stop": 3.5, "interval": 3.5, "rtol": 1e-8, "atol": 1e-10}
    with tempfile.TemporaryDirectory() as folder:
        path = str(Path(folder) / "e.parquet")
        run_ensemble(model, EnsembleOptions((parse_parameter("g=9,10"),), **settings),
                     path)  # the kernel built before the clock starts
        options = EnsembleOptions((parse_parameter(f"g=9:10.5:{n}"),),
                                  variables=("h", "v", "bounces"), **settings)
        wall, cpu = time.perf_counter(), cpu_seconds()
        summary = run_ensemble(model, options, path)
        wall, cpu = time.perf_counter() - wall, cpu_seconds() - cpu
        table = pq.read_table(path).to_pydict()
    assert summary.failed == 0, summary
    print(f"| C engine (run_ensemble) | {n:,} | {wall:.2f} | {cpu:.2f} | "
          f"{cpu / n * 1e3:.3f} |")
    measured = []
    for count in sorted({max(1, m // 5), m}):
        wall, cpu = time.perf_counter(), cpu_seconds()
        study = springc.sweep(model, params={"g": values[:count].tolist()}, solver="dop853",
                              error_control="off", as_="dataframe", **settings)
        wall, cpu = time.perf_counter() - wall, cpu_seconds() - cpu
        assert (study.groupby("run")["status"].first() == "ok").all()
        measured.append((count, cpu))
        print(f"| sweep (local processes) | {count:,} | {wall:.2f} | {cpu:.2f} | "
              f"{cpu / count * 1e3:.3f} |")
    if m < n and len(measured) == 2:  # the workers' start is a fixed cost: the slope
        (a, ca), (b, cb) = measured
        marginal = (cb - ca) / (b - a)
        print(f"sweep projected (not measured) to {n:,} runs: {cb + marginal * (n - b):.1f} "
              f"CPU s ({marginal * 1e3:.2f} CPU ms per further run)")
    last = study.groupby("run").last()
    worst = 0.0
    for name in ("h", "v", "bounces"):
        got = np.array(table[f"{name}.final"][:m])
        worst = max(worst, float(np.max(np.abs(got - last[name].to_numpy()))))
    print(f"largest difference of the final h, v, bounces (C engine vs sweep): {worst:.1e}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
