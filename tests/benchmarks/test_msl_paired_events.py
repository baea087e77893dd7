"""benchmarks/msl.py leaves out the rows between a reference event and springc's
nearest event when they are at most PAIRED_EVENTS output intervals apart (the same
switching located differently: HeatTransfer.ControlledTemperature's reference lags the
exact switching times, 0.62642535 s from an independent solve at 1e-12, by up to
1.25e-3 s); an event of springc that pairs with none leaves nothing out."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "msl.py"
_SPEC = importlib.util.spec_from_file_location("msl_benchmark", _PATH)
assert _SPEC is not None and _SPEC.loader is not None
msl = importlib.util.module_from_spec(_SPEC)
sys.modules["msl_benchmark"] = msl
_SPEC.loader.exec_module(msl)


def _reference(events: tuple[float, ...]) -> object:
    t = np.round(np.arange(0, 101) * 0.01, 10)
    return msl.Reference(("y",), t, {"y": np.zeros_like(t)}, 0.01, events)


def test_rows_between_a_reference_event_and_ours_are_left_out() -> None:
    keep = msl.paired_rows(_reference((0.5,)), [0.523], 1.0)
    t = np.round(np.arange(0, 101) * 0.01, 10)
    assert list(t[~keep]) == [0.49, 0.5, 0.51, 0.52, 0.53]  # one interval of guard


def test_an_event_far_from_every_reference_event_leaves_nothing_out() -> None:
    assert msl.paired_rows(_reference((0.5,)), [0.75], 1.0).all()
    assert msl.paired_rows(_reference(()), [0.25, 0.5], 1.0).all()
    assert msl.paired_rows(_reference((0.5,)), [], 1.0).all()
