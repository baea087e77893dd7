"""``springc sweep`` throughput: the seed over N stiffness values on 1 and 2 local
worker processes (N = 1,000; ``--quick``: 100), measured in the same run.

For each worker count the table gives the wall time of the whole study (process start,
cache hits in the workers, the runs, the tables), runs per second, and the throughput
relative to one worker, and the cores the workers obtained (their CPU seconds over the
wall time: on a shared machine, below the worker count when other jobs take cores).
Each count runs every value once, in two halves, in the order 1, 2, 2, 1 workers (a
load that drifts during the benchmark biases neither). The target is at least 1.7x on
two cores. Every run must be ok, and the final states of the two
counts identical.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SEED = ROOT / "models" / "SpringMass.mdl"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="100 runs instead of 1,000")
    parser.add_argument("--runs", type=int, help="number of stiffness values")
    args = parser.parse_args()
    runs = args.runs or (100 if args.quick else 1000)
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-bench-"))
    import springc
    from springc.studies import StudyOptions, parse_parameter, run_study

    load = os.getloadavg()[0]
    model = springc.compile_model([str(SEED)])
    stiffness = np.geomspace(1e3, 1e5, runs)
    halves = (",".join(map(repr, stiffness[0::2].tolist())),
              ",".join(map(repr, stiffness[1::2].tolist())))
    seconds = {1: 0.0, 2: 0.0}
    cpu = {1: 0.0, 2: 0.0}
    finals: dict[int, dict[float, float]] = {1: {}, 2: {}}
    # ABBA: each worker count runs every value once, in two halves, in the order
    # 1, 2, 2, 1 workers, so that a load that drifts during the run biases neither.
    for workers, half in ((1, 0), (2, 1), (2, 0), (1, 1)):
        spec = parse_parameter(f"spring.k={halves[half]}")
        began, before = time.perf_counter(), os.times()
        study = run_study(model, StudyOptions((spec,), workers=workers))
        seconds[workers] += time.perf_counter() - began
        cpu[workers] += os.times().children_user - before.children_user
        if study.failed:
            sys.exit(f"{study.failed} runs failed")
        finals[workers].update(zip(study.summary.column("spring.k").to_pylist(),
                                   study.summary.column("mass.pos[1].final").to_pylist()))
    rows = [(w, seconds[w], runs / seconds[w], cpu[w] / seconds[w]) for w in (1, 2)]
    same = finals[1] == finals[2] and len(finals[1]) == runs
    print(f"seed, {runs} stiffness values 1e3..1e5 (log), {os.cpu_count()} cores, load "
          f"average {load:.1f} at the start, {os.getloadavg()[0]:.1f} at the end")
    print("| workers | wall s | runs/s | vs 1 worker | cores the workers got |\n"
          "| ---: | ---: | ---: | ---: | ---: |")
    for workers, wall, rate, cores in rows:
        print(f"| {workers} | {wall:.1f} | {rate:.2f} | {rate / rows[0][2]:.2f}x | "
              f"{cores:.2f} |")
    print(f"final states identical on 1 and 2 workers: {same}")


if __name__ == "__main__":
    main()
