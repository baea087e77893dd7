"""The parser-table cache (springc.parse.parser.parser_cache_file): never a pickle in the
shared temporary folder, only one in springc's own per-user cache folder, kept private."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from springc.parse.parser import parser_cache_file
from springc.resources import grammar_path

SRC = Path(__file__).resolve().parents[2] / "src"


def _parse_in_fresh_process(tmp: Path, cache: Path) -> None:
    env = {**os.environ, "TMPDIR": str(tmp), "SPRINGC_CACHE_DIR": str(cache),
           "PYTHONPATH": str(SRC)}
    code = ("from springc.parse.parser import parse_text\n"
            "print(parse_text('model M Real x; end M;', 'm.mdl').classes[0].name)\n")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True)
    assert out.stdout == "M\n"


def test_nothing_is_written_to_or_read_from_the_shared_temporary_folder(tmp_path: Path
                                                                        ) -> None:
    shared, cache = tmp_path / "tmp", tmp_path / "cache"
    shared.mkdir()
    _parse_in_fresh_process(shared, cache)
    _parse_in_fresh_process(shared, cache)
    assert sorted(p.name for p in shared.iterdir()) == []
    folder = cache / "parser"
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    (cached,) = folder.iterdir()
    assert cached.name.startswith("modelica-") and cached.suffix == ".pickle"


def test_cache_folder_is_created_private_and_never_changed(tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch
                                                           ) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path))
    old = os.umask(0)
    try:
        file = parser_cache_file(grammar_path())
    finally:
        os.umask(old)
    assert file is not None and file.parent == tmp_path / "parser"
    assert stat.S_IMODE(file.parent.stat().st_mode) == 0o700
    file.parent.chmod(0o777)
    assert parser_cache_file(grammar_path()) is None  # others may write it: not used
    assert stat.S_IMODE(file.parent.stat().st_mode) == 0o777
    file.parent.chmod(0o700)


def test_no_parser_folder_in_another_users_cache_folder(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    folder = tmp_path / "cache"
    folder.mkdir(mode=0o700)
    uid = os.getuid()
    monkeypatch.setattr(os, "getuid", lambda: uid + 1)  # springc runs as another user
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    assert parser_cache_file(grammar_path()) is None
    assert list(folder.iterdir()) == []


def test_a_symlink_or_a_file_others_may_write_is_not_loaded(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path))
    file = parser_cache_file(grammar_path())
    assert file is not None
    planted = tmp_path / "planted.pickle"
    planted.write_bytes(b"not a parser")
    file.symlink_to(planted)
    assert parser_cache_file(grammar_path()) is None  # not followed: no cache at all
    file.unlink()
    file.write_bytes(b"not a parser")
    file.chmod(0o666)
    assert parser_cache_file(grammar_path()) == file
    assert not file.exists()  # removed; lark writes a fresh one


def test_a_cache_folder_that_is_not_a_folder_means_no_cache(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch
                                                            ) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path))
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "parser").symlink_to(tmp_path / "elsewhere")
    assert parser_cache_file(grammar_path()) is None


def test_without_a_home_folder_the_parser_is_built_without_a_cache(
        monkeypatch: pytest.MonkeyPatch) -> None:
    def no_home() -> Path:
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.delenv("SPRINGC_CACHE_DIR", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setattr(Path, "home", staticmethod(no_home))
    assert parser_cache_file(grammar_path()) is None
