"""The disk cache of generated modules: private, verified before import, pruned, and
keyed by everything that affects the generated code."""

from __future__ import annotations

import hashlib
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.pipeline import cache
from springc.resources import PACKAGE_ROOT

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


# ------------------------------------------------------------------ verified entries

ONE = MODEL.format(i=1)
PLANT = ('import os\nopen(os.environ["SPRINGC_TEST_MARKER"], "w").close()\n'
         'raise SystemExit("planted module ran")\n')


def compiled_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """A model compiled into a fresh cache: (model file, cached module path)."""
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("SPRINGC_TEST_MARKER", str(tmp_path / "marker"))
    model = tmp_path / "M1.mdl"
    model.write_text(ONE)
    first = springc.compile_model(str(model))
    assert not first.cached
    return model, first.path


def assert_regenerated(model: Path, capsys: pytest.CaptureFixture[str], reason: str) -> None:
    """The next compilation regenerates the entry, with one note, and runs correctly."""
    capsys.readouterr()
    again = springc.compile_model(str(model))
    err = capsys.readouterr().err
    assert not again.cached
    assert err.count("\n") == 1 and err.startswith("note: cache entry ")
    assert reason in err and err.endswith("; regenerating it\n")
    assert not (model.parent / "marker").exists()
    result = springc.simulate(again, stop=1.0, interval=0.5, rtol=1e-10, atol=1e-12)
    assert abs(result["x"][-1] - np.exp(-1.0)) < 1e-7  # x(0) = 1, x' = -x
    # Regenerated with a fresh record: the third compilation is a verified hit.
    assert springc.compile_model(str(model)).cached
    assert capsys.readouterr().err == ""


def test_planted_module_is_not_executed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    model, path = compiled_once(tmp_path, monkeypatch)
    path.write_text(PLANT)
    assert_regenerated(model, capsys, "does not match its recorded hash")


@pytest.mark.parametrize("damage", ["truncated", "no record", "empty record",
                                    "syntax error", "not a module"])
def test_damaged_entry_is_regenerated(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                      capsys: pytest.CaptureFixture[str], damage: str) -> None:
    model, path = compiled_once(tmp_path, monkeypatch)
    record = path.parent / "model.sha256"
    text = path.read_bytes()
    if damage == "truncated":
        path.write_bytes(text[: len(text) // 2])
    elif damage == "no record":
        record.unlink()
    elif damage == "empty record":
        record.write_text("")
    else:
        # Damage that the record does not catch (written with a matching record).
        bad = b"def rhs(:\n" if damage == "syntax error" else b"MODEL = 'M1'\n"
        path.write_bytes(bad)
        record.write_text(hashlib.sha256(bad).hexdigest() + "\n")
    reason = {"syntax error": "does not import (SyntaxError",
              "not a module": "does not import (ImportError"}.get(
        damage, "does not match its recorded hash")
    assert_regenerated(model, capsys, reason)


def test_cache_folder_is_private_under_umask_0(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "a" / "b" / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    model = tmp_path / "M1.mdl"
    model.write_text(ONE)
    old = os.umask(0)
    try:
        compiled = springc.compile_model(str(model))
    finally:
        os.umask(old)
    for made in (tmp_path / "a", tmp_path / "a" / "b", folder, compiled.path.parent):
        assert stat.S_IMODE(made.stat().st_mode) == 0o700, made
    assert compiled.path.parent.parent == folder


def test_own_cache_folder_writable_by_others_is_refused_untouched(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    model, path = compiled_once(tmp_path, monkeypatch)
    folder = path.parent.parent
    os.chmod(folder, 0o777)
    capsys.readouterr()
    again = springc.compile_model(str(model))
    assert stat.S_IMODE(folder.stat().st_mode) == 0o777  # springc changes no mode
    assert path.exists()  # ... and removes nothing
    assert not again.cached and not again.path.is_relative_to(folder)
    assert capsys.readouterr().err == (
        f"note: cannot use the cache folder: {folder} is writable by others (make it "
        "private: chmod 700); compiling in a temporary folder\n")
    os.chmod(folder, 0o700)


def test_shared_sticky_cache_folder_is_used_through_a_private_subfolder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A folder like /tmp (mode 1777, other users' files inside) keeps its mode and its
    files; springc creates its own private folder inside it and says so."""
    shared = tmp_path / "shared"
    shared.mkdir()
    os.chmod(shared, 0o1777)
    others = shared / "someone-else"
    others.mkdir()
    (others / "model.py").write_text("x = 1\n")
    (shared / "notes.txt").write_text("theirs\n")
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(shared))
    model = tmp_path / "M1.mdl"
    model.write_text(ONE)
    first = springc.compile_model(str(model))
    again = springc.compile_model(str(model))
    inner = shared / f"springc-{os.getuid()}"
    assert stat.S_IMODE(shared.stat().st_mode) == 0o1777
    assert sorted(p.name for p in shared.iterdir()) == sorted(
        ["someone-else", "notes.txt", inner.name])
    assert (others / "model.py").read_text() == "x = 1\n"
    assert stat.S_IMODE(inner.stat().st_mode) == 0o700
    assert first.path.parent.parent == inner and again.cached
    note = (f"note: the cache folder {shared} is shared with other users: springc keeps "
            f"its files in {inner}\n")
    assert capsys.readouterr().err == 2 * note
    os.chmod(shared, 0o700)


def test_pruning_removes_only_cache_entries(tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    project = folder / "project"
    project.mkdir(parents=True)
    (project / "model.py").write_text("print('mine')\n")
    (project / "model.sha256").write_text("0" * 64 + "\n")
    entries = []
    for i in range(3):
        entries.append(folder / f"{i:024x}")
        cache.write_entry(entries[-1], f"x = {i}\n")
        os.utime(entries[-1] / "model.py", (i + 1, i + 1))
    os.utime(project / "model.py", (0, 0))
    assert cache.prune_cache(folder, keep=entries[2].name, limit=1) == entries[1::-1]
    assert sorted(p.name for p in folder.iterdir()) == [entries[2].name, "project"]


@pytest.mark.parametrize("problem", ["a file", "another user's folder"])
def test_unusable_cache_folder_falls_back_to_a_private_temporary_folder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        problem: str) -> None:
    folder = tmp_path / "cache"
    if problem == "a file":
        folder.write_text("not a folder")
        reason = f"{folder} is not a folder"
    else:
        folder.mkdir(mode=0o700)
        # The folder is ours; springc is made to run as the next user id instead.
        uid = os.getuid()
        monkeypatch.setattr(os, "getuid", lambda: uid + 1)
        reason = f"{folder} belongs to another user"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    model = tmp_path / "M1.mdl"
    model.write_text(ONE)
    compiled = springc.compile_model(str(model))
    assert capsys.readouterr().err == (f"note: cannot use the cache folder: {reason}; "
                                       "compiling in a temporary folder\n")
    assert not compiled.cached
    assert not compiled.path.is_relative_to(folder)
    assert stat.S_IMODE(compiled.path.parent.stat().st_mode) == 0o700
    result = springc.simulate(compiled, stop=1.0, interval=0.5, rtol=1e-10, atol=1e-12)
    assert abs(result["x"][-1] - np.exp(-1.0)) < 1e-7


# ------------------------------------------------------------------ key


def test_cache_key_follows_the_text_of_codegen_modules(tmp_path: Path) -> None:
    """Every module below PACKAGE_ROOT feeds the key by its text: editing a codegen
    module in a copy of the package (same size, same modification time) moves it."""
    copy = tmp_path / "src" / "springc"
    shutil.copytree(PACKAGE_ROOT, copy, ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("grammar", "models"):  # resources.resource_dir finds them here
        if not (copy / name).exists():
            os.symlink(PACKAGE_ROOT.parents[1] / name, tmp_path / name)
    script = ("from springc.pipeline.cache import request_key\n"
              "import springc\n"
              "print(springc.__file__, request_key(('M', 'python'), [], []))\n")

    def key() -> str:
        env = {**os.environ, "PYTHONPATH": str(tmp_path / "src"),
               "SPRINGC_PATH": "", "PYTHONDONTWRITEBYTECODE": "1"}
        out = subprocess.run([sys.executable, "-c", script], env=env, check=True,
                             capture_output=True, text=True).stdout.split()
        assert out[0] == str(copy / "__init__.py")  # the copy, not the installed package
        return out[1]

    before = key()
    assert key() == before
    module = copy / "codegen" / "printer.py"
    info = module.stat()
    text = module.read_text()
    edited = text.replace("NEWTON", "NEWTOM", 1) if "NEWTON" in text else text.replace(
        "_PREC", "_PREX", 1)
    assert edited != text and len(edited) == len(text)
    module.write_text(edited)
    os.utime(module, ns=(info.st_atime_ns, info.st_mtime_ns))
    assert key() != before


def test_cache_write_failure_falls_back_to_a_temporary_folder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    # As root every folder is writable: a read-only file system is simulated instead.
    import springc.pipeline.compiler as compiler

    def read_only(entry: Path, text: str, extra: object = None) -> Path:
        raise PermissionError(13, "Permission denied", str(entry))

    folder = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    monkeypatch.setattr(compiler, "write_entry", read_only)
    model = tmp_path / "M1.mdl"
    model.write_text(ONE)
    compiled = springc.compile_model(str(model))
    assert capsys.readouterr().err == (f"note: cannot write to the cache folder {folder} "
                                       "(Permission denied); compiling in a temporary folder\n")
    assert not compiled.path.is_relative_to(folder) and compiled.path.exists()
    result = springc.simulate(compiled, stop=1.0, interval=0.5, rtol=1e-10, atol=1e-12)
    assert abs(result["x"][-1] - np.exp(-1.0)) < 1e-7


def test_without_a_home_folder_parsing_and_compiling_still_work(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    def no_home() -> Path:
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.delenv("SPRINGC_CACHE_DIR", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setattr(Path, "home", staticmethod(no_home))
    path = tmp_path / "m.mdl"
    path.write_text(MODEL.format(i=3))
    result = springc.simulate([path], stop=1.0, interval=0.5)
    assert "note: cannot use the cache folder: no home folder" in capsys.readouterr().err
    assert np.allclose(result["x"], 3 * np.exp(-result.time), rtol=1e-5)


# ------------------------------------------------------------------ --vars


SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")


def test_changing_vars_reuses_the_cached_module(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """--vars that select other states, or the same observed variables, load the module
    already cached, without flattening; a new observed variable generates one."""
    import springc.pipeline.generation as generation

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    first = springc.compile_model(SEED, outputs=["mass.pos[1]"])
    assert not first.cached and first.module.OBSERVED == ()
    derive = generation.derive_system

    def no_flattening(options: object) -> object:
        raise AssertionError("the model was flattened again")

    monkeypatch.setattr(generation, "derive_system", no_flattening)
    for patterns, outputs in ((["mass.v[*]"], ("mass.v[1]", "mass.v[2]")),
                              (["mass.*"], ("mass.pos[1]", "mass.pos[2]", "mass.v[1]",
                                            "mass.v[2]"))):
        again = springc.compile_model(SEED, outputs=patterns)
        assert again.cached and again.path == first.path and again.outputs == outputs
    with pytest.raises(springc.errors.SimulationError) as info:
        springc.compile_model(SEED, outputs=["mass.w"])
    assert info.value.message == "--vars 'mass.w' matches no state or observed variable"
    monkeypatch.setattr(generation, "derive_system", derive)
    spring = springc.compile_model(SEED, outputs=["mass.pos[1]", "spring.x"])
    assert not spring.cached and spring.module.OBSERVED == ("spring.x",)
    monkeypatch.setattr(generation, "derive_system", no_flattening)
    assert springc.compile_model(SEED, outputs=["spring.x"]).path == spring.path
    monkeypatch.setattr(generation, "derive_system", derive)
    everything = springc.compile_model(SEED, outputs=["*"])  # all observed: the default
    assert not everything.cached
    monkeypatch.setattr(generation, "derive_system", no_flattening)
    assert springc.compile_model(SEED).path == everything.path
    result = springc.simulate(SEED, outputs=["mass.v[2]"], stop=0.5)
    assert result.names == ("mass.v[2]",) and result.stats.cached


def test_a_damaged_names_record_is_rebuilt(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    springc.compile_model(SEED, outputs=["mass.pos[1]"])
    (record,) = folder.glob("*/names.json")
    record.write_text('{"states": ["mass.pos[1]"], "observed": ["__import__"]}')
    again = springc.compile_model(SEED, outputs=["mass.v[1]"])
    assert capsys.readouterr().err == (f"note: cache entry {record.parent} does not match "
                                       "its recorded hash; regenerating it\n")
    assert again.cached and again.outputs == ("mass.v[1]",)
    assert '"spring.x"' in record.read_text()
