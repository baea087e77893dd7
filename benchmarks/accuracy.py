"""Regenerate ``docs/accuracy.md`` and its work-precision plots.

    PYTHONPATH=src python benchmarks/accuracy.py [--quick] [--full] [--extremes] [--budget S]

Runs the tradeoff studies of ``bench_tradeoff.py`` (the seed and the 20x20 cloth with
every solver (``--quick``: fewer tolerances; ``--full`` adds the 50x50 cloth with
dop853), writes ``docs/accuracy-<scene>.png``, and rewrites ``docs/accuracy.md`` up to its
``## Extremes`` section. With ``--extremes`` the table of that section is re-measured
too (``benchmarks/extremes.py``); its prose, which reads the figures, is kept and is
maintained by hand. Prints the benchmark verdict as ``bench_tradeoff.py`` does.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_tradeoff import (
    BACKEND,
    ROOT,
    markdown,
    scenes,
    study,
    verdict,
)
from springc.tradeoff.model import (
    REFERENCE_RTOL,
    REPEAT_LIMIT,
    SCALE_FLOOR,
)
from springc.tradeoff.plot import write_work_precision
from springc.tradeoff.report import format_table, recommendations, unresolved_note

DOCS = ROOT / "docs"
EXTREMES = "## Extremes"
COMMAND = "PYTHONPATH=src python benchmarks/accuracy.py"

FULL_NOTE = """\
The 50x50 cloth is measured with `--full` (dop853 only); it is left out by default
because its reference solves take about half a minute each.
"""

METHOD = """\
## How it is measured

`springc tradeoff FILE... [--solvers LIST] [--tolerances LIST] [--steps LIST]
[--max-error LIST] [--reference ref.csv] [-o table.csv] [--plot wp.png]` (the
package is `src/springc/tradeoff/`) runs every solver at every setting and compares
its output with a reference on the output grid:

- **Error**: variable *j* at output time *t_i* is off by
  `|y_j(t_i) - ref_j(t_i)| / scale_j`, where `scale_j` is the largest `|ref_j|` over
  time, floored at {floor:g} times the largest scale among the compared
  variables of the same unit (a variable that stays near zero does not turn
  round-off into a large relative error). *max error* is the largest over times and
  variables, *RMS error* the root mean square over both. The states (positions and
  velocities) are compared.
- **Reference**: springc's `dop853` at rtol {rtol:.0e} (atol rtol/1000),
  verified by scipy's VODE in Adams mode (a variable-order multistep method, no
  Jacobian) at the same tolerances on the same generated right-hand side; their
  difference is reported, and the reference is refused if it exceeds the target.
  Errors below about ten times that difference are not resolved.
- **Time**: wall time of one simulation (integration and outputs, not compilation:
  each solver's compiled loop is loaded by an untimed run first), timed once; the
  contenders (runs meeting the target within 5x of the fastest known, under
  {repeat:g} s) are timed 3 times or more, the fastest kept. A run over the budget
  ({budget:g} s) is stopped and the solver's tighter settings are skipped.
  Adaptive solvers use atol = rtol/1000, the ratio of scipy's defaults.
- **Cost limit**: dop853 runs first; a solver's tighter settings are skipped once
  one of its runs takes over 10x dop853's fastest run meeting the target (they cost
  more and cannot be the fastest); the table lists them with the reason.
- **scipy baselines**: `solve_ivp(rhs, span, x0, t_eval=grid)` with scipy's defaults
  (RK45, rtol 1e-3, atol 1e-6), `rhs` being the same generated function springc
  integrates, timed 3 times; and `solve_ivp` RK45 at the first rtol of the table
  that reaches the target, found by springc's compiled rk45 (the same method, the
  same steps: the looser rtols are listed as skipped with its errors).
- Fixed-step solvers (verlet, symplectic-euler, rk4) take steps of the output
  interval divided by 2, 4, ..., 256.
"""


def scene_section(title: str, key: str, result: object, seconds: float, note: str) -> str:
    from springc.tradeoff.model import Tradeoff

    assert isinstance(result, Tradeoff)
    ref = result.reference
    unresolved = unresolved_note(result)
    lines = [f"## {title}", "",
             f"{result.states} states, {len(ref.time)} output times from {ref.time[0]:g} "
             f"to {ref.time[-1]:g} s; the study took {seconds / 60:.1f} minutes.", "",
             *([note, ""] if note else []),
             f"Reference: {ref.description}.", "",
             *(f"**{line}**" for line in recommendations(result)), "",
             format_table(result, markdown=True).rstrip(), ""]
    if unresolved is not None:
        lines += [f"Note: {unresolved.message}.", ""]
    lines += [f"![work-precision plot of {key}](accuracy-{key}.png)", ""]
    return "\n".join(lines)


def replace_table(section: str, table: str) -> str:
    """``section`` with its markdown table (the run of lines starting with ``|``)
    replaced by ``table``; the prose around it is kept."""
    lines = section.split("\n")
    rows = [i for i, line in enumerate(lines) if line.startswith("|")]
    if not rows:
        return section.rstrip() + "\n\n" + table + "\n"
    return "\n".join([*lines[:rows[0]], table, *lines[rows[-1] + 1:]])


def extremes_table(quick: bool) -> str:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from extremes import table

    return table(quick)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="fewer tolerances")
    parser.add_argument("--full", action="store_true", help="add the 50x50 cloth")
    parser.add_argument("--budget", type=float, default=20.0, help="seconds per run")
    parser.add_argument("--extremes", action="store_true",
                        help="also re-measure the Extremes table (about 15 minutes)")
    args = parser.parse_args()
    sections, rows = [], []
    for scene in scenes(args.quick, args.full):
        result, seconds = study(scene, args.budget)
        write_work_precision(result, DOCS / f"accuracy-{scene.key}.png")
        sections.append(scene_section(scene.title, scene.key, result, seconds, scene.note))
        rows.append((scene.title, verdict(result)))
    bench = markdown(rows)
    print(bench)
    date = datetime.date.today().isoformat()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    head = "\n".join([
        "# Accuracy and cost of the solvers", "",
        f"Generated by `{COMMAND}`{' --quick' if args.quick else ''}"
        f"{' --full' if args.full else ''} on {date} "
        f"({platform.python_implementation()} {platform.python_version()}, "
        f"{BACKEND} backend, {os.cpu_count()} CPUs, load average {load:.1f} at the end); "
        f"everything above `{EXTREMES}` is rewritten by it (with `--extremes`, that "
        "section's table too). Timings on a shared machine "
        "vary by about 20 %.", "",
        "## Benchmark: the recommendation vs scipy's default `solve_ivp`", "",
        "Target: for max error 1e-4, the recommended setting is at least 3x faster than "
        "scipy's default `solve_ivp` call reaching the same error, or the default call "
        "does not reach it. The last columns compare with `solve_ivp` RK45 at the "
        "loosest rtol of the table that reaches 1e-4.", "",
        bench.rstrip(), "", *([] if args.full else [FULL_NOTE, ""]), METHOD.format(
            floor=SCALE_FLOOR, rtol=REFERENCE_RTOL, repeat=REPEAT_LIMIT, budget=args.budget)])
    path = DOCS / "accuracy.md"
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    # The section heading on a line of its own (the header mentions it in backticks).
    heading = "\n" + EXTREMES + "\n"
    tail = old[old.index(heading) + 1:] if heading in old else (
        f"{EXTREMES}\n\n(see tests/extremes)\n")
    if args.extremes:
        tail = replace_table(tail, extremes_table(args.quick))
    path.write_text("\n".join([head, *sections, tail]).rstrip() + "\n", encoding="utf-8")
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
