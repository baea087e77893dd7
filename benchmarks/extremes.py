"""The "Extremes" table of docs/accuracy.md: every extreme case with every solver.

    PYTHONPATH=src python benchmarks/extremes.py [--quick]

Each row: case, solver (``auto -> chosen``), max error against the closed form or
reference of ``tests/extremes/cases.py`` (or the error message springc stopped with),
simulation wall time (compilation excluded; best of two runs), and for ``auto`` the
ratio of its time to that of the fastest solver within the case's error bound.
Explicit solvers are not run where stability alone needs more than ~10^6 steps
(``rho * T > 3e6``), nor implicit ones on the 10^4-period run (minutes).
"""

from __future__ import annotations

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
)
from springc.errors import SpringcError  # noqa: E402
from springc.results import SimulationResult  # noqa: E402

ADAPTIVE = ("dop853", "rk45", "radau", "bdf", "lsoda")
EXPLICIT = ("dop853", "rk45")
Error = Callable[[SimulationResult], float]


def _run(model: springc.CompiledModel, solver: str, error: Error, repeat: int,
         **kwargs: object) -> tuple[str, float, str]:
    """(solver shown, time or nan, error text)."""
    best = math.inf
    for _ in range(repeat):
        try:
            result = springc.simulate(model, solver=solver, **kwargs)  # type: ignore[arg-type]
        except SpringcError as err:
            return solver, math.nan, f"error: {err.message}"
        best = min(best, result.stats.wall_time)
    shown = f"auto -> {result.stats.solver}" if solver == "auto" else solver
    return shown, best, f"{error(result):.1e}"


def _rows(case: str, model: springc.CompiledModel, solvers: list[str], error: Error,
          bound: float, repeat: int, step: float | None = None, **kwargs: object
          ) -> list[tuple[str, str, str, str, str]]:
    runs = []
    for solver in solvers:
        extra = {"step": step} if solver in ("verlet", "symplectic-euler", "rk4") else {}
        runs.append(_run(model, solver, error, repeat, **kwargs, **extra))
    ok = [t for (s, t, e) in runs if not math.isnan(t) and not e.startswith("error")
          and float(e) <= bound and not s.startswith("auto")]
    rows = []
    for shown, seconds, err in runs:
        ratio = ""
        if shown.startswith("auto") and ok and not math.isnan(seconds):
            ratio = f"{seconds / min(ok):.2f}"
        rows.append((case, shown, err, "" if math.isnan(seconds) else f"{seconds:.3f}",
                     ratio))
    return rows


def main() -> None:
    quick = "--quick" in sys.argv
    repeat = 1 if quick else 2
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-ext-"))
    path = Path(tempfile.mkdtemp()) / "extremes.mdl"
    path.write_text(MODELS)
    harm = springc.compile_model(path, "Harmonic")
    pair = springc.compile_model(path, "StiffPair")
    through = springc.compile_model(path, "Through")
    springc.simulate(harm, stop=0.1)  # warm-up: imports
    rows: list[tuple[str, str, str, str, str]] = []

    for k in STIFFNESSES:
        rho_t = math.sqrt(1 + 2 * k) * 10
        solvers = ["auto"] + [s for s in ADAPTIVE if not (s in EXPLICIT and rho_t > 3e6)]
        rows += _rows(f"stiffness k = {k:g}, m = 1 (bound 2e-5)", pair, solvers,
                      lambda r, k=k: float(np.max(np.abs(r["x1"] - stiff_pair(r.time, k)))),
                      2e-5, repeat, parameters={"k": k})
    for m in MASSES:
        bound = 2e-3 if m < 1 else 5e-6
        step = min(2 * math.pi * math.sqrt(m) / 200, 10 / 500)
        rows += _rows(f"mass m = {m:g}, k = 1 (bound {bound:g})", harm,
                      ["auto", *ADAPTIVE, "verlet"],
                      lambda r, m=m: float(np.max(np.abs(r["x"] - harmonic(r.time, m=m)))),
                      bound, repeat, step=step, parameters={"m": m})

    k = (2 * math.pi) ** 2
    periods = 1000 if quick else 10_000

    def drift(r: SimulationResult) -> float:
        e = 0.5 * r["v"] ** 2 + 0.5 * k * r["x"] ** 2
        return float(np.max(np.abs(e - e[0])) / e[0])

    rows += _rows(f"{periods} periods: relative energy error (bound 0.02)", harm,
                  ["auto", "dop853", "rk45", "verlet", "symplectic-euler", "rk4"], drift,
                  0.02, 1, step=1 / 25, parameters={"k": k}, stop=float(periods),
                  interval=periods / 500)
    rows += _rows("2D spring through length 0 (bound 1e-4)", through,
                  ["auto", *ADAPTIVE, "verlet"],
                  lambda r: float(np.max(np.abs(r["pos[1]"] - harmonic(r.time, k=100)))),
                  1e-4, repeat, step=1e-3)
    rows += _rows("2D spring starting at length 0", through, ["auto", "verlet"],
                  lambda r: 0.0, 0.0, 1, step=1e-3, parameters={"r": 0.0})
    n = 1000 if quick else 10_000
    chain = springc.compile_model(path, "BigChain", outputs=["x[1]", "x[2]"],
                                  parameters={"N": n} if quick else None)
    rows += _rows(f"{n} masses, 1 s (bound 1e-4)", chain, ["auto", "dop853", "bdf", "radau"],
                  lambda r: float(np.max(np.abs(r.values - big_chain(r.time, n)))), 1e-4,
                  1, stop=1.0, interval=0.1)
    rows += _rows("at equilibrium, k = 1e12", harm, ["auto", "dop853", "radau", "verlet"],
                  lambda r: float(np.max(np.abs(r.values))), 0.0, repeat, step=1e-3,
                  parameters={"a": 0.0, "k": 1e12}, stop=1e-3)
    rows += _rows("zero-length span", harm, ["auto"], lambda r: 0.0, 0.0, 1,
                  start=1.0, stop=1.0)
    for assignment in ({"m": 0.0}, {"k": math.inf}, {"k": 1e300}, {"a": math.inf}):
        name, value = next(iter(assignment.items()))
        rows += _rows(f"--set {name}={value:g}", harm, ["auto"], lambda r: 0.0, 0.0, 1,
                      parameters=assignment)

    print("| case | solver | max error (or the error) | time s | auto / best |")
    print("| --- | --- | --- | ---: | ---: |")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
