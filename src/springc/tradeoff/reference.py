"""References for :mod:`springc.tradeoff`: a user CSV, or a tight solve verified by a
second method -> Reference.

The tight reference is springc's ``dop853`` at rtol :data:`~springc.tradeoff.model.REFERENCE_RTOL`
(atol in the same ratio to rtol as the simulator's default); the check is scipy's
VODE in Adams mode (variable order up to 12, functional iteration: no Jacobian, so
it suits models of any size) on the same generated right-hand side at the same
tolerances. Different method families (one-step Runge-Kutta vs multistep Adams) are
unlikely to share an error, so their agreement bounds the reference's own error.
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import IO

import numpy as np

from ..errors import Note, SimulationError
from ..fileio import atomic_write
from ..pipeline import ModuleKind
from ..simulation import EXPLICIT, RACE_IMPLICIT, simulate_model
from .model import REFERENCE_RTOL, Reference, TradeoffError
from .setup import StudySetup, relative_errors, scipy_outputs, variable_scales


def _adams(setup: StudySetup, rtol: float, atol: float) -> np.ndarray:
    """The states on the grid by VODE Adams (raises SimulationError if it fails)."""
    from scipy.integrate import ode

    mod, p, grid = setup.model.module, setup.p, setup.grid
    z = np.asarray(mod.guesses(p), dtype=float)
    solver = ode(lambda t, x: mod.rhs(t, x, p, z))
    solver.set_integrator("vode", method="adams", rtol=rtol, atol=atol, nsteps=10**9,
                          with_jacobian=False)
    solver.set_initial_value(setup.x0, grid[0])
    states = np.empty((len(grid), len(setup.x0)))
    states[0] = setup.x0
    with np.errstate(all="ignore"):
        for i in range(1, len(grid)):
            states[i] = solver.integrate(grid[i])
            if not solver.successful():
                raise SimulationError(f"the check of the reference (VODE Adams) failed at "
                                      f"time {grid[i]:g} (code {solver.get_return_code()})")
    return states


def tight_reference(setup: StudySetup, target: float, rtol: float = REFERENCE_RTOL
                    ) -> Reference:
    """dop853 at ``rtol``, checked by VODE Adams; refused if they differ by more than
    ``target`` (the smallest error the study is asked about)."""
    atol = rtol * setup.atol_ratio
    began = time.perf_counter()
    try:
        primary = simulate_model(setup.model, setup.sim_options(EXPLICIT, rtol))
    except SimulationError as err:
        raise TradeoffError(f"the reference solve (dop853 at rtol {rtol:.0e}) failed: "
                            f"{err.message}", notes=err.notes,
                            hint="give a reference trajectory with --reference") from None
    first = time.perf_counter() - began
    began = time.perf_counter()
    checker = "VODE Adams"
    if setup.model.kind == ModuleKind.HYBRID:
        # a hybrid model: the check locates the events too (simulation/events.py)
        checker = "radau with event location"
        check = simulate_model(setup.model, setup.sim_options(RACE_IMPLICIT, rtol)).values
    else:
        check = scipy_outputs(setup.model, setup.p, setup.grid, _adams(setup, rtol, atol))
    second = time.perf_counter() - began
    scales = variable_scales(primary.values, setup.units)
    agreement, _ = relative_errors(check, primary.values, scales)
    description = (f"dop853 ({primary.stats.engine}) at rtol {rtol:.0e} ({first:.3g} s), "
                   f"verified by {checker} at "
                   f"rtol {rtol:.0e} ({second:.3g} s): they agree to {agreement:.1e} "
                   "(max relative difference on the grid)")
    if not agreement <= target:
        raise TradeoffError(
            f"the reference is not accurate enough: dop853 and {checker} at rtol "
            f"{rtol:.0e} differ by {agreement:.1e}, more than the target error {target:.0e}",
            notes=[Note("errors smaller than the disagreement cannot be measured")],
            hint="give a reference trajectory with --reference, or a larger --max-error")
    return Reference(primary.time, primary.names, primary.values, description, agreement)


def read_reference(path: str, grid: np.ndarray, names: Sequence[str]) -> Reference:
    """A CSV written by ``springc simulate -o`` (header ``time,<names>``) on ``grid``;
    every compared name must be a column (others are ignored)."""
    def fail(message: str, *notes: str) -> TradeoffError:
        return TradeoffError(f"{path}: {message}", notes=[Note(n) for n in notes],
                             hint="write it with springc simulate -o on the same model, "
                             "times and --vars")

    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError) as err:
        raise fail(f"cannot read the reference: {err}") from None
    if not rows or not rows[0] or rows[0][0].strip() != "time":
        raise fail("the first line must be a header starting with 'time'")
    header = [h.strip() for h in rows[0]]
    missing = [n for n in names if n not in header]
    if missing:
        shown = ", ".join(missing[:5]) + (f", ... ({len(missing)} in all)"
                                          if len(missing) > 5 else "")
        raise fail(f"missing columns: {shown}",
                   f"the columns are: {', '.join(header[1:6])}"
                   + (", ..." if len(header) > 6 else ""))
    data = np.empty((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:]):
        if len(row) != len(header):
            raise fail(f"line {i + 2} has {len(row)} fields, the header {len(header)}")
        try:
            data[i] = [float(x) for x in row]
        except ValueError:
            raise fail(f"line {i + 2} holds a value that is not a number") from None
    if len(data) != len(grid):
        raise fail(f"{len(data)} output times, the study's grid has {len(grid)}",
                   f"the grid: {grid[0]:g} to {grid[-1]:g} s, every "
                   f"{(grid[-1] - grid[0]) / max(1, len(grid) - 1):g} s")
    tol = 1e-9 * max(1.0, float(np.max(np.abs(grid))))
    off = np.flatnonzero(np.abs(data[:, 0] - grid) > tol)
    if len(off):
        i = int(off[0])
        raise fail(f"line {i + 2} is at time {float(data[i, 0])!r}, the grid at "
                   f"{float(grid[i])!r}",
                   f"{len(off)} times differ")
    columns = [header.index(n) for n in names]
    values = data[:, columns]
    if not np.isfinite(values).all():
        raise fail("the reference holds non-finite values")
    return Reference(grid.copy(), tuple(names), values, f"{path} (not verified)", math.nan)


def write_reference_csv(ref: Reference, f: IO[str]) -> None:
    """The reference as CSV (header ``time,<names>``, full precision): reusable with
    ``--reference``."""
    writer = csv.writer(f, lineterminator="\n")
    writer.writerow(["time", *ref.names])
    for t, row in zip(ref.time.tolist(), ref.values.tolist()):
        writer.writerow([repr(t), *map(repr, row)])


def write_reference(ref: Reference, path: str | Path) -> None:
    """The reference as a CSV file (written atomically)."""
    with atomic_write(path, "w") as f:
        write_reference_csv(ref, f)
