"""``springc sweep`` throughput: the seed over N stiffness values on 1 and 2 local
worker processes (N = 1,000; ``--quick``: 100), measured in the same run.

For each worker count the table gives the wall time of the whole study (process start,
cache hits in the workers, the runs, the Parquet shards and tables), runs per second,
and the throughput relative to one worker. The target is at least 1.7x on two cores.
Each study is checked: every run ok, and the two studies' final states identical.
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

    model = springc.compile_model([str(SEED)])
    spec = parse_parameter(f"spring.k=1e3:1e5:log:{runs}")
    rows, finals = [], []
    for workers in (1, 2):
        began = time.perf_counter()
        study = run_study(model, StudyOptions((spec,), workers=workers))
        seconds = time.perf_counter() - began
        if study.failed:
            sys.exit(f"{study.failed} runs failed")
        finals.append(np.asarray(study.summary.column("mass.pos[1].final")))
        rows.append((workers, seconds, runs / seconds))
    same = np.array_equal(finals[0], finals[1])
    print(f"seed, {runs} stiffness values 1e3..1e5 (log), {os.cpu_count()} cores, load "
          f"average {os.getloadavg()[0]:.1f}")
    print("| workers | wall s | runs/s | vs 1 worker |\n| ---: | ---: | ---: | ---: |")
    for workers, seconds, rate in rows:
        print(f"| {workers} | {seconds:.1f} | {rate:.2f} | {rate / rows[0][2]:.2f}x |")
    print(f"final states identical on 1 and 2 workers: {same}")


if __name__ == "__main__":
    main()
