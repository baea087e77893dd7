"""The "Extremes" table of docs/accuracy.md: every extreme case with every solver.

    PYTHONPATH=src python benchmarks/extremes.py [--quick]

Each row: case, solver (``auto -> chosen``), max error against the closed form or
reference of ``tests/extremes/cases.py`` (or the error message springc stopped with),
simulation wall time (compilation excluded: every solver runs once untimed on each
model first, over a thousandth of the span, numba compiling the compiled engine's loops
for it; best of two runs, of up to seven for runs under a second; no error estimate),
all at the default setting (rtol 1e-6). For ``auto``: the ratio of its time to that of
the fastest run *reaching auto's error*, over every solver of the case at every tolerance 1e-3 ...
1e-12 (fixed-step solvers: the case's step halved up to five times), each solver
swept from loose to tight until it reaches that error or takes longer than auto
(solvers over 20x slower than auto at their default are not swept).
Explicit solvers are not run where stability alone needs more than ~10^6 steps
(``rho * T > 3e6``), nor implicit ones on the 10^4-period run (minutes), nor bdf and
lsoda on the uneven pair at k = 1e12 (hours, see :data:`BDF_FAMILY`).
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import springc  # noqa: E402
from extremes.cases import (  # noqa: E402
    MASSES,
    MODELS,
    STIFFNESSES,
    big_chain,
    harmonic,
    stiff_pair,
    uneven_pair,
)
from springc.errors import SpringcError  # noqa: E402
from springc.simulation.results import SimulationResult  # noqa: E402

ADAPTIVE = ("dop853", "rk45", "radau", "bdf", "lsoda")
EXPLICIT = ("dop853", "rk45")
FIXED = ("verlet", "symplectic-euler", "rk4")
BDF_FAMILY = ("bdf", "lsoda")
"""Left out on the uneven pair at k = 1e12: their higher orders are not stable near the
imaginary axis, so they resolve the excited fast mode (bdf: over 10^7 steps)."""
SLOW = 5.0
"""A run over 5 s is not repeated."""
SWEEP_LIMIT = 20.0
INTERLEAVED = 5
"""auto and the best run at its error are timed again in turns, best of 5 each, for the
ratio (each timed alone, minutes apart, they met different loads)."""
"""A solver 20x slower than auto at its default setting is not swept."""
Error = Callable[[SimulationResult], float]


WARM: set[tuple[int, str]] = set()
"""(model, solver) pairs run once already: numba compiles the compiled engine's loops
for each model's functions on their first run (or loads them from its cache), which is
compilation, not simulation time."""


def _warm(model: springc.CompiledModel, solver: str, **kwargs: object) -> None:
    """One untimed run of ``solver`` (for auto: of its dop853 and radau too) on
    ``model`` over the first thousandth of the span, the first time the pair is timed."""
    start = float(kwargs.pop("start", 0.0))  # type: ignore[arg-type]
    stop = float(kwargs.pop("stop", 10.0))  # type: ignore[arg-type]
    kwargs.pop("interval", None)
    for name in (solver, *(("dop853", "radau") if solver == "auto" else ())):
        if (id(model), name) in WARM:
            continue
        WARM.add((id(model), name))
        with contextlib.suppress(SpringcError):
            springc.simulate(model, solver=name, start=start,  # type: ignore[arg-type]
                             stop=start + (stop - start) / 1000, **kwargs)


def _run(model: springc.CompiledModel, solver: str, error: Error, repeat: int,
         **kwargs: object) -> tuple[str, float, str]:
    """(solver shown, time or nan, error text)."""
    kwargs.setdefault("error_control", "off")  # the solver's own setting and time
    _warm(model, solver, **kwargs)
    best, spent, runs = math.inf, 0.0, 0
    while runs < repeat or (runs < 7 and spent < 1.0):  # short runs: best of up to 7
        try:
            result = springc.simulate(model, solver=solver, **kwargs)  # type: ignore[arg-type]
        except SpringcError as err:
            return solver, math.nan, f"error: {err.message}"
        seconds = result.stats.wall_time
        best, spent, runs = min(best, seconds), spent + seconds, runs + 1
        if best > SLOW:
            break
    shown = f"auto -> {result.stats.solver}" if solver == "auto" else solver
    return shown, best, f"{error(result):.1e}"


def _settings(solver: str, step: float | None) -> list[dict[str, float]]:
    """Loose to tight: rtol for the adaptive solvers, halved steps for the fixed ones."""
    if solver in FIXED:
        return [{"step": step / 2**i} for i in range(6)]  # type: ignore[operator]
    return [{"rtol": 10.0**-e} for e in range(3, 13)]


def _best_at(target: float, limit: float, model: springc.CompiledModel, solver: str,
             error: Error, repeat: int, step: float | None, **kwargs: object
             ) -> tuple[float, str, dict[str, float]] | None:
    """The fastest run of ``solver`` whose error is within ``target``, trying its
    settings from loose to tight until one reaches it or one takes over ``limit``."""
    for setting in _settings(solver, step):
        _, seconds, err = _run(model, solver, error, repeat, **kwargs, **setting)
        if math.isnan(seconds):
            continue
        if float(err) <= target:
            name, value = next(iter(setting.items()))
            return seconds, f"{solver} {name} {value:.3g}", setting
        if seconds > limit:
            return None
    return None


def _interleaved(model: springc.CompiledModel, runs: list[dict[str, object]]
                 ) -> list[float]:
    """The best of :data:`INTERLEAVED` rounds of each run of ``runs`` (simulate's
    keywords), one after the other in each round: a change of load on a shared machine
    hits them alike."""
    best = [math.inf] * len(runs)
    for _ in range(INTERLEAVED):
        for i, keywords in enumerate(runs):
            result = springc.simulate(model, **keywords)  # type: ignore[arg-type]
            best[i] = min(best[i], result.stats.wall_time)
    return best


def _rows(case: str, model: springc.CompiledModel, solvers: list[str], error: Error,
          repeat: int, step: float | None = None, **kwargs: object
          ) -> list[tuple[str, ...]]:
    """Every solver at its default setting; for auto, the ratio of its time to that of
    the fastest solver (at any tolerance or step) reaching auto's error."""
    print(f"{case} ...", file=sys.stderr, flush=True)
    runs = []
    for solver in solvers:
        extra = {"step": step} if solver in FIXED else {}
        runs.append((solver, *_run(model, solver, error, repeat, **kwargs, **extra)))
    rows = [(case, shown, err, "" if math.isnan(t) else f"{t:.3f}", "")
            for _, shown, t, err in runs]
    auto = next(((t, err) for s, _, t, err in runs if s == "auto"), None)
    if auto is None or math.isnan(auto[0]):
        return rows
    auto_time, target = auto[0], max(float(auto[1]), 1e-14)
    best, label = auto_time, "auto"
    winner: dict[str, object] = {}
    for solver, _, seconds, _err in runs:
        if solver == "auto" or math.isnan(seconds) or seconds > SWEEP_LIMIT * auto_time:
            continue
        found = _best_at(target, auto_time, model, solver, error, repeat, step, **kwargs)
        if found and found[0] < best:
            best, label, setting = found
            winner = {"solver": solver, **setting}
    if winner:
        plain = {"error_control": "off", **kwargs}
        auto_time, best = _interleaved(model, [{"solver": "auto", **plain},
                                               {**plain, **winner}])
    index = [s for s, *_ in runs].index("auto")
    rows[index] = (*rows[index][:4], f"{auto_time / best:.2f} ({label}: {best:.3f} s)")
    return rows


def _positions_error(result: SimulationResult, k: float) -> float:
    positions = np.column_stack([result["x1"], result["x2"]])
    return float(np.max(np.abs(positions - uneven_pair(result.time, k)[:, :2])))


def main() -> None:
    print(table("--quick" in sys.argv))
    sys.stdout.flush()


def table(quick: bool = False) -> str:
    """The markdown table of every case (also used by ``accuracy.py --extremes``)."""
    repeat = 1 if quick else 2
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-ext-"))
    path = Path(tempfile.mkdtemp()) / "extremes.mdl"
    path.write_text(MODELS)
    harm = springc.compile_model(path, "Harmonic")
    pair = springc.compile_model(path, "StiffPair")
    through = springc.compile_model(path, "Through")
    springc.simulate(harm, stop=0.1)  # warm-up: imports
    rows: list[tuple[str, ...]] = []

    for k in STIFFNESSES:
        rho_t = math.sqrt(1 + 2 * k) * 10
        solvers = ["auto"] + [s for s in ADAPTIVE if not (s in EXPLICIT and rho_t > 3e6)]
        rows += _rows(f"stiffness k = {k:g}, m = 1 (bound 2e-5)", pair, solvers,
                      lambda r, k=k: float(np.max(np.abs(r["x1"] - stiff_pair(r.time, k)))),
                      repeat, parameters={"k": k})
    for k in STIFFNESSES[1:]:
        rho_t = math.sqrt(3 + 2 * k) * 10
        solvers = ["auto"] + [s for s in ADAPTIVE if not (s in EXPLICIT and rho_t > 3e6)
                              and not (s in BDF_FAMILY and k > 1e8)]
        rows += _rows(f"uneven walls, k = {k:g} (bound 2e-5)", pair, solvers,
                      lambda r, k=k: _positions_error(r, k), repeat,
                      parameters={"k": k, "k2": 2.0})
    for m in MASSES:
        bound = 2e-3 if m < 1 else 5e-6
        step = min(2 * math.pi * math.sqrt(m) / 200, 10 / 500)
        rows += _rows(f"mass m = {m:g}, k = 1 (bound {bound:g})", harm,
                      ["auto", *ADAPTIVE, "verlet"],
                      lambda r, m=m: float(np.max(np.abs(r["x"] - harmonic(r.time, m=m)))),
                      repeat, step=step, parameters={"m": m})

    k = (2 * math.pi) ** 2
    periods = 1000 if quick else 10_000

    def drift(r: SimulationResult) -> float:
        e = 0.5 * r["v"] ** 2 + 0.5 * k * r["x"] ** 2
        return float(np.max(np.abs(e - e[0])) / e[0])

    rows += _rows(f"{periods} periods: relative energy error (bound 0.02)", harm,
                  ["auto", "dop853", "rk45", "verlet", "symplectic-euler", "rk4"], drift,
                  1, step=1 / 25, parameters={"k": k}, stop=float(periods),
                  interval=periods / 500)
    rows += _rows("2D spring through length 0 (bound 1e-4)", through,
                  ["auto", *ADAPTIVE, "verlet"],
                  lambda r: float(np.max(np.abs(r["pos[1]"] - harmonic(r.time, k=100)))),
                  repeat, step=1e-3)
    rows += _rows("2D spring starting at length 0", through, ["auto", "verlet"],
                  lambda r: 0.0, 1, step=1e-3, parameters={"r": 0.0})
    n = 1000 if quick else 10_000
    chain = springc.compile_model(path, "BigChain", outputs=["x[1]", "x[2]"],
                                  parameters={"N": n} if quick else None)
    rows += _rows(f"{n} masses, 1 s (bound 1e-4)", chain, ["auto", "dop853", "bdf", "radau"],
                  lambda r: float(np.max(np.abs(r.values - big_chain(r.time, n)))),
                  1, stop=1.0, interval=0.1)
    rows += _rows("at equilibrium, k = 1e12", harm, ["auto", "dop853", "radau", "verlet"],
                  lambda r: float(np.max(np.abs(r.values))), repeat, step=2e-6,
                  parameters={"a": 0.0, "k": 1e12}, stop=1e-3)  # the output interval
    rows += _rows("zero-length span", harm, ["auto"], lambda r: 0.0, 1,
                  start=1.0, stop=1.0)
    for assignment in ({"m": 0.0}, {"k": math.inf}, {"k": 1e300}, {"a": math.inf}):
        name, value = next(iter(assignment.items()))
        rows += _rows(f"--set {name}={value:g}", harm, ["auto"], lambda r: 0.0, 1,
                      parameters=assignment)

    lines = ["| case | solver | max error (or the error) | time s | "
             "auto / best (best at auto's error) |", "| --- | --- | --- | ---: | --- |"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
