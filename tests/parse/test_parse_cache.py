"""The parse cache (springc.parse.parse_cache): a tree per unchanged file, least
recently used first out beyond its size in source bytes, one entry per path."""

from __future__ import annotations

import os
from pathlib import Path

from springc.parse.parse_cache import ParseCache


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


def test_a_file_larger_than_the_cache_is_parsed_and_not_kept(tmp_path: Path) -> None:
    cache = ParseCache(max_bytes=50)
    a = _file(tmp_path, "A", 100)
    assert cache.parse(a).classes[0].name == "A"
    assert (len(cache), cache.size) == (0, 0)
