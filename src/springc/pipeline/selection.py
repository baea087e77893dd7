"""Which outputs ``--vars`` selects: wildcard patterns over a model's flat names.

``*`` matches any run of characters and ``?`` one; nothing else is special, so
``x[1]`` is literal. The selection decides which observed variables a generated module
computes (:func:`selected_observed`), and thus the module's cache key.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Sequence

from ..errors import SimulationError, did_you_mean

ALL_OBSERVED = "all"
"""The selection of a module that computes every observed variable (no ``--vars``)."""


def wildcard_match(pattern: str, name: str) -> bool:
    """Whether ``name`` matches ``pattern`` (``*``: any run, ``?``: one character; no
    other special characters, so ``x[1]`` is literal). Linear in the number of ``*``:
    each segment between stars is found at its leftmost place, never backtracked."""
    return wildcard(pattern)(name)


def wildcard(pattern: str) -> Callable[[str], bool]:
    """:func:`wildcard_match` of ``pattern``, its segments prepared once for many
    names (``m[*].s`` over the 220,000 names of a 10,000-mass chain): a pattern without
    ``?`` compares with string methods, one with ``?`` with compiled expressions."""
    parts = pattern.split("*")
    if "?" not in pattern:
        if len(parts) == 1:
            return pattern.__eq__
        return functools.partial(_plain, parts[0], parts[1:-1], parts[-1])
    first, *middle = [_segment(part) for part in parts]
    if not middle:
        return lambda name: first.fullmatch(name) is not None
    return functools.partial(_segments, first, middle[:-1], middle[-1], len(parts[-1]))


def _plain(first: str, middle: list[str], last: str, name: str) -> bool:
    end = len(name) - len(last)
    if end < len(first) or not name.startswith(first) or not name.endswith(last):
        return False
    pos = len(first)
    for segment in middle:
        found = name.find(segment, pos, end)
        if found < 0:
            return False
        pos = found + len(segment)
    return True


def _segments(first: re.Pattern[str], middle: list[re.Pattern[str]], last: re.Pattern[str],
              last_length: int, name: str) -> bool:
    head = first.match(name)
    if head is None:
        return False
    pos = head.end()
    end = len(name) - last_length
    if end < pos or last.fullmatch(name, end) is None:
        return False
    for segment in middle:
        found = segment.search(name, pos, end)
        if found is None:
            return False
        pos = found.end()
    return True


def _segment(text: str) -> re.Pattern[str]:
    return re.compile("".join("." if c == "?" else re.escape(c) for c in text), re.DOTALL)


def select_names(candidates: Sequence[str], patterns: Sequence[str] | None) -> list[str]:
    """``candidates`` matching any of ``patterns`` (all when ``None``), in model order."""
    if patterns is None:
        return list(candidates)
    # A pattern without * or ? matches its own name only: a set lookup, so that a list
    # of thousands of names does not cost names x candidates matches.
    literal = {p for p in patterns if "*" not in p and "?" not in p}
    wild = [p for p in patterns if p not in literal]
    known = set(candidates)
    for text in patterns:
        if text in literal and text in known:
            continue
        if text in literal or not any(map(wildcard(text), candidates)):
            raise SimulationError(
                f"--vars '{text}' matches no state or observed variable",
                hint=did_you_mean(text, candidates)
                or "use flat names such as 'mass.pos[1]', with * and ? as wildcards")
    matchers = [wildcard(p) for p in wild]
    return [c for c in candidates if c in literal or any(match(c) for match in matchers)]


def selected_observed(names: tuple[tuple[str, ...], tuple[str, ...]],
                      patterns: Sequence[str]) -> tuple[str, ...] | str:
    """The observed variables ``patterns`` select (an error names a pattern that matches
    nothing), or :data:`ALL_OBSERVED` when they select every one."""
    states, observed = names
    selected = set(select_names(states + observed, patterns))
    chosen = tuple(n for n in observed if n in selected)
    return ALL_OBSERVED if chosen == observed else chosen
