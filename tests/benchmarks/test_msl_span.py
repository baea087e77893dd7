"""benchmarks/msl.py simulates over the reference's own span and compares no row outside
springc's result: Analog.DifferenceAmplifier's experiment stops at 1e-8 s, its reference
(Dymola, StopTime=1) at 1 s; a run to 1e-8 s held its last value over the reference's
rows up to 1 s and reported a worst error of 0.475 that no simulation made."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "msl.py"
_SPEC = importlib.util.spec_from_file_location("msl_benchmark_span", _PATH)
assert _SPEC is not None and _SPEC.loader is not None
msl = importlib.util.module_from_spec(_SPEC)
sys.modules["msl_benchmark_span"] = msl
_SPEC.loader.exec_module(msl)


def _write(root: Path) -> None:
    folder = root / "Lib" / "Examples" / "Amp"
    folder.mkdir(parents=True)
    (folder / "comparisonSignals.txt").write_text("time\nv\n")
    rows = ["0,0", "1e-09,0.5", "1e-09,0.5"] + [f"{k * 0.25:g},{k}" for k in range(1, 5)]
    (folder / "Amp.csv").write_text('"time","v"\n' + "\n".join(rows) + "\n")


def test_the_span_is_the_first_and_last_time_event_rows_included(tmp_path: Path) -> None:
    _write(tmp_path)
    reference = msl.read_reference(tmp_path, "Lib.Examples.Amp", 0.0)
    assert reference.span == (0.0, 1.0)
    assert reference.events == (1e-09,)
    assert list(reference.time) == [0.0, 0.25, 0.5, 0.75, 1.0]  # the event rows left out


def test_a_result_that_ends_before_the_reference_is_not_compared(tmp_path: Path) -> None:
    _write(tmp_path)
    reference = msl.read_reference(tmp_path, "Lib.Examples.Amp", 0.0)
    assert msl.uncovered(reference, np.array([0.0, 1e-8])) == \
        "the result covers 0 to 1e-08 s, the reference 0 to 1 s"
    assert msl.uncovered(reference, np.array([0.1, 1.0])) == \
        "the result covers 0.1 to 1 s, the reference 0 to 1 s"
    assert msl.uncovered(reference, np.array([])) == \
        "the result covers no rows, the reference 0 to 1 s"
    assert msl.uncovered(reference, np.linspace(0.0, 1.0 - 1e-12, 5)) == ""
