"""The simulate command's two memory settings of glibc's malloc (``cli.options``):
large buffers mapped apart (``mallopt``) and the heap trimmed after a compile
(``malloc_trim``); the user's ``MALLOC_MMAP_THRESHOLD_`` is left alone."""

from __future__ import annotations

import ctypes
import sys
from typing import Any

import pytest

from springc.cli import options


class FakeLibc:
    def __init__(self) -> None:
        self.calls: list[tuple[str, tuple[int, ...]]] = []

    def __getattr__(self, name: str) -> Any:
        def call(*args: int) -> int:
            self.calls.append((name, args))
            return 1
        return call


@pytest.fixture
def libc(monkeypatch: pytest.MonkeyPatch) -> FakeLibc:
    fake = FakeLibc()
    monkeypatch.setattr(ctypes, "CDLL", lambda name: fake)
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    return fake


def test_buffers_of_a_mebibyte_and_more_are_mapped_apart(libc: FakeLibc) -> None:
    options.unmapped_large_buffers()
    assert libc.calls == [("mallopt", (-3, 1 << 20))]  # M_MMAP_THRESHOLD


def test_the_users_threshold_is_kept(libc: FakeLibc, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MALLOC_MMAP_THRESHOLD_", "65536")
    options.unmapped_large_buffers()
    assert libc.calls == []


def test_a_compile_is_followed_by_a_trim_of_the_heap(libc: FakeLibc) -> None:
    options.release_compile_memory()
    assert libc.calls == [("malloc_trim", (0,))]
