"""What a new model costs before its first result, and the chain against hand-written code.

    PYTHONPATH=src python benchmarks/bench_compile.py [--quick] [--only abcd] [--cpu]

Each figure comes from a fresh interpreter with a new springc cache (a model springc
has not seen; the cache holds only the parser tables, built once per user) and numba's
cache holding the integration kernels (they compile once per machine; a first step of
this script makes sure both are there). Each phase is timed in wall-clock and CPU
seconds (on a loaded machine the CPU time is the better guide to an idle machine's):

(a) the seed: ``compile_model`` (flatten .. generate .. import) and the first call of
    each generated function (numba compiles it), then the first ``simulate`` on the
    compiled engine; baseline: the interpreter + numpy + scipy + numba import floor,
    measured in the same run. Target: about 2 s of compilation.
(b) the 1,000-mass chain end to end (import, compile, first compiled DOP853 run of all
    10,002 outputs): target under 5 s; the same import floor as baseline.
(c) the 1,000-mass chain warm, in process: ``springc.simulate`` (compiled engine, DOP853,
    every output, and the states only) and its loop against the compiled DOP853 loop
    (plain loops) on the hand-written right-hand side of ``handwritten.py`` (with
    ``--fused``: that loop specialised by numba on it, a compile of minutes), same
    tolerances and grid, error control off (the hand-written run has none): target
    within 1.5x; the same rows on the C loop
    (``SPRINGC_LOOP=c``, python modules: the model's C functions and DOP853 in one
    library). Best of 7 in wall seconds, or with ``--cpu`` in this process's CPU
    seconds (a loaded machine); "its loop" rows are ``SimulationStats.loop_time``
    (wall) either way.
(d) the 10,000-mass chain (2,000 with --quick): compile_model and first calls.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as `springc simulate` does

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = str(ROOT / "models" / "Scenes.mdl")
SEED = str(ROOT / "models" / "SpringMass.mdl")
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

Row = tuple[str, str, str, str, str]
rows: list[Row] = []

FIRST_RUN = """
import json, sys, time
clock = lambda: (time.perf_counter(), time.process_time())
began = clock()
import numpy as np
import springc
figures = {}
def lap(key, since):
    now = clock()
    figures[key] = (now[0] - since[0], now[1] - since[1])
    return now
t = lap("import", began)
files, name, n = sys.argv[1], sys.argv[2] or None, int(sys.argv[3])
model = springc.compile_model(files, name, backend="numba",
                              parameters={"N": n} if n else None)
t = lap("compile_model", t)
if sys.argv[4] == "functions":
    mod = model.module
    p = mod.parameters({})
    x, z = mod.start(p), mod.guesses(p)
    for fn in ("rhs", "jacobian_values", "observed"):
        getattr(mod, fn)(0.0, x, p, z)
        t = lap(fn, t)
    mod.observed_grid(np.zeros(1), np.ascontiguousarray(x[None, :]), p, z)
    t = lap("observed_grid", t)
result = springc.simulate(model, solver="dop853", engine="compiled")
lap("simulate", t)
lap("total", began)
figures["engine"] = result.stats.engine
figures["outputs"] = len(result.names)
print(json.dumps(figures))
"""
Figures = dict[str, Any]
PARSER_TABLES = tempfile.TemporaryDirectory()
"""A springc cache of the first run: the parser tables each fresh cache starts with."""


def fresh(env: dict[str, str], files: str, name: str = "", n: int = 0,
          functions: bool = True) -> Figures:
    """The figures of FIRST_RUN in a new interpreter with a new springc cache: (wall,
    CPU) seconds per phase (the CPU time is the wall time of an idle machine)."""
    with tempfile.TemporaryDirectory() as tmp:
        parser = Path(PARSER_TABLES.name) / "parser"
        if parser.is_dir():  # springc's grammar tables, built once per user
            shutil.copytree(parser, Path(tmp) / "parser")
        out = subprocess.run([sys.executable, "-c", FIRST_RUN, files, name, str(n),
                              "functions" if functions else "run"],
                             env=dict(env, SPRINGC_CACHE_DIR=tmp), check=True,
                             capture_output=True, text=True).stdout
    figures: Figures = json.loads(out.splitlines()[-1])
    assert figures["engine"] == "compiled", figures
    return figures


def both(pair: tuple[float, float]) -> str:
    return f"{pair[0]:.2f} s (CPU {pair[1]:.2f} s)"


def import_floor(env: dict[str, str]) -> tuple[float, float]:
    """(wall, CPU) seconds of an interpreter importing numpy, scipy and numba: the least
    any first run costs."""
    code = ("import time; import numpy, scipy.integrate, scipy.sparse, numba; "
            "print(time.process_time())")
    times = []
    for _ in range(3):
        began = time.perf_counter()
        cpu = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                             capture_output=True, text=True).stdout
        times.append((time.perf_counter() - began, float(cpu)))
    return min(times)


def bench_seed(env: dict[str, str], floor: tuple[float, float]) -> None:
    f = fresh(env, SEED)
    names = ("rhs", "jacobian_values", "observed", "observed_grid")
    for key in ("compile_model", *names):
        rows.append((f"(a) seed, new model: {key}", both(f[key]), "", "", ""))
    functions = (sum(f[k][0] for k in names), sum(f[k][1] for k in names))
    rows.append(("(a) seed, new model: the generated functions", both(functions), "", "",
                 ""))
    g = fresh(env, SEED, functions=False)
    first = (g["compile_model"][0] + g["simulate"][0], g["compile_model"][1] + g["simulate"][1])
    rows.append(("(a) seed, new model: compile_model + first simulate", both(first),
                 f"import floor {both(floor)}", f"{first[1] / floor[1]:.1f}x CPU",
                 "about 2 s"))


def bench_chain_end_to_end(env: dict[str, str], floor: tuple[float, float]) -> None:
    f = fresh(env, SCENES, "Scenes.Chain", 1000, functions=False)
    rows.append(("(b) chain N=1000, fresh process + new model, end to end",
                 both(f["total"]), f"import floor {both(floor)}",
                 f"{f['total'][1] / floor[1]:.1f}x CPU", "< 5 s"))
    for key in ("import", "compile_model", "simulate"):
        rows.append((f"(b)   {key}", both(f[key]),
                     f"{f['outputs']} outputs" if key == "simulate" else "", "", ""))


CLOCK = [time.perf_counter]
"""(c)'s clock: wall, or ``time.process_time`` with ``--cpu``."""


def best_of(repeats: int, run: object) -> float:
    run()  # type: ignore[operator]
    times = []
    for _ in range(repeats):
        began = CLOCK[0]()
        run()  # type: ignore[operator]
        times.append(CLOCK[0]() - began)
    return min(times)


def bench_chain_warm(repeats: int, fused: bool) -> None:
    from numba import njit

    import springc
    from handwritten import chain_rhs
    from springc.integrate import dop853, dop853_steps
    from springc.integrate.loop import specialize
    from springc.integrate.models import no_observed

    n = 1000
    every = springc.compile_model(SCENES, "Scenes.Chain", backend="numba",
                                  parameters={"N": n})
    states = springc.compile_model(SCENES, "Scenes.Chain", backend="numba",
                                   parameters={"N": n}, outputs=list(every.states))
    result = springc.simulate(every, solver="dop853", engine="compiled", error_control="off")
    rtol, atol, grid = 1e-6, 1e-9, result.time  # springc's defaults: atol = rtol / 1000
    all_outputs = best_of(repeats, lambda: springc.simulate(every, solver="dop853",
                                                            engine="compiled",
                                                            error_control="off"))
    loops = []

    def states_only() -> None:
        loops.append(springc.simulate(states, solver="dop853", engine="compiled",
                                      error_control="off").stats.loop_time)
    states_time = best_of(repeats, states_only)
    loop = min(loops)

    @njit(error_model="numpy")
    def hand(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
        return chain_rhs(t, x, p[0], p[1], p[2])

    x0 = np.array([result[s][0] for s in every.states])
    p, z = np.array([100.0, 1.0, 1.0]), np.zeros(1)
    atols = np.full(x0.size, atol)
    if fused:  # the loop specialised by numba on this rhs (minutes to compile under load)
        kernel = specialize("dop853_fused", dop853_steps, False)  # the shared loop
        none = np.empty(0, dtype=np.int64)

        def hand_run() -> object:
            return kernel(hand, no_observed, no_observed, 0, no_observed, np.empty(0),
                          np.empty(0), grid, x0.copy(), p, z, rtol, atols, np.inf, 0.0, 0,
                          np.inf, (none, 0, 0, none, none))
    else:  # the same compiled loop calling the hand-written rhs through a function pointer
        def hand_run() -> object:
            return dop853(hand, grid, x0, p, z, rtol=rtol, atol=atol,
                          scipy_arithmetic=False).states
    began = time.perf_counter()
    out = hand_run()
    print(f"  hand-written run compiled in {time.perf_counter() - began:.1f} s", flush=True)
    states_out = out[1] if fused else out  # type: ignore[index]
    np.testing.assert_allclose(states_out,
                               np.column_stack([result[s] for s in every.states]),
                               rtol=0, atol=1e-5)  # the same method (other roundings)
    hand_time = best_of(repeats, hand_run)
    base = f"{'fused ' if fused else ''}hand-written loop {hand_time * 1e3:.0f} ms"
    rows.append(("(c) chain N=1000 warm: simulate, 10,002 outputs", f"{all_outputs * 1e3:.0f} ms",
                 base, f"{all_outputs / hand_time:.2f}x", ""))
    rows.append(("(c) chain N=1000 warm: simulate, the 2,000 states",
                 f"{states_time * 1e3:.0f} ms", base, f"{states_time / hand_time:.2f}x",
                 "<= 1.5x"))
    rows.append(("(c) chain N=1000 warm: its compiled loop", f"{loop * 1e3:.0f} ms", base,
                 f"{loop / hand_time:.2f}x", f"{result.stats.steps} steps"))
    c_rows(repeats, n, base, hand_time)


def c_rows(repeats: int, n: int, base: str, hand_time: float) -> None:
    """(c) on the C loop (SPRINGC_LOOP=c, python modules): the same rows."""
    import springc

    os.environ["SPRINGC_LOOP"] = "c"
    try:
        every = springc.compile_model(SCENES, "Scenes.Chain", backend="python",
                                      parameters={"N": n})
        states = springc.compile_model(SCENES, "Scenes.Chain", backend="python",
                                       parameters={"N": n}, outputs=list(every.states))
        probe = springc.simulate(states, solver="dop853", error_control="off")
        if "(C," not in probe.stats.engine_reason:  # pipeline.c_kernels.loop_refusal
            rows.append(("(c) C loop: not taken", probe.stats.engine_reason, base, "", ""))
            return
        all_outputs = best_of(repeats, lambda: springc.simulate(every, solver="dop853",
                                                            error_control="off"))
        loops = []

        def states_only() -> None:
            run = springc.simulate(states, solver="dop853", error_control="off")
            assert "(C," in run.stats.engine_reason
            loops.append(run.stats.loop_time)
        states_time = best_of(repeats, states_only)
    finally:
        del os.environ["SPRINGC_LOOP"]
    rows.append(("(c) C loop: simulate, 10,002 outputs", f"{all_outputs * 1e3:.0f} ms",
                 base, f"{all_outputs / hand_time:.2f}x", ""))
    rows.append(("(c) C loop: simulate, the 2,000 states", f"{states_time * 1e3:.0f} ms",
                 base, f"{states_time / hand_time:.2f}x", "<= 1.5x"))
    rows.append(("(c) C loop: the loop itself", f"{min(loops) * 1e3:.0f} ms", base,
                 f"{min(loops) / hand_time:.2f}x", ""))


def bench_large(env: dict[str, str], n: int) -> None:
    f = fresh(env, SCENES, "Scenes.Chain", n)
    for key in ("compile_model", "rhs", "jacobian_values", "observed", "simulate"):
        rows.append((f"(d) chain N={n}, new model: {key}", both(f[key]), "", "",
                     "not minutes" if key == "compile_model" else ""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller scenes, fewer repeats")
    parser.add_argument("--only", default="abcd", help="which benchmarks, e.g. 'ab'")
    parser.add_argument("--fused", action="store_true",
                        help="(c) against the loop specialised on the hand-written rhs")
    parser.add_argument("--cpu", action="store_true",
                        help="(c) in CPU seconds of this process, not wall seconds")
    args = parser.parse_args()
    if args.cpu:
        CLOCK[0] = time.process_time
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    # the kernels compile (once per machine) or load; the parser tables are built
    subprocess.run([sys.executable, "-c", FIRST_RUN, SEED, "", "0", "run"], check=True,
                   env=dict(env, SPRINGC_CACHE_DIR=PARSER_TABLES.name), capture_output=True)
    floor = import_floor(env)
    if "a" in args.only:
        print("(a) seed", flush=True)
        bench_seed(env, floor)
    if "b" in args.only:
        print("(b) chain end to end", flush=True)
        bench_chain_end_to_end(env, floor)
    if "c" in args.only:
        print("(c) chain warm", flush=True)
        bench_chain_warm(3 if args.quick else 7, args.fused)
    if "d" in args.only:
        print("(d) large chain", flush=True)
        bench_large(env, 2000 if args.quick else 10_000)
    header: Row = ("benchmark", "springc", "baseline (same run)", "ratio", "target")
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(5)]
    print()
    for r in [header, tuple("-" * w for w in widths), *rows]:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths)).rstrip())


if __name__ == "__main__":
    main()
