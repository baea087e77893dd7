"""The Modelica Standard Library's examples against the official reference results (issue 25).

    PYTHONPATH=src python benchmarks/msl.py --msl MSL --refs REFS [--cap S] [PACKAGE...]

``MSL`` holds ``Modelica/`` as distributed (e.g. 4.1.0, unmodified), ``REFS`` the tree of
modelica/MAP-LIB_ReferenceResults at the matching branch (``Modelica/Blocks/Examples/
Filter/{comparisonSignals.txt,Filter.csv}``). ``PACKAGE`` is one of ``Translational``,
``Rotational``, ``Blocks``, ``Analog``, ``HeatTransfer``, ``Elementary`` (default: all).

Every example (a class directly in the package's ``Examples`` with an ``experiment``
annotation) runs in its own process, capped at ``--cap`` seconds (default 120):

- **check**: it flattens and is balanced (``springc check``);
- **simulate**: it compiles and runs at its experiment settings (tolerance), from the
  reference's first time to its last and at its output interval, so that the grid holds
  the reference's times (Analog.DifferenceAmplifier's experiment stops at 1e-8 s, its
  reference at 1 s: the line names such an example's spans);
- **match**: every signal of ``comparisonSignals.txt`` agrees with the reference:
  ``max |a - b| / max(1, |b|) <= --tol`` (default 1e-3) on the reference's times,
  every row of the reference inside springc's result (a result that ends before the
  reference's last time is an error, never extrapolated), leaving out the rows of an
  event (a time written twice) and, with ``--guard``, the rows within that many output
  intervals of one (default 1); an event springc locates
  at most ``PAIRED_EVENTS`` intervals from the reference's also leaves out the rows
  between the two times (with the same guard).

The runs use the python backend on scipy's engine with error control off by default
(``--backend``/``--engine`` change that): the numba compile of a hybrid kernel costs
minutes on a loaded machine, and the reference comparison is the accuracy measure here.
Prints one line per example (its stage, worst error or the first line of its error)
and the table: package, examples, check, simulate, match.
"""

from __future__ import annotations

import os

# as `springc simulate` does: a multithreaded BLAS on a loaded machine made each solve
# of a 181-unknown linear block 0.1 s (RollingWheelSetDriving: 32 s of CPU for 0.05 s
# of simulated time, 1.1 s with one thread)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import csv
import json
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

PACKAGES = {
    "Translational": "Modelica.Mechanics.Translational.Examples",
    "Rotational": "Modelica.Mechanics.Rotational.Examples",
    "Blocks": "Modelica.Blocks.Examples",
    "Analog": "Modelica.Electrical.Analog.Examples",
    "HeatTransfer": "Modelica.Thermal.HeatTransfer.Examples",
    "Elementary": "Modelica.Mechanics.MultiBody.Examples.Elementary",
}

_CLASS = re.compile(r"^\s*(?:encapsulated\s+|partial\s+)*(model|block|class)\s+(\w+)", re.M)


def examples_of(msl: Path, package: str) -> list[str]:
    """The classes directly in ``package`` (a folder) with an ``experiment`` annotation,
    in ``package.order`` order."""
    folder = msl.joinpath(*package.split("."))
    if not folder.is_dir():
        return _examples_in_text(folder.parent / "package.mo", package)
    order = folder / "package.order"
    names = [n.strip() for n in order.read_text().splitlines() if n.strip()] \
        if order.exists() else sorted(p.stem for p in folder.glob("*.mo"))
    found = []
    for name in names:
        path = folder / f"{name}.mo"
        if not path.exists():
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        head = _CLASS.search(text)
        if head and head.group(2) == name and "experiment(" in text and \
                not re.search(rf"partial\s+(model|block|class)\s+{name}\b", text):
            found.append(f"{package}.{name}")
    return found


def _examples_in_text(path: Path, package: str) -> list[str]:
    """The examples of ``package``, a class written inside the file ``path``."""
    text = path.read_text(encoding="utf-8", errors="replace")
    last = package.split(".")[-1]
    body = re.search(rf"^(\s*)package {last}\b(.*?)^\1end {last};", text, re.M | re.S)
    if body is None:
        return []
    inner = body.group(2)
    nested = [m.span() for m in re.finditer(r"^\s*package (\w+)\b.*?^\s*end \1;", inner,
                                            re.M | re.S)]
    found = []
    for head in re.finditer(r"^\s*((?:encapsulated |partial )*)(model|block|class) (\w+)\b"
                            r"(.*?)^\s*end \3;", inner, re.M | re.S):
        if not any(a <= head.start() < b for a, b in nested) \
                and "partial" not in head.group(1) and "experiment(" in head.group(4):
            found.append(f"{package}.{head.group(3)}")
    return found


@dataclass(frozen=True)
class Reference:
    signals: tuple[str, ...]
    time: object
    values: dict[str, object]
    interval: float
    events: tuple[float, ...] = ()  # the times written twice
    span: tuple[float, float] = (0.0, 0.0)  # the first and last time, event rows included


#: A reference event and springc's nearest one at most this many output intervals
#: apart are one event located differently: the rows between them are left out too.
PAIRED_EVENTS = 10


def paired_rows(reference: Reference, ours: list[float], guard: float) -> object:
    """The mask of the reference's kept rows outside the span between each reference
    event and springc's nearest event (within ``PAIRED_EVENTS`` intervals), widened
    by ``guard`` intervals: a discontinuous signal differs there by its jump. An event
    of springc that pairs with none of the reference's leaves nothing out."""
    import numpy as np

    t = np.asarray(reference.time)
    keep = np.ones(len(t), dtype=bool)
    if not ours:
        return keep
    mine = np.asarray(ours)
    width = reference.interval * (1 + 1e-9)
    for te in reference.events:
        ts = float(mine[np.argmin(np.abs(mine - te))])
        if abs(ts - te) <= PAIRED_EVENTS * width:
            keep &= (t < min(te, ts) - guard * width) | (t > max(te, ts) + guard * width)
    return keep


def read_reference(refs: Path, example: str, guard: float) -> Reference:
    """The comparison signals of ``example``, without event rows (and ``guard``
    intervals around them)."""
    import numpy as np

    folder = refs.joinpath(*example.split("."))
    names = [n.strip() for n in (folder / "comparisonSignals.txt").read_text().splitlines()
             if n.strip()]
    signals = tuple(n for n in names if n != "time")
    with open(folder / f"{example.split('.')[-1]}.csv", newline="") as stream:
        reader = csv.reader(stream)
        header = [h.strip().strip('"') for h in next(reader)]
        table = np.array([[float(v) for v in row] for row in reader if row])
    column = {name: i for i, name in enumerate(header)}
    column.setdefault("time", column.get("Time", 0))  # some results write "Time"
    t = table[:, column["time"]]
    steps = np.diff(np.unique(t))
    interval = float(np.median(steps)) if len(steps) else 0.0
    events = t[np.flatnonzero(np.diff(t) == 0.0)]
    keep = np.ones(len(t), dtype=bool)
    for te in events:
        keep &= np.abs(t - te) > guard * interval * (1 + 1e-9) if guard else t != te
    return Reference(signals, t[keep], {s: table[keep, column[s]] for s in signals},
                     interval, tuple(float(te) for te in np.unique(events)),
                     (float(t[0]), float(t[-1])) if len(t) else (0.0, 0.0))


def uncovered(reference: Reference, time: object) -> str:
    """Why springc's result over ``time`` cannot be compared with every row of the
    reference (it starts after its first time or ends before its last), or ``""``."""
    import numpy as np

    t = np.asarray(time)
    first, last = reference.span
    width = 1e-9 * max(1.0, abs(first), abs(last))
    if not len(t) or t[0] > first + width or t[-1] < last - width:
        ends = f"{t[0]:g} to {t[-1]:g} s" if len(t) else "no rows"
        return f"the result covers {ends}, the reference {first:g} to {last:g} s"
    return ""


def _stage(out: dict[str, object], stage: str) -> None:
    """Record the stage reached (printed, so that a capped run still tells it)."""
    out["stage"] = stage
    print(f"STAGE {stage}", flush=True)


def one(args: argparse.Namespace, out: dict[str, object]) -> None:
    """Check, simulate and compare one example (run in a child process)."""
    import numpy as np

    from springc.ir.expr import recursion_room
    from springc.pipeline import flatten_files
    from springc.simplify import check_balance

    example = args.one
    files = [str(args.msl / "Modelica" / "package.mo")]
    _stage(out, "check")
    with recursion_room():  # as `springc check` and the API (deep expressions: RealFFT)
        check_balance(flatten_files(tuple(files), example, (str(args.msl),)))
    _stage(out, "simulate")
    refdir = args.refs.joinpath(*example.split("."))
    reference = read_reference(args.refs, example, args.guard) \
        if (refdir / "comparisonSignals.txt").exists() and \
        (refdir / f"{example.split('.')[-1]}.csv").exists() else None
    import springc

    model = springc.compile_model(files, example, libraries=[str(args.msl)],
                                  backend=args.backend)
    span = {} if reference is None else \
        {"start": reference.span[0], "stop": reference.span[1], "interval": reference.interval}
    result = springc.simulate(model, engine=args.engine, error_control=args.error_control,
                              **span)
    _stage(out, "compare")
    if reference is None:
        out["note"] = "no reference result"
        return
    experiment = model.module.EXPERIMENT
    own = (float(experiment.get("start") or 0.0), float(experiment.get("stop") or 1.0))
    if own != reference.span:  # the reference tool's stop time differs (its creation.txt)
        out["span"] = (f"reference {reference.span[0]:g} to {reference.span[1]:g} s, "
                       f"experiment {own[0]:g} to {own[1]:g} s")
    out["error"] = uncovered(reference, result.time)
    if out["error"]:
        return
    del out["error"]
    worst, where = 0.0, ""
    keep = paired_rows(reference, [e.time for e in result.events
                                   if e.kind in ("state", "time")], args.guard)
    for signal in reference.signals:
        try:
            ours = np.interp(reference.time, result.time, result[signal])[keep]
        except KeyError:
            out["error"] = f"signal {signal} not in the result"
            return
        theirs = np.asarray(reference.values[signal])[keep]
        error = float(np.max(np.abs(ours - theirs) / np.maximum(1.0, np.abs(theirs)),
                             initial=0.0))
        if not error <= worst:
            worst, where = error, signal
    if not where:  # every signal equal to its reference (Booleans, Integers)
        where = f"all {len(reference.signals)} signals"
    out.update(stage="match" if worst <= args.tol else "compare", worst=worst, signal=where)


def child(args: argparse.Namespace) -> int:
    out: dict[str, object] = {"example": args.one, "stage": "none"}
    try:
        one(args, out)
    except BaseException as error:  # reported: the parent counts it
        text = str(error).strip().splitlines()
        out["error"] = f"{type(error).__name__}: " + (text[0] if text else "")
        if isinstance(error, KeyboardInterrupt):
            raise
    print("RESULT " + json.dumps(out), flush=True)
    return 0


def run_one(example: str, args: argparse.Namespace) -> dict[str, object]:
    command = [sys.executable, __file__, "--one", example, "--msl", str(args.msl),
               "--refs", str(args.refs), "--tol", str(args.tol), "--guard", str(args.guard),
               "--backend", args.backend, "--engine", args.engine,
               "--error-control", args.error_control]
    began = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=args.cap)
    except subprocess.TimeoutExpired as expired:
        printed = expired.stdout.decode() if isinstance(expired.stdout, bytes) \
            else expired.stdout or ""
        stages = [line[6:] for line in printed.splitlines() if line.startswith("STAGE ")]
        return {"example": example, "error": f"timeout after {args.cap:g} s",
                "seconds": args.cap, "stage": stages[-1] if stages else "none"}
    seconds = time.perf_counter() - began
    for line in done.stdout.splitlines():
        if line.startswith("RESULT "):
            out: dict[str, object] = json.loads(line[7:])
            out["seconds"] = seconds
            return out
    tail = (done.stderr.strip().splitlines() or ["(no output)"])[-1]
    return {"example": example, "error": f"crashed: {tail}", "seconds": seconds}


def reached(out: dict[str, object]) -> tuple[bool, bool, bool]:
    """(checked, simulated, matched) for one example's result."""
    stage = str(out.get("stage", "none"))
    failed = "error" in out
    order = ["none", "check", "simulate", "compare", "match"]
    level = order.index(stage) if stage in order else 0
    return (level >= 2, level >= 3, stage == "match" and not failed)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("packages", nargs="*", default=[], help=", ".join(PACKAGES))
    parser.add_argument("--msl", type=Path, required=True)
    parser.add_argument("--refs", type=Path, required=True)
    parser.add_argument("--cap", type=float, default=120.0, help="seconds per example")
    parser.add_argument("--tol", type=float, default=1e-3)
    parser.add_argument("--guard", type=float, default=1.0)
    parser.add_argument("--backend", default="python")
    parser.add_argument("--engine", default="scipy")
    parser.add_argument("--error-control", default="off")
    parser.add_argument("--only", default="", help="run only examples containing this")
    parser.add_argument("--one", default="", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        return child(args)
    table = []
    for package in args.packages or list(PACKAGES):
        examples = [e for e in examples_of(args.msl, PACKAGES[package]) if args.only in e]
        counts = [0, 0, 0]
        for example in examples:
            out = run_one(example, args)
            flags = reached(out)
            counts = [c + f for c, f in zip(counts, flags)]
            what = out.get("error") or out.get("note") or \
                f"worst {out.get('worst', 0):.2e} ({out.get('signal')})"
            if out.get("span"):
                what += f"; {out['span']}"
            print(f"{package:13} {example.split('.')[-1]:32} "
                  f"{'CSM'[:sum(flags)]:3} {out.get('seconds', 0):6.1f}s  {what}"[:300],
                  flush=True)
        table.append((package, len(examples), *counts))
    print("\n| package | examples | check | simulate | match within "
          f"{args.tol:g} |\n| --- | ---: | ---: | ---: | ---: |")
    for row in table:
        print("| " + " | ".join(str(v) for v in row) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
