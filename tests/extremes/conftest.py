"""Fixtures of the extremes suite: a private code cache and the compiled models."""

from __future__ import annotations

from pathlib import Path

import pytest

import springc
from springc.pipeline.compiler import CompiledModel

from .cases import MODELS


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="session")
def models_file(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = Path(tmp_path_factory.mktemp("extremes")) / "extremes.mdl"
    path.write_text(MODELS)
    return str(path)


@pytest.fixture(scope="session")
def compiled(models_file: str, tmp_path_factory: pytest.TempPathFactory
             ) -> dict[str, CompiledModel]:
    """Each small model compiled once (into the session's cache)."""
    mp = pytest.MonkeyPatch()
    mp.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
    try:
        return {name: springc.compile_model(models_file, name)
                for name in ("Harmonic", "StiffPair", "Through")}
    finally:
        mp.undo()
