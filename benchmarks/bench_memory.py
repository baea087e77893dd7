"""Peak memory and cost of the large scenes through the CLI (issue 24), one fresh
interpreter per run, each measured by the kernel (``wait4``: the child's peak resident
set size and its user + system CPU seconds):

- the 50x50 cloth, ``springc simulate ... --plot cloth.png`` (every output, 128,700
  variables x 501 times), cold (an empty ``SPRINGC_CACHE_DIR``: flatten, simplify,
  generate, numba compiles the model's functions) and warm (the model cached);
  target: peak under 1 GB;
- the 10,000-mass chain cold end to end, ``springc simulate ... --stop 1 --vars 'm[*].s'
  -o chain.csv``; target: under 20 s.

The compiled loops of ``springc.integrate`` are compiled once per machine, not per
model: run any ``springc simulate`` once first so that they are in numba's cache.

    PYTHONPATH=src python benchmarks/bench_memory.py [--only cloth|chain] [--side N]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "models" / "Scenes.mdl"
MEMORY_TARGET_MB = 1000.0
CHAIN_TARGET_S = 20.0


def measure(args: list[str], cache: Path) -> tuple[float, float, float, int]:
    """Peak RSS (MB), CPU seconds (user + system), wall seconds and exit status of
    ``springc ARGS`` in a fresh interpreter with the cache folder ``cache``."""
    env = dict(os.environ, SPRINGC_CACHE_DIR=str(cache))
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "src"),
                                                      env.get("PYTHONPATH", "")]))
    began = time.perf_counter()
    child = subprocess.Popen([sys.executable, "-m", "springc", *args], env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert child.stderr is not None
    errors = child.stderr.read()
    _, status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - began
    if child.returncode:
        print(errors.decode(errors="replace"), file=sys.stderr)
    return usage.ru_maxrss / 1024.0, usage.ru_utime + usage.ru_stime, wall, child.returncode


def row(scene: str, figures: tuple[float, float, float, int], target: str,
        ratio: float) -> None:
    peak, cpu, wall, status = figures
    print(f"| {scene} | {peak:,.0f} | {cpu:.1f} | {wall:.1f} | {status} | {target} "
          f"| {ratio:.2f} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=("cloth", "chain"))
    parser.add_argument("--side", type=int, default=50, help="rows and columns of the cloth")
    parser.add_argument("--masses", type=int, default=10_000, help="masses of the chain")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print("| scene | peak RSS MB | CPU s | wall s | exit | target | ratio |\n"
          "| --- | ---: | ---: | ---: | ---: | --- | ---: |")
    with tempfile.TemporaryDirectory(prefix="bench-memory-") as folder:
        work = Path(folder)
        if args.only in (None, "cloth"):
            cloth = ["simulate", str(SCENES), "--model", "Scenes.Cloth",
                     "--set", f"N={args.side}", "--set", f"M={args.side}",
                     "--plot", str(work / "cloth.png")]
            for kind in ("cold", "warm"):
                figures = measure(cloth, work / "cloth-cache")
                row(f"cloth {args.side}x{args.side} --plot, {kind}", figures,
                    "peak < 1 GB", figures[0] / MEMORY_TARGET_MB)
        if args.only in (None, "chain"):
            chain = ["simulate", str(SCENES), "--model", "Scenes.Chain",
                     "--set", f"N={args.masses}", "--stop", "1", "--vars", "m[*].s",
                     "-o", str(work / "chain.csv")]
            figures = measure(chain, work / "chain-cache")
            row(f"chain {args.masses:,} -o CSV, cold", figures, "wall < 20 s",
                figures[2] / CHAIN_TARGET_S)
    print(f"load average {load:.1f} at the start, {os.getloadavg()[0]:.1f} at the end "
          f"(2-core machine: CPU seconds and peak RSS vary less than wall seconds)")


if __name__ == "__main__":
    main()
