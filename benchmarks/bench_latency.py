"""What a user waits for a warm result: the seed end to end through the CLI, against rumoca.

Each contender is a fresh process that writes the seed's trajectory (0..10 s, rtol
1e-6, atol 1e-9, 1,001 points) to a CSV file:

- ``springc``: ``python -m springc simulate models/SpringMass.mdl -o seed.csv`` with the
  model already in its cache (a first, untimed run fills the cache and numba's);
- ``baseline`` (``--baseline SRC``): the same command on another springc source tree
  (``/work/main/src``, say), with a cache of its own, for a before/after in one run;
- ``rumoca`` (``--rumoca PYTHON``: an interpreter where ``pip install rumoca`` went, by
  default this one or ``/work/venv-rumoca/bin/python``): ``Session().load`` +
  ``simulate`` + the CSV written with the csv module;
- the floors: ``python -c pass`` and ``python -c "import numpy"``.

The runs alternate (each round in a rotated order) and the table gives the median wall
and CPU seconds of each, and each median as a ratio to rumoca's (or, without rumoca,
to the numpy import floor), all measured in the same run. The load average before and
after is printed: on a shared machine the wall times move with it, the CPU times less.

    PYTHONPATH=src python benchmarks/bench_latency.py [--runs 7] [--baseline OTHER/src]
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SEED = ROOT / "models" / "SpringMass.mdl"
DEFAULT_RUMOCA = Path("/work/venv-rumoca/bin/python")

RUMOCA_SCRIPT = """
import csv, sys
import rumoca
model = rumoca.Session().load(sys.argv[1])
result = model.simulate((0.0, 10.0), dt=0.01, config=rumoca.SimConfig(rtol=1e-6, atol=1e-9))
with open(sys.argv[2], "w", newline="") as f:
    out = csv.writer(f)
    out.writerow(["time", *result.names])
    columns = [result[name] for name in result.names]
    for i, t in enumerate(result.time):
        out.writerow([t, *(c[i] for c in columns)])
"""


@dataclass
class Contender:
    """A command timed in a fresh process, its output file and its samples."""

    name: str
    command: list[str]
    env: dict[str, str]
    output: Path | None = None
    wall: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)

    def run(self, timed: bool = True) -> None:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        began = time.perf_counter()
        done = subprocess.run(self.command, env=self.env, capture_output=True, text=True,
                              check=False)
        wall = time.perf_counter() - began
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if done.returncode != 0:
            raise SystemExit(f"{self.name} failed ({done.returncode}):\n{done.stderr}")
        if timed:
            self.wall.append(wall)
            self.cpu.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)


def springc_contender(name: str, src: Path, cache: Path, output: Path) -> Contender:
    env = {**os.environ, "PYTHONPATH": str(src), "SPRINGC_CACHE_DIR": str(cache)}
    command = [sys.executable, "-m", "springc", "simulate", str(SEED), "-o", str(output),
               "--interval", "0.01", "--rtol", "1e-6", "--atol", "1e-9", "-q"]
    return Contender(name, command, env, output)


def rumoca_python(given: str | None) -> str | None:
    """An interpreter that imports rumoca, or None."""
    candidates = [given] if given else [sys.executable, str(DEFAULT_RUMOCA)]
    for python in candidates:
        if python and Path(python).exists() and subprocess.run(
                [python, "-c", "import rumoca"], capture_output=True, check=False
        ).returncode == 0:
            return python
    return None


def final_row(path: Path) -> dict[str, float]:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    return dict(zip(rows[0], map(float, rows[-1])))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="timed runs of each (default 7)")
    parser.add_argument("--rumoca", help="a Python interpreter with rumoca installed")
    parser.add_argument("--src", type=Path, default=ROOT / "src",
                        help="the springc source tree to time (default: this checkout's)")
    parser.add_argument("--baseline", type=Path, help="another springc source tree to time")
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="springc-latency-"))
    contenders = [springc_contender("springc", args.src.resolve(), work / "cache",
                                    work / "springc.csv")]
    if args.baseline:
        contenders.append(springc_contender("baseline", args.baseline.resolve(),
                                            work / "cache-baseline", work / "baseline.csv"))
    rumoca = rumoca_python(args.rumoca)
    if rumoca:
        contenders.append(Contender("rumoca", [rumoca, "-c", RUMOCA_SCRIPT, str(SEED),
                                               str(work / "rumoca.csv")], dict(os.environ),
                                    work / "rumoca.csv"))
    contenders += [Contender("python -c pass", [sys.executable, "-c", "pass"], dict(os.environ)),
                   Contender("python -c 'import numpy'",
                             [sys.executable, "-c", "import numpy"], dict(os.environ))]
    load_before = os.getloadavg()
    for contender in contenders:  # fill the caches (springc's, numba's, the OS's)
        contender.run(timed=False)
    for round_ in range(args.runs):
        shift = round_ % len(contenders)
        for contender in contenders[shift:] + contenders[:shift]:
            contender.run()
    load_after = os.getloadavg()
    reference = next((c for c in contenders if c.name == "rumoca"), contenders[-1])
    print(f"seed end to end, warm, {args.runs} alternating runs; load average "
          f"{load_before[0]:.2f} before, {load_after[0]:.2f} after ({os.cpu_count()} CPUs)")
    if not rumoca:
        print("rumoca was not available (pip install rumoca, then --rumoca PYTHON): ratios "
              "are to the numpy import floor")
    ref_wall, ref_cpu = statistics.median(reference.wall), statistics.median(reference.cpu)
    print(f"{'contender':<28} {'wall s':>8} {'cpu s':>8} {'wall / ' + reference.name:>16} "
          f"{'cpu / ' + reference.name:>16}")
    for c in contenders:
        wall, cpu = statistics.median(c.wall), statistics.median(c.cpu)
        print(f"{c.name:<28} {wall:8.3f} {cpu:8.3f} {wall / ref_wall:16.2f} "
              f"{cpu / ref_cpu:16.2f}")
    outputs = [(c.name, final_row(c.output)) for c in contenders if c.output is not None]
    for name, last in outputs[1:]:  # the same problem: final states agree to the tolerance
        first = outputs[0][1]
        gap = max(abs(first[k] - last[k]) for k in first if k in last and k != "time")
        print(f"largest difference of {name}'s final values from {outputs[0][0]}'s: "
              f"{gap:.2g}")


if __name__ == "__main__":
    main()
