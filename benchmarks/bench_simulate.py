"""Benchmarks of code generation and simulation, with baselines measured in the same run.

    python benchmarks/bench_simulate.py [--quick] [--only abc]

(a) generated numba right-hand side vs a hand-written numba one (``handwritten.py``)
    for the 1,000-mass chain and the 50x50 cloth (20x20 with --quick): target 1.5x;
(b) ``springc simulate`` of the seed end to end in a fresh interpreter, cold and warm
    cache, against the interpreter + numpy + scipy.integrate import floor:
    target warm under 1.5 s;
(c) the 10,000-mass chain (2,000 with --quick) with BDF and the sparse analytic
    Jacobian: wall time and the share spent in springc's generated code vs scipy;
(d) the seed, warm, in process: ``springc.simulate`` on the compiled engine (numba
    loops of springc.integrate) against the scipy engine on the same numba module and
    on the python backend (the scipy engine's default), and the first run's compile
    time in a fresh process: numba's cache empty (kernels and model functions compile)
    and with the kernels cached (a new model compiles its own functions only).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as `springc simulate` does

import argparse
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = str(ROOT / "models" / "Scenes.mdl")
SEED = str(ROOT / "models" / "SpringMass.mdl")
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import springc  # noqa: E402

Row = tuple[str, str, str, str, str]
rows: list[Row] = []


def per_call(fn: object, repeat: int = 7) -> float:
    """Best time of one call, in seconds."""
    number = 200
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number  # type: ignore[arg-type]


def bench_rhs(name: str, params: dict[str, float], hand: object, label: str) -> None:
    began = time.perf_counter()
    model = springc.compile_model(SCENES, name, parameters=params, backend="numba")
    compiled = time.perf_counter() - began
    mod = model.module
    p = mod.parameters()
    z = mod.guesses(p)
    x = mod.start(p) + 1e-3 * np.random.default_rng(0).standard_normal(len(mod.STATES))
    began = time.perf_counter()
    ours = mod.rhs(0.0, x, p, z)
    first = time.perf_counter() - began
    theirs = hand(0.0, x)  # type: ignore[operator]
    error = np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs))
    assert error < 1e-12, f"{label}: generated and hand-written RHS differ ({error:.1e})"
    t_ours = per_call(lambda: mod.rhs(0.0, x, p, z))
    t_hand = per_call(lambda: hand(0.0, x))  # type: ignore[operator]
    rows.append((f"(a) RHS {label}, numba, per call", f"{t_ours * 1e6:.1f} us",
                 f"{t_hand * 1e6:.1f} us hand-written", f"{t_ours / t_hand:.2f}x", "<= 1.5x"))
    print(f"  {label}: {len(mod.STATES)} states; flatten+simplify+generate "
          f"{compiled:.1f} s ({'cached' if model.cached else 'cold'}), numba compile "
          f"{first:.1f} s, max relative difference {error:.1e}", flush=True)


def run(args: list[str], env: dict[str, str]) -> float:
    began = time.perf_counter()
    subprocess.run(args, check=True, env=env, capture_output=True)
    return time.perf_counter() - began


def bench_end_to_end() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, SPRINGC_CACHE_DIR=str(Path(tmp) / "cache"),
                   PYTHONPATH=str(ROOT / "src"))
        cmd = [sys.executable, "-m", "springc", "simulate", SEED, "-o",
               str(Path(tmp) / "seed.csv"), "-q"]
        floor = min(run([sys.executable, "-c", "import numpy, scipy.integrate"], env)
                    for _ in range(3))
        cold = run(cmd, env)
        warm = min(run(cmd, env) for _ in range(3))
        plot = min(run([*cmd, "--plot", str(Path(tmp) / "seed.png")], env) for _ in range(2))
    base = f"{floor:.2f} s import floor"
    rows.append(("(b) seed end to end, cold cache", f"{cold:.2f} s", base,
                 f"{cold / floor:.2f}x", ""))
    rows.append(("(b) seed end to end, warm cache", f"{warm:.2f} s", base,
                 f"{warm / floor:.2f}x", "< 1.5 s"))
    rows.append(("(b) seed + --plot, warm cache", f"{plot:.2f} s", base,
                 f"{plot / floor:.2f}x", ""))


def bench_large_chain(n: int) -> None:
    began = time.perf_counter()
    model = springc.compile_model(SCENES, "Scenes.Chain", parameters={"N": n},
                                  outputs=["m[1].s", f"m[{n}].s"])
    compiled = time.perf_counter() - began
    result = springc.simulate(model, solver="bdf")
    s = result.stats
    share = s.model_time / s.wall_time
    rows.append((f"(c) chain N={n}, bdf + sparse Jacobian", f"{s.wall_time:.2f} s",
                 f"springc code {s.model_time:.2f} s", f"{100 * share:.0f}% springc",
                 f"{100 - 100 * share:.0f}% scipy"))
    print(f"  chain N={n}: {2 * n} states, compile {compiled:.1f} s "
          f"({'cached' if model.cached else 'cold'}); {s.summary(result.model)}", flush=True)


def best_run(repeats: int, **keywords: object) -> tuple[float, object]:
    """The smallest wall time of ``repeats`` simulate calls (after a warm-up) and a result."""
    result = springc.simulate(**keywords)  # type: ignore[arg-type]
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        springc.simulate(**keywords)  # type: ignore[arg-type]
        times.append(time.perf_counter() - began)
    return min(times), result


FIRST_RUN = """
import sys, time
began = time.perf_counter()
import springc
result = springc.simulate(sys.argv[1], engine="compiled")
print(time.perf_counter() - began, result.stats.wall_time, result.stats.engine)
"""


def first_run(env: dict[str, str]) -> tuple[float, float]:
    """Seconds of a fresh process's import + simulate, and of simulate alone."""
    out = subprocess.run([sys.executable, "-c", FIRST_RUN, SEED], check=True, env=env,
                         capture_output=True, text=True).stdout.split()
    assert out[2] == "compiled", out
    return float(out[0]), float(out[1])


def solve_ivp_on_numba_rhs(repeats: int) -> float:
    """The smallest wall time of scipy's ``solve_ivp(method="DOP853")`` driving the seed's
    hand-written numba right-hand side (``bench_engine.seed_rhs``), same tolerances and
    output grid as ``simulate``'s defaults."""
    from scipy.integrate import solve_ivp

    from bench_engine import ATOL, INTERVALS, NO_Z, RTOL, SEED_P, SEED_X0, STOP, seed_rhs

    grid = np.linspace(0.0, STOP, INTERVALS + 1)

    def run() -> object:
        return solve_ivp(lambda t, x: seed_rhs(t, x, SEED_P, NO_Z), (0.0, STOP), SEED_X0,
                         method="DOP853", t_eval=grid, rtol=RTOL, atol=ATOL)
    run()
    return min(timeit.repeat(run, number=1, repeat=repeats))


def bench_engines(repeats: int) -> None:
    numba_model = springc.compile_model(SEED, backend="numba")
    python_model = springc.compile_model(SEED, backend="python")
    compiled, run = best_run(repeats, model=numba_model, engine="compiled")
    scipy_numba, _ = best_run(repeats, model=numba_model, engine="scipy")
    scipy_python, _ = best_run(repeats, model=python_model, engine="scipy")
    steps = run.stats.steps  # type: ignore[attr-defined]
    baseline = solve_ivp_on_numba_rhs(repeats)
    rows.append(("(d) seed in process, warm, compiled engine", f"{compiled * 1e3:.1f} ms",
                 f"solve_ivp DOP853, hand-written numba rhs {baseline * 1e3:.0f} ms",
                 f"{baseline / compiled:.0f}x faster", "issue 13: at least 20x"))
    rows.append(("(d) seed in process, warm, compiled engine", f"{compiled * 1e3:.1f} ms",
                 f"scipy engine, numba module {scipy_numba * 1e3:.0f} ms",
                 f"{scipy_numba / compiled:.0f}x faster", f"{steps} steps"))
    rows.append(("(d) seed in process, warm, compiled engine", f"{compiled * 1e3:.1f} ms",
                 f"scipy engine, python module {scipy_python * 1e3:.0f} ms",
                 f"{scipy_python / compiled:.0f}x faster", "(the scipy engine's default)"))
    os.environ["SPRINGC_LOOP"] = "c"  # the C loop on a python module, same run
    try:
        c_auto, c_run = best_run(repeats, model=python_model, engine="compiled")
        c_direct, _ = best_run(repeats, model=python_model, solver="dop853",
                               engine="compiled")
    finally:
        del os.environ["SPRINGC_LOOP"]
    assert "(C," in c_run.stats.engine_reason  # type: ignore[attr-defined]
    rows.append(("(d) seed in process, warm, C loop (auto)", f"{c_auto * 1e3:.1f} ms",
                 f"numba loop {compiled * 1e3:.1f} ms", f"{c_auto / compiled:.2f}x",
                 f"{c_run.stats.steps} steps"))  # type: ignore[attr-defined]
    # --solver dop853: no auto probe and no stiffness estimate
    direct, _ = best_run(repeats, model=numba_model, solver="dop853", engine="compiled")
    scipy_direct, _ = best_run(repeats, model=numba_model, solver="dop853", engine="scipy")
    rows.append(("(d) seed in process, warm, --solver dop853 compiled",
                 f"{direct * 1e3:.1f} ms", f"scipy engine {scipy_direct * 1e3:.0f} ms",
                 f"{scipy_direct / direct:.0f}x faster", "same steps"))
    rows.append(("(d) seed in process, warm, --solver dop853, C loop",
                 f"{c_direct * 1e3:.1f} ms", f"numba loop {direct * 1e3:.1f} ms",
                 f"{c_direct / direct:.2f}x", "same steps"))
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, SPRINGC_CACHE_DIR=str(Path(tmp) / "springc"),
                   NUMBA_CACHE_DIR=str(Path(tmp) / "numba"), PYTHONPATH=str(ROOT / "src"))
        cold_total, cold_run = first_run(env)
        env["SPRINGC_CACHE_DIR"] = str(Path(tmp) / "springc2")  # a new model, kernels cached
        model_total, model_run = first_run(env)
        warm_total, warm_run = first_run(env)  # both cached
    rows.append(("(d) seed first run, fresh process, numba cache empty",
                 f"{cold_total:.1f} s", f"simulate call {cold_run:.1f} s", "",
                 "kernels + model compile"))
    rows.append(("(d) seed first run, kernels cached, new model", f"{model_total:.1f} s",
                 f"simulate call {model_run:.1f} s", "", "model functions compile"))
    rows.append(("(d) seed, fresh process, everything cached", f"{warm_total:.1f} s",
                 f"simulate call {warm_run:.2f} s", "", "import + cache loads"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller scenes")
    parser.add_argument("--only", default="abcd", help="which benchmarks, e.g. 'bc'")
    args = parser.parse_args()
    quick, only = args.quick, args.only

    side = 20 if quick else 50
    if "a" in only:
        from handwritten import chain_rhs, cloth_rhs

        print("(a) right-hand sides", flush=True)
        bench_rhs("Scenes.Chain", {"N": 1000},
                  lambda t, x: chain_rhs(t, x, 100.0, 1.0, 1.0), "chain N=1000")
        bench_rhs("Scenes.Cloth", {"N": side, "M": side},
                  lambda t, x: cloth_rhs(t, x, side, side, 0.1, 0.01, 1000.0, 200.0),
                  f"cloth {side}x{side}")
    if "b" in only:
        print("(b) end to end", flush=True)
        bench_end_to_end()
    if "c" in only:
        print("(c) large chain", flush=True)
        bench_large_chain(2000 if quick else 10000)
    if "d" in only:
        print("(d) compiled engine vs scipy engine", flush=True)
        bench_engines(3 if quick else 10)
    header: Row = ("benchmark", "springc", "baseline (same run)", "ratio", "target")
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(5)]
    print()
    for r in [header, tuple("-" * w for w in widths), *rows]:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths)).rstrip())


if __name__ == "__main__":
    main()
