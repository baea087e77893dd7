"""Benchmark of lowering + simplification (flat model -> ODE) on Chain and Cloth.

    PYTHONPATH=src python benchmarks/bench_simplify.py [--quick] [--full]

For each size: flatten time (reported, not the target), lowering + simplification
time, states, equations, and the symbolic work (``solve``: equations solved for a
variable, ``diff``: differentiations) per equation. Ratios are against the smallest
size of the same family in this run (baseline), and the scaling exponent is the
least-squares slope of log(time) over log(equations). Wall and CPU time are
both shown: on a shared machine the CPU time of this process is the steadier
figure. Targets: under 5 s for the 10,000-mass chain and the 50x50 cloth;
``--full`` adds the 100x100 cloth.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

from springc.pipeline.files import flatten_files
from springc.simplify.isolate import counting
from springc.simplify.passes import simplify

ROOT = Path(__file__).resolve().parents[1]


def run(folder: Path, family: str, size: tuple[int, ...]) -> dict[str, float]:
    """Flatten and simplify one instance; return timings and counts."""
    if family == "Chain":
        name, mods = f"Chain{size[0]}", f"N = {size[0]}"
    else:
        name, mods = f"Cloth{size[0]}x{size[1]}", f"N = {size[0]}, M = {size[1]}"
    path = folder / f"{name}.mdl"
    path.write_text(f"model {name}\n  extends Scenes.{family}({mods});\nend {name};\n")
    t0 = time.perf_counter()
    flat = flatten_files([path], name)
    t1 = time.perf_counter()
    c1 = time.process_time()
    with counting() as work:
        result = simplify(flat)
    t2, c2 = time.perf_counter(), time.process_time()
    return {"flatten": t1 - t0, "simplify": t2 - t1, "cpu": c2 - c1,
            "states": len(result.ode.states),
            "equations": len(flat.equations), "solve": work.solve,
            "diff": work.diff}


def exponent(rows: list[dict[str, float]]) -> float:
    """Slope of log(simplify time) against log(equations)."""
    xs = [math.log(r["equations"]) for r in rows]
    ys = [math.log(r["simplify"]) for r in rows]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return (sum((a - mx) * (b - my) for a, b in zip(xs, ys))
            / sum((a - mx) ** 2 for a in xs))


def report(family: str, sizes: list[tuple[int, ...]], folder: Path) -> None:
    rows = []
    print(f"{family}: size, equations, states, flatten s, simplify s (wall), simplify s "
          f"(CPU), time/eq vs baseline, solve/eq, diff/eq")
    for size in sizes:
        row = run(folder, family, size)
        rows.append(row)
        base = rows[0]
        ratio = (row["simplify"] / row["equations"]) / (base["simplify"] / base["equations"])
        print(f"  {'x'.join(map(str, size)):>9} {row['equations']:>8} {row['states']:>7} "
              f"{row['flatten']:>8.2f} {row['simplify']:>8.2f} {row['cpu']:>8.2f} {ratio:>8.2f} "
              f"{row['solve'] / row['equations']:>8.3f} {row['diff'] / row['equations']:>8.3f}",
              flush=True)
    if len(rows) > 1:
        print(f"  scaling exponent of simplify time over equations: {exponent(rows):.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes only")
    parser.add_argument("--full", action="store_true", help="add the 100x100 cloth")
    args = parser.parse_args()
    chain = [(n,) for n in ((250, 500, 1000) if args.quick else (1000, 2500, 5000, 10000))]
    cloth = [(n, n) for n in ((5, 10, 15) if args.quick else (10, 20, 35, 50))]
    if args.full:
        cloth.append((100, 100))
    with tempfile.TemporaryDirectory() as tmp:
        report("Chain", chain, Path(tmp))
        report("Cloth", cloth, Path(tmp))


if __name__ == "__main__":
    main()
