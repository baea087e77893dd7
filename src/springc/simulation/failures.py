"""Failure text of a simulation run: the error that stops the step loop, the states
at fault, where in the generated code an operation failed, and what to try."""

from __future__ import annotations

import linecache
import math
import traceback

import numpy as np

from ..errors import Note, SimulationError
from ..ir.dae import derivative_name
from .solver_names import FIXED_STEP, IMPLICIT_SOLVERS


class Stop(Exception):
    """Raised inside the right-hand side to end the integration with an error."""

    def __init__(self, error: SimulationError) -> None:
        super().__init__(error.message)
        self.error = error


def format_time(t: float) -> str:
    return f"{t:.9g}"


def remedy(solver: str) -> str:
    if solver in FIXED_STEP:
        return "reduce --step or use --solver radau"
    if solver in IMPLICIT_SOLVERS:
        return ("check the parameters and start values near that time (a spring of zero "
                "length? a mass of zero?), or try a tighter --rtol")
    return "the system looks stiff or unstable: try --solver radau (or bdf)"


def state_notes(names: tuple[str, ...], x: np.ndarray, dx: np.ndarray | None,
                 limit: int = 4) -> list[Note]:
    bad = [i for i in range(len(x)) if not math.isfinite(x[i])]
    if dx is not None:
        bad += [i for i in range(len(dx)) if not math.isfinite(dx[i]) and i not in bad]
    if not bad and dx is not None:
        scale = np.abs(dx) / (1e-300 + np.abs(x) + 1.0)
        bad = [int(i) for i in np.argsort(-scale)[:limit]]
    elif not bad:
        bad = list(range(min(len(x), limit)))
    notes = [Note(f"{names[i]} = {x[i]:.6g}" + (f", {derivative_name(names[i])} = {dx[i]:.6g}"
                                                 if dx is not None else ""))
             for i in bad[:limit]]
    if len(bad) > limit:
        notes.append(Note(f"... and {len(bad) - limit} more states"))
    return notes


def code_location(err: BaseException, path: str) -> str | None:
    """The flat name and source location of the generated line that raised ``err``."""
    frames = [f for f in traceback.extract_tb(err.__traceback__) if f.filename == path]
    if not frames:
        return None
    lineno = frames[-1].lineno or 0
    for n in range(lineno, max(0, lineno - 200), -1):
        line = linecache.getline(path, n).strip()
        if "  # " in line:
            name, _, where = line.split("  # ", 1)[1].strip().partition("  ")
            return f"{name} ({where})" if where else name
        if line.startswith("# "):
            return line[2:].strip()
        if line.startswith("def "):
            break
    return None
