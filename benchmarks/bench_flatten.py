"""Benchmark of parse + flatten (source -> flat model) on the Chain and Cloth scenes.

    PYTHONPATH=src python benchmarks/bench_flatten.py [--quick]

Sizes: the 1D chain at N = 100, 1,000, 10,000 and the 2D cloth at 10x10, 30x30,
50x50, 100x100 (``--quick``: chain 100 and 1,000, cloth 10x10 and 30x30). For each
size: unknowns, equations, parse + load time (the scene file plus the bundled library),
flatten time, their total, microseconds of flatten time per equation, and that time
per equation relative to the smallest size of the same family measured in this run
(1.00 = perfectly linear). Times are medians over a few repeats (more for small
sizes) of the CPU time of this (single-threaded) process, which on an idle machine is
the wall-clock time and on a shared one is not inflated by other processes. The
scaling exponent is the least-squares slope of log(flatten time) over log(N) for the
chain and over log(N*M) for the cloth.
Targets: the 10,000-mass chain and the 50x50 cloth each flatten in under 3 s.
"""

from __future__ import annotations

import argparse
import gc
import math
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from springc.flatten.flattener import flatten
from springc.parse import clear_parse_cache, load

CHAIN = [100, 1_000, 10_000]
CLOTH = [(10, 10), (30, 30), (50, 50), (100, 100)]
QUICK_CHAIN = [100, 1_000]
QUICK_CLOTH = [(10, 10), (30, 30)]


@dataclass(frozen=True)
class Row:
    """One measured size."""

    label: str
    size: int  # N for the chain, N*M for the cloth
    unknowns: int
    equations: int
    load: float  # seconds, parse + load
    flatten: float  # seconds

    @property
    def total(self) -> float:
        return self.load + self.flatten

    @property
    def us_per_equation(self) -> float:
        return 1e6 * self.flatten / self.equations


def repeats(size: int) -> int:
    """More repeats for small models, whose times are short and noisy."""
    return 5 if size <= 1_000 else 3 if size <= 3_000 else 1


def measure(folder: Path, label: str, model: str, size: int) -> Row:
    """Parse, load and flatten ``model`` (a short class definition) a few times."""
    path = folder / "Bench.mdl"
    path.write_text(f"model Bench = {model};\n")
    loads, flattens = [], []
    for _ in range(repeats(size)):
        gc.collect()
        # A cold parse every time: load() keeps the syntax trees of unchanged files.
        clear_parse_cache()
        t0 = time.process_time()
        tree = load([path])
        t1 = time.process_time()
        flat = flatten(tree, "Bench")
        t2 = time.process_time()
        loads.append(t1 - t0)
        flattens.append(t2 - t1)
        unknowns, equations = len(flat.unknowns), len(flat.equations)
        del flat, tree
    return Row(label, size, unknowns, equations, statistics.median(loads),
               statistics.median(flattens))


def exponent(rows: list[Row]) -> float:
    """Least-squares slope of log(flatten time) against log(size)."""
    xs = [math.log(r.size) for r in rows]
    ys = [math.log(r.flatten) for r in rows]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return (sum((a - mx) * (b - my) for a, b in zip(xs, ys))
            / sum((a - mx) ** 2 for a in xs))


HEADER = (f"{'model':<14} {'unknowns':>9} {'equations':>9} {'parse+load s':>12} "
          f"{'flatten s':>9} {'total s':>8} {'us/eq':>6} {'vs smallest':>11}")


def print_row(row: Row, base: Row) -> None:
    ratio = row.us_per_equation / base.us_per_equation
    print(f"{row.label:<14} {row.unknowns:>9,} {row.equations:>9,} {row.load:>12.3f} "
          f"{row.flatten:>9.3f} {row.total:>8.3f} {row.us_per_equation:>6.1f} "
          f"{ratio:>11.2f}", flush=True)


def family(folder: Path, cases: list[tuple[str, str, int]], what: str) -> None:
    """Measure and print one family of sizes, then its scaling exponent."""
    rows: list[Row] = []
    for label, model, size in cases:
        rows.append(measure(folder, label, model, size))
        print_row(rows[-1], rows[0])
    if len(rows) > 1:
        print(f"{'':<14} scaling exponent of flatten time over {what}: "
              f"{exponent(rows):.2f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="a CI-sized subset (chain up to 1,000, cloth up to 30x30)")
    args = parser.parse_args()
    chain = QUICK_CHAIN if args.quick else CHAIN
    cloth = QUICK_CLOTH if args.quick else CLOTH
    print(HEADER)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        family(folder, [(f"Chain {n:,}", f"Scenes.Chain(N = {n})", n) for n in chain], "N")
        family(folder, [(f"Cloth {n}x{m}", f"Scenes.Cloth(N = {n}, M = {m})", n * m)
                        for n, m in cloth], "N*M")


if __name__ == "__main__":
    main()
