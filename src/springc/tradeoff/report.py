"""Reports of a study: Tradeoff -> recommendation lines, text or Markdown table, CSV.

The recommendation reads ``for max error <= 1e-04 the fastest is dop853 at rtol 1e-06
(0.12 s, 3.4x faster than scipy's default RK45 at rtol 1e-3 which reaches 2.1e-02)``,
followed, when scipy's default call does not reach the error, by the rtol that
``solve_ivp`` RK45 needs for it.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from pathlib import Path
from typing import IO

from ..errors import Note, printable
from ..fileio import atomic_write
from .model import (
    BUDGET_SKIP,
    COST_SKIP,
    CSV_COLUMNS,
    PROBE_SKIP,
    SCIPY_DEFAULT,
    SCIPY_RK45,
    Run,
    Tradeoff,
)


def _times(seconds: float, other: float) -> str:
    ratio = other / seconds
    return f"{ratio:.1f}x faster than" if ratio >= 1 else f"{1 / ratio:.1f}x slower than"


def recommend(runs: Sequence[Run], baselines: Sequence[Run], target: float) -> str:
    """``for max error <= 1e-04 the fastest is dop853 at rtol 1e-06 (0.12 s); scipy's
    RK45 needs rtol 1e-07 for it (0.43 s: dop853 is 3.6x faster); scipy's default RK45
    (rtol 1e-3) reaches only 2.1e-02, 210x the target``: compared first with a scipy
    run that meets the target, the default's miss said after; where the default meets
    the target, ``(0.12 s, 3.4x faster than scipy's default RK45 at rtol 1e-3, which
    reaches 1.0e-05)``."""
    head = f"for max error <= {target:.0e}"
    good = [r for r in runs if r.ok and r.max_error <= target]
    if not good:
        done = [r for r in runs if r.ok]
        if not done:
            return f"{head} no setting succeeded"
        best = min(done, key=lambda r: r.max_error)
        return (f"{head} no setting is accurate enough (the most accurate is "
                f"{best.solver} at {best.label()}: {best.max_error:.1e})")
    fast = min(good, key=lambda r: r.wall_time)
    text = f"{head} the fastest is {fast.solver} at {fast.label()} ({fast.wall_time:.3g} s"
    default = next((b for b in baselines if b.solver == SCIPY_DEFAULT), None)
    if default is not None and default.ok and default.max_error <= target:
        return (text + f", {_times(fast.wall_time, default.wall_time)} scipy's default "
                f"RK45 at rtol 1e-3, which reaches {default.max_error:.1e})")
    text += ")"
    tightened = [b for b in baselines if b.solver == SCIPY_RK45]
    match = next((b for b in tightened if b.ok and b.max_error <= target), None)
    if match is not None:
        text += (f"; scipy's RK45 needs rtol {match.value:.0e} for it "
                 f"({match.wall_time:.3g} s: {fast.solver} is "
                 f"{_times(fast.wall_time, match.wall_time).removesuffix(' than')})")
    elif tightened:
        last = tightened[-1]
        text += (f"; scipy's RK45 does not reach it down to rtol {last.value:.0e}"
                 + ("" if last.ok else f" ({last.status})"))
    if default is not None and default.ok:
        text += (f"; scipy's default RK45 (rtol 1e-3) reaches only "
                 f"{default.max_error:.1e}, {default.max_error / target:.3g}x the target")
    elif default is not None:
        text += f"; scipy's default RK45 (rtol 1e-3): {default.status}"
    return text


def recommendations(tradeoff: Tradeoff) -> list[str]:
    """One line per target of the study (:func:`recommend`)."""
    return [recommend(tradeoff.runs, tradeoff.baselines, t) for t in tradeoff.targets]


# ------------------------------------------------------------------ table

def table_rows(tradeoff: Tradeoff) -> list[tuple[str, ...]]:
    """The CSV rows (springc runs, then the scipy baselines), as text."""
    def num(x: float, fmt: str) -> str:
        return "" if not math.isfinite(x) else format(x, fmt)

    rows: list[tuple[str, ...]] = []
    for r in (*tradeoff.runs, *tradeoff.baselines):
        rows.append((r.solver, r.setting, repr(r.value), num(r.wall_time, ".6g"),
                     str(r.repeats), "" if r.steps < 0 else str(r.steps),
                     "" if r.rhs_evaluations < 0 else str(r.rhs_evaluations),
                     "" if r.jacobian_evaluations < 0 else str(r.jacobian_evaluations),
                     num(r.max_error, ".3e"), num(r.rms_error, ".3e"), r.status,
                     num(r.energy_drift, ".3e"), r.engine))
    return rows


def write_table(tradeoff: Tradeoff, f: IO[str]) -> None:
    """The table as CSV (:data:`CSV_COLUMNS`, then :func:`table_rows`)."""
    writer = csv.writer(f, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    writer.writerows(table_rows(tradeoff))


def write_table_csv(tradeoff: Tradeoff, path: str | Path) -> None:
    """The table as a CSV file (written atomically)."""
    with atomic_write(path, "w") as f:
        write_table(tradeoff, f)


def format_table(tradeoff: Tradeoff, markdown: bool = False) -> str:
    """The table as aligned text (or a Markdown table)."""
    head: tuple[str, ...] = ("solver", "setting", "engine", "time s", "steps", "RHS",
                             "Jacobians", "max error", "RMS error", "status")
    energy = tradeoff.energy is not None
    if energy:
        head = (*head[:-1], f"{tradeoff.energy} drift", head[-1])
    body = []
    for r in (*tradeoff.runs, *tradeoff.baselines):
        if skipped(r):  # said in a note (skipped_notes); the CSV table has their rows
            continue
        ok = r.ok
        body.append((r.solver, r.label(), r.engine, f"{r.wall_time:.3g}" if ok else "",
                     str(r.steps) if ok and r.steps >= 0 else "",
                     str(r.rhs_evaluations) if ok else "",
                     str(r.jacobian_evaluations) if ok else "",
                     f"{r.max_error:.1e}" if ok else "", f"{r.rms_error:.1e}" if ok else "",
                     *([f"{r.energy_drift:.1e}" if ok else ""] if energy else []), r.status))
    if markdown:
        right = "| --- | --- | --- |" + " ---: |" * (len(head) - 4) + " --- |"
        return "\n".join(["| " + " | ".join(head) + " |", right,
                          *("| " + " | ".join(row) + " |" for row in body)]) + "\n"
    widths = [max(len(row[i]) for row in (head, *body)) for i in range(len(head))]
    left = (0, 1, 2, len(head) - 1)
    lines = ["  ".join(c.ljust(w) if i in left else c.rjust(w)
                       for i, (c, w) in enumerate(zip(row, widths))).rstrip()
             for row in (head, *body)]
    return "\n".join(lines) + "\n"


def summary(tradeoff: Tradeoff) -> str:
    """Reference line, table, then one recommendation per target."""
    ref = tradeoff.reference
    lines = [f"{printable(tradeoff.model)}: {tradeoff.states} states, {len(ref.time)} "
             f"output times, {len(ref.names)} variables compared",
             f"reference: {ref.description}", "", format_table(tradeoff).rstrip(), ""]
    for note in (*skipped_notes(tradeoff), unresolved_note(tradeoff)):
        if note is not None:
            lines += [f"note: {note.message}", ""]
    return "\n".join(lines + recommendations(tradeoff)) + "\n"


def unresolved_note(tradeoff: Tradeoff) -> Note | None:
    """A note when some errors are below what the reference can resolve."""
    agreement = tradeoff.reference.agreement
    if not math.isfinite(agreement):
        return None
    low = [r for r in tradeoff.runs if r.ok and r.max_error < 10 * agreement]
    if not low:
        return None
    return Note(f"{len(low)} runs have max errors below 10x the reference agreement "
                f"({10 * agreement:.0e}); those errors are not resolved")


SKIPS = (COST_SKIP, PROBE_SKIP, BUDGET_SKIP)
"""The statuses of settings not run: a note names them, the printed table leaves them
out, the CSV table (``-o``) keeps a row for each."""


def skipped(run: Run) -> bool:
    """Whether ``run`` is a setting that was not run (:data:`SKIPS`)."""
    return run.status.startswith(SKIPS)


def skipped_notes(tradeoff: Tradeoff) -> list[Note]:
    """Notes naming the settings not run (the CSV table has a row for each), by
    reason."""
    kinds = ((COST_SKIP, f"a looser setting of the same solver took over "
              f"{tradeoff.cost_limit}, and tighter settings cost more (--cost-limit)"),
             (PROBE_SKIP, "springc's compiled rk45, the same method taking the same steps, "
              "does not reach the target there (its error is in the CSV table, -o)"),
             (BUDGET_SKIP, "a looser setting of the same solver was over the budget "
              "(--budget)"))
    notes = []
    for start, reason in kinds:
        per: dict[str, list[Run]] = {}
        for r in (*tradeoff.runs, *tradeoff.baselines):
            if r.status.startswith(start):
                per.setdefault(r.solver, []).append(r)
        if per:
            count = sum(len(v) for v in per.values())
            named = ", ".join(f"{solver} {run_label(runs)}" for solver, runs in per.items())
            notes.append(Note(f"{count} setting{'s were' if count > 1 else ' was'} not run "
                              f"({named}): {reason}"))
    return notes


def run_label(runs: Sequence[Run]) -> str:
    """``rtol 1e-04 to 1e-10`` or ``rtol 1e-04``: the settings of ``runs``."""
    first, last = runs[0].label(), runs[-1].label()
    return first if len(runs) == 1 else f"{first} to {last.split(' ', 1)[1]}"
