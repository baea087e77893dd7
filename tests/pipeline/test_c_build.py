"""The C library of a compiled model (pipeline/c_build.py): built once into the model's
cache entry, loaded from it without a compiler, a damaged file rebuilt with a note, and
a clear error on a machine without a C compiler (none on the PATH, no ziglang)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SpringcError
from springc.pipeline import CCompilerMissing, c_build, c_library, find_compiler

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))


def no_compiler() -> list[str]:
    raise AssertionError("the compiler ran")


def seed_dx(lib: c_build.CLibrary) -> np.ndarray:
    p = lib.parameters()
    x, z = lib.start(p)
    return lib.rhs(0.0, x + 0.25, p, z)[1]


def expected_dx() -> np.ndarray:
    model = springc.compile_model([SEED], "SpringMass", backend="python")
    p = model.module.parameters()
    x = model.module.start(p) + 0.25
    return np.asarray(model.module.rhs(0.0, x, p, model.module.guesses(p)))


def test_the_library_is_kept_in_the_cache_entry_and_loaded_without_a_compiler(
        monkeypatch: pytest.MonkeyPatch) -> None:
    model = springc.compile_model([SEED], "SpringMass", backend="python")
    first = c_library(model)
    entry = model.path.parent
    assert sorted(p.name for p in entry.iterdir() if "cmodel" in p.name) == [
        "cmodel.c", "cmodel.sha256", "libcmodel.sha256", "libcmodel.so"]
    monkeypatch.setattr(c_build, "find_compiler", no_compiler)
    again = c_library(springc.compile_model([SEED], "SpringMass", backend="python"))
    assert again.source == first.source
    np.testing.assert_allclose(seed_dx(again), expected_dx(), rtol=1e-12)


@pytest.mark.parametrize("damaged", ["libcmodel.so", "cmodel.c"])
def test_a_damaged_file_is_built_again_with_a_note(capsys: pytest.CaptureFixture[str],
                                                   damaged: str) -> None:
    model = springc.compile_model([SEED], "SpringMass", backend="python")
    c_library(model)
    path = model.path.parent / damaged
    original = path.read_bytes()
    path.write_bytes(b"planted")
    capsys.readouterr()
    lib = c_library(model)
    assert capsys.readouterr().err == (f"note: {path} does not match its recorded hash; "
                                       "building it again\n")
    assert "planted" not in lib.source
    np.testing.assert_allclose(seed_dx(lib), expected_dx(), rtol=1e-12)
    assert path.read_bytes() == original  # the same text builds the same bytes


def test_no_compiler_is_a_clear_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model = springc.compile_model([SEED], "SpringMass", backend="python")
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    monkeypatch.setenv("CC", "no-such-compiler")
    monkeypatch.setitem(sys.modules, "ziglang", None)  # find_spec: not installed
    with pytest.raises(CCompilerMissing) as caught:
        c_library(model)
    assert caught.value.message == ("no C compiler found (looked for $CC, cc, gcc and "
                                    "clang on the PATH, and the ziglang package)")
    assert caught.value.hint == ("pip install ziglang (a C compiler from PyPI), or install "
                                 "a system C compiler (for example gcc), to build the C "
                                 "model; the Python module needs none")
    assert isinstance(caught.value, SpringcError)  # the CLI reports it, exit 1


def test_without_a_system_compiler_zig_cc_of_the_ziglang_package_is_found(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    monkeypatch.delenv("CC", raising=False)
    assert find_compiler() == [sys.executable, "-m", "ziglang", "cc"]
