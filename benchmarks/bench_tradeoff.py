"""Benchmark: the setting ``springc tradeoff`` recommends vs scipy's default call.

    PYTHONPATH=src python benchmarks/bench_tradeoff.py [--quick]
    PYTHONPATH=src python benchmarks/bench_tradeoff.py --versus OLD/src

With ``--versus OLD/src`` (the sources of an older springc, e.g. ``git worktree add
/tmp/tradeoff-old c2523e1``): only the whole ``springc tradeoff models/SpringMass.mdl``
command, wall clock, with this tree, then the old one, then this tree again (same
machine state: the ratio is the old time over the mean of the two new ones; each tree's
model cache and compiled loops warmed by a short study first), and whether the
recommendation lines are the same. **Target:** 10x faster, the same recommendation
from both new runs (printed next to the old one's: on c2523e1, whose dop853 ran in
scipy's loop, dop853 at rtol 1e-7 and lsoda at rtol 1e-8 are within its timing noise,
and it recommends either).

For the seed (``models/SpringMass.mdl``) and the 20x20 cloth (``Scenes.Cloth``): the
full tradeoff study (:mod:`springc.tradeoff.study`; ``--quick``: fewer tolerances); with
``--full`` also a reduced one of the 50x50 cloth (dop853 only). Then
the fastest setting for max error 1e-4 against scipy's default
``solve_ivp(rhs, span, x0, t_eval=grid)`` (RK45, rtol 1e-3, atol 1e-6) on the same
generated right-hand side, and against ``solve_ivp`` RK45 at the loosest rtol that
reaches 1e-4. **Target:** the recommendation is at least 3x faster than scipy's
default call at the same error, or the default call does not reach that error.
``benchmarks/accuracy.py`` runs the same studies and writes ``docs/accuracy.md``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as `springc simulate` does

import argparse
import importlib.util
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import springc  # noqa: E402
from springc.tradeoff import (  # noqa: E402
    DEFAULT_TOLERANCES,
    Tradeoff,
    TradeoffOptions,
    compare_states,
    recommendations,
    run_tradeoff,
)
from springc.tradeoff.model import SCIPY_DEFAULT, SCIPY_RK45  # noqa: E402

TARGET = 1e-4
SPEEDUP = 3.0
BACKEND = "numba" if importlib.util.find_spec("numba") else "python"
QUICK_TOLERANCES = (1e-3, 1e-5, 1e-7, 1e-9)


@dataclass(frozen=True)
class Scene:
    key: str
    title: str
    file: str
    model: str | None
    parameters: dict[str, float]
    solvers: tuple[str, ...] | None = None  # None: every available solver
    tolerances: tuple[float, ...] = DEFAULT_TOLERANCES
    budget: float | None = None  # seconds per run; None: the command's --budget
    note: str = ""


def scenes(quick: bool, full: bool = False) -> list[Scene]:
    """The seed and the 20x20 cloth with every solver; with ``full``, the 50x50 cloth
    with dop853 only (its reference solves take about half a minute each)."""
    tolerances = QUICK_TOLERANCES if quick else DEFAULT_TOLERANCES
    scenes_file = str(ROOT / "models" / "Scenes.mdl")
    out = [Scene("seed", "Seed (`models/SpringMass.mdl`)",
                 str(ROOT / "models" / "SpringMass.mdl"), None, {}, tolerances=tolerances),
           Scene("cloth20", "Cloth 20x20 (`Scenes.Cloth`, N = M = 20)", scenes_file,
                 "Scenes.Cloth", {"N": 20, "M": 20}, tolerances=tolerances)]
    if full:
        out.append(Scene(
            "cloth50", "Cloth 50x50 (`Scenes.Cloth`, N = M = 50)", scenes_file,
            "Scenes.Cloth", {"N": 50, "M": 50}, ("dop853",), (1e-4, 1e-5, 1e-6, 1e-7, 1e-8),
            300.0, "A reduced study: the 50x50 cloth's reference solves take about half a "
            "minute on the development VM, so only dop853 (what `--solver auto` picks for "
            "the cloth) is measured, at rtol 1e-4 to 1e-8, with a 300 s budget per run. "
            "The full comparison of the solvers is the 20x20 cloth's."))
    return out


def study(scene: Scene, budget: float = 20.0, log: object = sys.stderr,
          executor: object = None) -> tuple[Tradeoff, float]:
    """The tradeoff study of ``scene`` (the states compared) and its total seconds; in
    this process, or on ``executor`` (``springc.studies.Executor``)."""
    began = time.perf_counter()
    model = springc.compile_model(scene.file, scene.model, parameters=scene.parameters,
                                  backend=BACKEND)
    print(f"{scene.key}: compiled in {time.perf_counter() - began:.1f} s "
          f"({len(model.states)} states, {BACKEND} backend)", file=sys.stderr, flush=True)
    began = time.perf_counter()
    options = TradeoffOptions(scene.solvers, scene.tolerances, targets=(TARGET,),
                              budget=scene.budget or budget, log=log)  # type: ignore[arg-type]
    result = run_tradeoff(compare_states(model), options, executor)  # type: ignore[arg-type]
    return result, time.perf_counter() - began


def compare_executor(scene: Scene, budget: float, workers: int) -> None:
    """The study of ``scene`` in this process, then on ``workers`` local processes (the
    default of ``springc tradeoff``): both times, and whether the tables are equal
    except the measured times."""
    from dataclasses import replace

    from springc.studies import Executor

    here, serial = study(scene, budget, None)
    there, parallel = study(scene, budget, None, Executor(workers))

    def untimed(result: Tradeoff) -> list[str]:
        return [repr(replace(r, wall_time=0.0, repeats=0))
                for r in (*result.runs, *result.baselines)]

    print(f"{scene.key}: tradeoff in process {serial:.1f} s, on {workers} local "
          f"processes {parallel:.1f} s ({serial / parallel:.2f}x), load average "
          f"{os.getloadavg()[0]:.1f}; tables equal except times: "
          f"{untimed(here) == untimed(there)}")


@dataclass(frozen=True)
class Verdict:
    recommended: str
    seconds: float
    error: float
    default_seconds: float
    default_error: float
    matched: str  # "rtol 1e-08, 1.67 s" or why there is none
    vs_default: float
    vs_matched: float  # NaN: no matched run
    met: bool

    def cells(self) -> tuple[str, ...]:
        reaches = ("reaches it" if self.default_error <= TARGET else "does not reach it")
        vs_default = (f"{self.vs_default:.1f}x" if self.default_error <= TARGET
                      else f"({self.vs_default:.1f}x, default not accurate)")
        vs_matched = "" if self.vs_matched != self.vs_matched else f"{self.vs_matched:.1f}x"
        return (self.recommended, f"{self.seconds:.3g} s", f"{self.error:.1e}",
                f"{self.default_seconds:.3g} s, error {self.default_error:.1e} ({reaches})",
                self.matched, vs_default, vs_matched, "yes" if self.met else "NO")


HEADER = ("recommended for 1e-4", "time", "its error", "scipy default call",
          "scipy RK45 reaching 1e-4", "vs default", "vs RK45 at same error",
          "target met")


def verdict(result: Tradeoff) -> Verdict:
    good = [r for r in result.runs if r.ok and r.max_error <= TARGET]
    default = next(b for b in result.baselines if b.solver == SCIPY_DEFAULT)
    if not good or not default.ok:
        return Verdict("none", float("nan"), float("nan"), default.wall_time,
                       default.max_error, "", float("nan"), float("nan"), False)
    best = min(good, key=lambda r: r.wall_time)
    tightened = [b for b in result.baselines if b.solver == SCIPY_RK45]
    match = next((b for b in tightened if b.ok and b.max_error <= TARGET), None)
    matched = (f"rtol {match.value:.0e}: {match.wall_time:.3g} s" if match else
               "none down to rtol " + (f"{tightened[-1].value:.0e}" if tightened else "?"))
    speedup = default.wall_time / best.wall_time
    met = default.max_error > TARGET or speedup >= SPEEDUP
    return Verdict(f"{best.solver} at {best.label()}", best.wall_time, best.max_error,
                   default.wall_time, default.max_error, matched, speedup,
                   match.wall_time / best.wall_time if match else float("nan"), met)


def markdown(rows: list[tuple[str, Verdict]]) -> str:
    lines = ["| scene | " + " | ".join(HEADER) + " |",
             "| --- | --- | ---: | ---: | --- | --- | ---: | ---: | --- |"]
    lines += ["| " + " | ".join((name, *v.cells())) + " |" for name, v in rows]
    return "\n".join(lines) + "\n"


SEED = ROOT / "models" / "SpringMass.mdl"
VERSUS_TARGET = 10.0


def command_run(src: Path) -> tuple[float, list[str], str]:
    """``springc tradeoff models/SpringMass.mdl`` with ``src`` first on the path: wall
    seconds, the recommendation lines, and how many rows ran on each engine (the old
    table has no engine column: none)."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    began = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "springc", "tradeoff", str(SEED), "-q"],
                          env=env, capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - began
    lines = [line for line in done.stdout.splitlines() if line.startswith("for max error")]
    cells = [line.split() for line in done.stdout.splitlines()]
    counts = {e: sum(len(c) > 3 and c[3] == e for c in cells) for e in ("compiled", "scipy")}
    return seconds, lines, ", ".join(f"{n} {e}" for e, n in counts.items())


def warm(src: Path) -> None:
    """A short study of the seed with ``src``, untimed: its model cache and compiled
    loops are then ready (any edit of springc's code moves the model cache's key)."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    subprocess.run([sys.executable, "-m", "springc", "tradeoff", str(SEED), "-q",
                    "--tolerances", "1e-3", "--steps", "0.01", "--stop", "0.05",
                    "--interval", "0.01", "--repeats", "1"],
                   env=env, capture_output=True, text=True, check=True)


def versus(old: Path) -> None:
    """The seed's whole command: this tree, the old one, this tree again (each tree
    warmed up first)."""
    for src in (ROOT / "src", old):
        warm(src)
    load = os.getloadavg()[0]
    new1, lines, engines = command_run(ROOT / "src")
    print(f"new: {new1:.1f} s ({engines} rows)", file=sys.stderr, flush=True)
    before, old_lines, _ = command_run(old)
    print(f"old: {before:.1f} s", file=sys.stderr, flush=True)
    new2, lines2, _ = command_run(ROOT / "src")
    print(f"new again: {new2:.1f} s", file=sys.stderr, flush=True)
    mean = (new1 + new2) / 2

    def chosen(found: list[str]) -> list[str]:  # "for max error <= 1e-04 the fastest is ..."
        return [re.sub(r" \(.*", "", line) for line in found]

    steady = chosen(lines) == chosen(lines2)
    print(f"springc tradeoff models/SpringMass.mdl: old ({old}) {before:.1f} s, new "
          f"{new1:.1f} s and {new2:.1f} s (mean {mean:.1f} s): {before / mean:.1f}x faster "
          f"(target {VERSUS_TARGET:g}x); load average {load:.1f} -> "
          f"{os.getloadavg()[0]:.1f}; the new runs recommend the same: {steady}; the old "
          f"run the same as they: {chosen(lines) == chosen(old_lines)}")
    for name, found in (("old", old_lines), ("new", lines), ("new again", lines2)):
        for line in found:
            print(f"  {name}: {line}")
    if not (steady and before / mean >= VERSUS_TARGET):
        sys.exit(1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="fewer tolerances")
    parser.add_argument("--full", action="store_true", help="add the 50x50 cloth")
    parser.add_argument("--budget", type=float, default=20.0, help="seconds per run")
    parser.add_argument("--executor", type=int, metavar="WORKERS",
                        help="only time the seed's study in process and on WORKERS local "
                        "processes (springc tradeoff's default executor)")
    parser.add_argument("--versus", type=Path, metavar="OLD_SRC",
                        help="only time the seed's whole command against the sources "
                        "of an older springc (see the module text)")
    args = parser.parse_args()
    if args.versus:
        versus(args.versus)
        return
    if args.executor:
        compare_executor(scenes(args.quick)[0], args.budget, args.executor)
        return
    rows = []
    for scene in scenes(args.quick, args.full):
        result, seconds = study(scene, args.budget)
        print(f"{scene.key}: study took {seconds:.0f} s", file=sys.stderr)
        for line in recommendations(result):
            print(f"{scene.key}: {line}", file=sys.stderr)
        rows.append((scene.title, verdict(result)))
    print(markdown(rows))
    if not all(v.met for _, v in rows):
        sys.exit(1)


if __name__ == "__main__":
    main()
