"""The disk cache keeps the most recently used generated modules only."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import springc
from springc.pipeline import cache

MODEL = "model M{i}\n  Real x(start = {i});\nequation\n  der(x) = -x;\nend M{i};\n"


def test_least_recently_used_entries_are_pruned(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    monkeypatch.setattr(cache, "CACHE_ENTRIES", 2)
    files = []
    for i in range(3):
        files.append(tmp_path / f"M{i}.mdl")
        files[-1].write_text(MODEL.format(i=i))
    first = springc.compile_model(str(files[0]))
    second = springc.compile_model(str(files[1]))
    os.utime(first.path, (1, 1))
    os.utime(second.path, (2, 2))
    assert springc.compile_model(str(files[0])).cached  # a hit marks M0 as recent
    third = springc.compile_model(str(files[2]))
    assert sorted(p.parent.name for p in folder.glob("*/model.py")) == sorted(
        [first.path.parent.name, third.path.parent.name])
    assert not second.path.exists()
    assert springc.simulate(third).stats.steps > 0  # the new entry is intact
