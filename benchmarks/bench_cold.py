"""Cold start: CPU seconds of each compiled loop's first compile, and of the seed's first
simulate, on a machine whose numba cache is empty.

Each measurement runs in a fresh interpreter with its own empty ``NUMBA_CACHE_DIR``
(and, for the seed, an empty ``SPRINGC_CACHE_DIR``), so nothing is shared between them:

- ``<method> loop``: ``springc.integrate.load(method)`` (the loop compiled for this
  machine, as its first run does), CPU seconds of that call alone, numba's import left
  out; and of the whole process (imports included);
- ``seed first simulate``: ``python -m springc simulate models/SpringMass.mdl -o CSV``
  (default solver and engine), CPU seconds of the whole process (the model compiled, its
  functions and the loops it uses compiled by numba);
- ``seed warm simulate``: the same command again, caches filled;
- each seed figure twice: on the C loop (``SPRINGC_LOOP=c``: the model's C functions and
  the DOP853 loop compiled by the C compiler into one library, no numba) and on numba's
  (``SPRINGC_LOOP=numba``), with their ratio;
- ``stiff``: the first ``simulate --solver radau`` (and ``bdf``) of a small stiff model
  (STIFF below, 2 states), caches empty, on the C loop (the model's C functions, the
  loop and the implicit methods compiled into one library) and on numba's (its radau or
  bdf loop compiled by numba), with their ratio, and the next (warm) run: issue #24's
  "first use of each implicit solver under 10 s of CPU";
- ``zig``: the seed's C loop library compiled by ``python -m ziglang cc`` with zig's
  cache empty (its first use on a machine fills it) and again, against the system
  compiler (``cc``), CPU seconds of the compiler processes.

CPU seconds (``getrusage``), not wall: the development machine is shared, and CPU time
is what compiling costs. ``--baseline OTHER/src`` measures another springc tree
alongside, in the same run (before/after); ``--only dop853,radau,stiff`` a subset.

Run: ``PYTHONPATH=src python benchmarks/bench_cold.py [--baseline OTHER/src]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
METHODS = ("dop853", "rk45", "radau", "bdf", "verlet")
CHILD = """
import json, resource, sys
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
import numba, numpy  # noqa: F401  (imports left out of the compile figure)
from springc.integrate import load
before = cpu()
load(sys.argv[1])
print(json.dumps({"compile": cpu() - before, "process": cpu()}))
"""


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(command: list[str], src: Path, cache: Path, **extra: str) -> tuple[str, float]:
    """``command`` in a fresh interpreter on the springc of ``src``: stdout, CPU s."""
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache / "numba"),
           "SPRINGC_CACHE_DIR": str(cache / "springc"), "SPRINGC_QUIET": "1", **extra}
    before = children_cpu()
    done = subprocess.run(command, env=env, cwd=ROOT, capture_output=True, text=True,
                          check=False)
    if done.returncode:
        raise SystemExit(f"{command} failed:\n{done.stderr}")
    return done.stdout, children_cpu() - before


def loop(method: str, src: Path) -> tuple[float, float]:
    """CPU s of ``load(method)`` and of the whole process, numba's cache empty."""
    with tempfile.TemporaryDirectory() as folder:
        out, _ = run([sys.executable, "-c", CHILD, method], src, Path(folder))
    figures = json.loads(out.strip().splitlines()[-1])
    return figures["compile"], figures["process"]


def seed(src: Path, loop: str = "", model: str = "models/SpringMass.mdl",
         options: tuple[str, ...] = ()) -> tuple[float, float]:
    """CPU s of the seed's first simulate (caches empty) and of the next one
    (``loop``: ``SPRINGC_LOOP``, empty: the default; ``model``, ``options``: another
    model file and simulate options)."""
    with tempfile.TemporaryDirectory() as folder:
        csv = Path(folder) / "seed.csv"
        command = [sys.executable, "-m", "springc", "simulate", model, *options,
                   "-o", str(csv)]
        _, first = run(command, src, Path(folder), SPRINGC_LOOP=loop)
        _, warm = run(command, src, Path(folder), SPRINGC_LOOP=loop)
    return first, warm


STIFF = """model Stiff
  parameter Real k = 10000;
  Real a(start = 1, fixed = true);
  Real b(start = 0, fixed = true);
equation
  der(a) = -k * (a - cos(time));
  der(b) = a - b;
end Stiff;
"""


def stiff(trees: list[tuple[str, Path]]) -> None:
    """The rows of ``stiff``: radau's and bdf's first and warm simulate of STIFF, on
    the C loop and on numba's, and their ratios."""
    with tempfile.TemporaryDirectory() as folder:
        model = Path(folder) / "Stiff.mo"
        model.write_text(STIFF, encoding="utf-8")
        for solver in ("radau", "bdf"):
            options = ("--solver", solver, "--stop", "20")
            cells = {loop: [seed(src, loop, str(model), options) for _, src in trees]
                     for loop in ("c", "numba")}
            for loop in ("c", "numba"):
                for k, label in enumerate(("first", "warm")):
                    print(f"{f'{solver} {label} simulate, {loop}':<28}"
                          + "".join(f"{cell[k]:>22.2f}" for cell in cells[loop]))
            for k, label in enumerate(("first", "warm")):
                print(f"{f'{solver} {label}, C / numba':<28}" + "".join(
                    f"{c[k] / n[k]:>22.2f}" for c, n in zip(cells["c"], cells["numba"])),
                    flush=True)


ZIG_BUILD = """
import sys
import springc
from springc.pipeline import c_build, c_kernels
c_build.COMPILERS = ()  # as on a machine whose only compiler is the ziglang package
if sys.argv[1] == "cc":
    c_build.ZIG_MODULE = "no-such-module"
    c_build.COMPILERS = ("cc",)
model = springc.compile_model("models/SpringMass.mdl", backend="python")
c_kernels.loop_library(model)
"""


def zig(src: Path) -> list[tuple[str, float]]:
    """CPU s of building the seed's loop library (its C text printed too) with zig cc,
    zig's cache empty, then again (a new springc cache), and with cc."""
    figures = []
    with tempfile.TemporaryDirectory() as folder:
        zig_cache = {"ZIG_GLOBAL_CACHE_DIR": str(Path(folder) / "zig"),
                     "ZIG_LOCAL_CACHE_DIR": str(Path(folder) / "zig-local")}
        for label, compiler, cache in (("zig cc, zig cache empty", "zig", "a"),
                                       ("zig cc, zig cache filled", "zig", "b"),
                                       ("cc (system)", "cc", "c")):
            _, cpu = run([sys.executable, "-c", ZIG_BUILD, compiler], src,
                         Path(folder) / cache, **zig_cache)
            figures.append((label, cpu))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", type=Path, help="another springc src tree")
    parser.add_argument("--only", default=",".join((*METHODS, "seed", "stiff", "zig")))
    args = parser.parse_args()
    trees = [("this tree", ROOT / "src")]
    if args.baseline:
        trees.insert(0, ("baseline", args.baseline.resolve()))
    wanted = args.only.split(",")
    print(f"{'measure':<28}" + "".join(f"{name:>22}" for name, _ in trees))
    for method in (m for m in METHODS if m in wanted):
        cells = [loop(method, src) for _, src in trees]
        print(f"{method + ' loop, CPU s':<28}"
              + "".join(f"{c:>9.2f} (proc {p:5.2f})" for c, p in cells), flush=True)
    if "seed" in wanted:
        for loop in ("c", "numba"):
            cells = [seed(src, loop) for _, src in trees]
            print(f"{'seed first simulate, ' + loop:<28}"
                  + "".join(f"{first:>22.2f}" for first, _ in cells))
            print(f"{'seed warm simulate, ' + loop:<28}"
                  + "".join(f"{warm:>22.2f}" for _, warm in cells), flush=True)
            if loop == "c":
                c_cells = cells
        print(f"{'seed first, C / numba':<28}" + "".join(
            f"{c[0] / n[0]:>22.2f}" for c, n in zip(c_cells, cells)))
        print(f"{'seed warm, C / numba':<28}" + "".join(
            f"{c[1] / n[1]:>22.2f}" for c, n in zip(c_cells, cells)), flush=True)
    if "stiff" in wanted:
        stiff(trees)
    if "zig" in wanted:
        for label, cpu in zig(trees[-1][1]):
            print(f"{'seed C loop build, ' + label:<44}{cpu:>8.2f} CPU s", flush=True)


if __name__ == "__main__":
    main()
