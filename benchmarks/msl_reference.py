"""Modelica Standard Library examples against the Modelica Association's reference results.

    PYTHONPATH=src python benchmarks/msl_reference.py --msl MSL --refs REFS \\
        [--rtol R] [--solver S] [--floor F] EXAMPLE...

``MSL`` is a folder holding ``Modelica/`` (a checkout of modelica/ModelicaStandardLibrary
at a release tag, e.g. v4.1.0), ``REFS`` one holding the reference tree of
modelica/MAP-LIB_ReferenceResults at the matching branch (``Modelica/Blocks/Examples/
SlewRateLimiter/{comparisonSignals.txt,SlewRateLimiter.csv}``); no MSL file is part of
springc. Each ``EXAMPLE`` (``Modelica.Blocks.Examples.SlewRateLimiter``) is simulated
at springc's default settings (the experiment's start, stop and tolerance, ``--solver
auto``) except its output interval, which is the reference's, so that the output grid
holds the reference's times; ``--rtol`` overrides the tolerance.

For every signal of ``comparisonSignals.txt`` the result is interpolated onto the
reference's times, leaving out the rows of an event (a time written twice, the left and
right limits); the error is ``max|a - b| / max(max|b|, floor)`` over those times.
Prints a table, one row per signal, and each example's worst error.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import springc

FLOOR = 1e-6
"""The scale of a signal that stays near zero."""


@dataclass(frozen=True)
class Reference:
    """A reference result: its times (no event rows) and signals there."""

    signals: tuple[str, ...]
    time: np.ndarray
    values: dict[str, np.ndarray]
    interval: float


def read_reference(refs: Path, example: str) -> Reference:
    """The reference of ``example`` (its comparison signals) from the tree ``refs``."""
    folder = refs.joinpath(*example.split("."))
    names = [line.strip() for line in (folder / "comparisonSignals.txt").read_text()
             .splitlines() if line.strip()]
    signals = tuple(n for n in names if n != "time")
    with open(folder / f"{example.split('.')[-1]}.csv", newline="") as stream:
        reader = csv.reader(stream)
        header = next(reader)
        table = np.array([[float(v) for v in row] for row in reader if row])
    column = {name: i for i, name in enumerate(header)}
    t = table[:, column["time"]]
    once = np.ones(len(t), dtype=bool)
    twice = np.flatnonzero(np.diff(t) == 0.0)
    once[twice] = once[twice + 1] = False
    steps = np.diff(np.unique(t))
    interval = float(np.median(steps)) if len(steps) else 0.0
    values = {s: table[once, column[s]] for s in signals}
    return Reference(signals, t[once], values, interval)


def compare(result: springc.SimulationResult, reference: Reference,
            floor: float) -> list[tuple[str, float, float, float]]:
    """Per signal: the largest difference, the reference's scale and their ratio."""
    rows = []
    for signal in reference.signals:
        ours = np.interp(reference.time, result.time, result[signal])
        theirs = reference.values[signal]
        error = float(np.max(np.abs(ours - theirs)))
        scale = max(float(np.max(np.abs(theirs))), floor)
        rows.append((signal, error, scale, error / scale))
    return rows


def run(example: str, msl: Path, reference: Reference, rtol: float | None,
        solver: str) -> tuple[springc.SimulationResult, float]:
    """The example simulated on the reference's output interval; and its seconds."""
    began = time.perf_counter()
    model = springc.compile_model(str(msl / "Modelica" / "package.mo"), example,
                                  libraries=[str(msl)])
    result = springc.simulate(model, interval=reference.interval or None, rtol=rtol,
                              solver=solver)
    return result, time.perf_counter() - began


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("examples", nargs="+", metavar="EXAMPLE")
    parser.add_argument("--msl", type=Path, required=True, help="folder holding Modelica/")
    parser.add_argument("--refs", type=Path, required=True,
                        help="folder holding the reference tree (Modelica/...)")
    parser.add_argument("--rtol", type=float, default=None)
    parser.add_argument("--solver", default="auto")
    parser.add_argument("--floor", type=float, default=FLOOR)
    args = parser.parse_args(argv)
    print(f"{'example / signal':<58} {'max |a-b|':>10} {'scale':>10} {'error':>10}")
    worst_all = 0.0
    for example in args.examples:
        reference = read_reference(args.refs, example)
        result, seconds = run(example, args.msl, reference, args.rtol, args.solver)
        rows = compare(result, reference, args.floor)
        stats = result.stats
        print(f"{example} ({stats.solver}, {stats.steps} steps, "
              f"{stats.state_events} state and {stats.time_events} time events, "
              f"{seconds:.1f} s)")
        for signal, error, scale, ratio in rows:
            print(f"  {signal:<56} {error:>10.3g} {scale:>10.3g} {ratio:>10.3g}")
        worst = max(r[3] for r in rows)
        worst_all = max(worst_all, worst)
        print(f"  {'worst':<56} {'':>10} {'':>10} {worst:>10.3g}")
    print(f"worst of all: {worst_all:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
