"""The parse cache (springc.parse.parse_cache): a tree per unchanged file, least
recently used first out beyond its size in source bytes, one entry per path."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from springc.errors import LoadError
from springc.parse import parser
from springc.parse.parse_cache import ParseCache
from springc.parse.parsed_store import ParsedStore


def _file(folder: Path, name: str, size: int) -> Path:
    """A model file of exactly ``size`` bytes."""
    head, tail = f"model {name}\n  Real x;\n", "end " + name + ";\n"
    path = folder / f"{name}.mo"
    path.write_text(head + "//" + "c" * (size - len(head) - len(tail) - 3) + "\n" + tail)
    assert path.stat().st_size == size
    return path


def test_an_unchanged_file_is_parsed_once(tmp_path: Path) -> None:
    cache = ParseCache(max_bytes=1000)
    a = _file(tmp_path, "A", 100)
    first = cache.parse(a)
    assert cache.parse(a) is first
    assert first.classes[0].name == "A"
    assert (len(cache), cache.size) == (1, 100)


def test_the_least_recently_used_file_goes_first_beyond_the_size(tmp_path: Path) -> None:
    cache = ParseCache(max_bytes=250)
    a, b, c = (_file(tmp_path, name, 100) for name in "ABC")
    tree_a, tree_b = cache.parse(a), cache.parse(b)
    assert cache.parse(a) is tree_a  # A used last: B is the oldest now
    cache.parse(c)
    assert (len(cache), cache.size) == (2, 200)
    assert cache.parse(a) is tree_a
    again_b = cache.parse(b)  # forgotten: parsed anew (and C goes)
    assert again_b is not tree_b and again_b == tree_b
    assert (len(cache), cache.size) == (2, 200)


def test_a_changed_file_replaces_its_tree(tmp_path: Path) -> None:
    cache = ParseCache(max_bytes=1000)
    a = _file(tmp_path, "A", 100)
    first = cache.parse(a)
    a.write_text("model A\n  Real y;\nend A;\n")
    os.utime(a, ns=(a.stat().st_atime_ns, a.stat().st_mtime_ns + 10**9))
    changed = cache.parse(a)
    assert changed is not first
    assert [c.name for c in changed.classes[0].elements] == ["y"]
    assert (len(cache), cache.size) == (1, a.stat().st_size)


def test_an_edit_that_keeps_the_size_and_the_time_is_seen(tmp_path: Path) -> None:
    cache = ParseCache(max_bytes=1000)
    a = tmp_path / "A.mo"
    a.write_text("model A\n  Real x;\nend A;\n")
    when = a.stat().st_mtime_ns
    assert [c.name for c in cache.parse(a).classes[0].elements] == ["x"]
    a.write_text("model A\n  Real z;\nend A;\n")  # same size, as `cp -p` keeps a time
    os.utime(a, ns=(when, when))
    assert [c.name for c in cache.parse(a).classes[0].elements] == ["z"]
    assert (len(cache), cache.size) == (1, a.stat().st_size)


def test_a_file_larger_than_the_cache_is_parsed_and_not_kept(tmp_path: Path) -> None:
    cache = ParseCache(max_bytes=50)
    a = _file(tmp_path, "A", 100)
    assert cache.parse(a).classes[0].name == "A"
    assert (len(cache), cache.size) == (0, 0)


# ------------------------------------------------------------ the trees kept on disk


def _fresh(store_folder: Path) -> ParseCache:
    """A cache of a new process: nothing in memory, the store on disk."""
    return ParseCache(store=ParsedStore(store_folder))


def _no_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("parsed again")

    monkeypatch.setattr(parser, "parse_text", refuse)


def test_a_file_parsed_by_one_process_is_read_back_by_the_next(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    a = tmp_path / "A.mo"
    a.write_text("model A\n  connector Port\n    Real p;\n    flow Real m;\n"
                 "    stream Real h;\n  end Port;\n  Real x(start = 1);\n"
                 "equation\n  der(x) = -x;\nend A;\n")
    first = _fresh(tmp_path / "store").parse(a)
    entries = os.listdir(tmp_path / "store")
    assert len(entries) == 1 and entries[0].endswith(".pickle")
    assert stat.S_IMODE((tmp_path / "store" / entries[0]).stat().st_mode) == 0o600
    _no_parsing(monkeypatch)
    again = _fresh(tmp_path / "store").parse(a)
    assert again is not first
    assert again.classes[0].elements[1:] == first.classes[0].elements[1:]
    assert again.classes[0].equations == first.classes[0].equations
    # the construct outside the subset is reported as before, where it was written
    port = again.classes[0].elements[0]
    assert [str(e) for e in port.unsupported] == [str(e) for e in
                                                   first.classes[0].elements[0].unsupported]
    assert str(port.unsupported[0]).startswith(
        f"{a}:5:5: error: `stream` connectors are not supported yet")


def test_a_changed_file_or_a_damaged_entry_is_parsed_again(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    a = _file(tmp_path, "A", 100)
    _fresh(tmp_path / "store").parse(a)
    a.write_text("model A\n  Real y;\nend A;\n")  # same size class, other bytes
    changed = _fresh(tmp_path / "store").parse(a)
    assert [c.name for c in changed.classes[0].elements] == ["y"]
    assert len(os.listdir(tmp_path / "store")) == 2
    for entry in (tmp_path / "store").iterdir():
        entry.write_bytes(b"not a pickle")
    assert [c.name for c in _fresh(tmp_path / "store").parse(a).classes[0].elements] \
        == ["y"]
    _no_parsing(monkeypatch)  # the damaged entry was replaced
    assert [c.name for c in _fresh(tmp_path / "store").parse(a).classes[0].elements] \
        == ["y"]


def test_windows_newlines_and_unreadable_bytes_read_as_from_text(tmp_path: Path) -> None:
    a = tmp_path / "A.mo"
    a.write_bytes(b"model A\r\n  Real x;\r\n  Real z;\r\nend A;\r\n")
    tree = _fresh(tmp_path / "store").parse(a)
    assert [(c.name, c.span.line, c.span.column) for c in tree.classes[0].elements] == [
        ("x", 2, 8), ("z", 3, 8)]
    assert tree == parser.parse_file(a, defer=True)  # Path.read_text's newlines
    b = tmp_path / "B.mo"
    b.write_bytes(b"model B\n  Real \xff;\nend B;\n")
    with pytest.raises(LoadError) as caught:
        _fresh(tmp_path / "store").parse(b)
    assert caught.value.message == f"'{b}' is not UTF-8 text: byte 0xff invalid start byte"
    assert caught.value.span is not None and \
        (caught.value.span.line, caught.value.span.column) == (2, 8)
