"""``fileio.replace_private``: the one temp-and-rename writer of the cache's entries and
run records (``pipeline.cache.add_to_entry``, ``run_record.write``)."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from springc.fileio import replace_private


def test_replace_private_writes_the_bytes_private_and_leaves_no_temporary(
        tmp_path: Path) -> None:
    target = tmp_path / "entry.bin"
    target.write_bytes(b"old content")
    replace_private(target, b"\x00new\xff")
    assert target.read_bytes() == b"\x00new\xff"
    assert stat.S_IMODE(target.stat().st_mode) == 0o600
    assert sorted(os.listdir(tmp_path)) == ["entry.bin"]


def test_replace_private_keeps_the_old_file_and_removes_its_temporary_on_failure(
        tmp_path: Path) -> None:
    target = tmp_path / "entry.bin"
    target.mkdir()  # os.replace of a file over a folder fails: IsADirectoryError
    with pytest.raises(IsADirectoryError):
        replace_private(target, b"data")
    assert target.is_dir()
    assert sorted(os.listdir(tmp_path)) == ["entry.bin"]


def test_the_cache_and_the_run_record_write_through_it(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    """Both writers go through the helper (a failing write reaches neither's target)."""
    from springc import run_record
    from springc.pipeline import cache

    written: list[tuple[str, bytes]] = []
    monkeypatch.setattr(cache, "replace_private",
                        lambda path, data: written.append((Path(path).name, data)))
    monkeypatch.setattr(run_record, "replace_private",
                        lambda path, data: written.append((Path(path).name, data)))
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    cache.add_to_entry(tmp_path, "lib.so", b"abc")
    run_record.write("k" * 64, {"x": 1})
    names = [name for name, _ in written]
    assert names == ["lib.sha256", "lib.so", "k" * 64 + ".json"]
    assert written[1][1] == b"abc"
    assert written[0][1] == (
        b"ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad\n")
    assert written[2][1] == b'{"format": %d, "key": "%s", "x": 1}' % (
        run_record.FORMAT, b"k" * 64)


def test_keep_newest_removes_only_its_own_oldest_files(tmp_path: Path) -> None:
    from springc.fileio import keep_newest

    ours = [tmp_path / f"{i:064x}.json" for i in range(4)]
    for age, path in enumerate(ours):
        path.write_text("{}")
        os.utime(path, ns=(10**18 - age * 10**9, 10**18 - age * 10**9))  # ours[0] newest
    other = tmp_path / "notes.json"  # not a hash: never counted, never removed
    other.write_text("mine")
    os.utime(other, ns=(1, 1))
    keep_newest(tmp_path, ".json", 69, 2)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [ours[0].name, ours[1].name, other.name])
    keep_newest(tmp_path / "absent", ".json", 69, 2)  # a missing folder: nothing to do
