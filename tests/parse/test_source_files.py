"""Source files springc reads (springc.source_files, parse.parse_cache.read_source_file):
regular files only, UTF-8 only, each refusal a clear error (exit 1), never a hang."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main


def _check(path: Path) -> tuple[int, str]:
    result = CliRunner().invoke(main, ["check", str(path)], prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    return result.exit_code, result.stderr


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    fifo = tmp_path / "m.mo"
    os.mkfifo(fifo)
    assert _check(fifo) == (1, f"error: cannot read '{fifo}': not a regular file\n")


def test_a_device_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    assert _check(Path("/dev/zero")) == (
        1, "error: cannot read '/dev/zero': not a regular file\n")


def test_a_file_that_is_not_utf8_is_located(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """The first byte that is not UTF-8 (Latin-1 é), at its line and character column."""
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.chdir(tmp_path)
    Path("m.mo").write_bytes("model M\n  Real x = 1; // ÿ \xe9t\xe9\nend M;\n"
                             .encode().replace(b"\xc3\xa9", b"\xe9"))
    assert _check(Path("m.mo")) == (1, (
        "m.mo:2:20: error: 'm.mo' is not UTF-8 text: byte 0xe9 invalid continuation "
        "byte\n"
        "    2 |   Real x = 1; // ÿ \ufffdt\ufffd\n"
        "      |                    ^\n"
        "help: Modelica files are UTF-8 (Modelica 3.6, section 13.4); convert it, e.g. "
        "iconv -f latin1 -t utf-8\n"))
