"""Compare texts that carry numbers computed by two differently compiled code paths
(the compiled engine and scipy's, numba and the python backend): the words exactly, the
numbers within a stated tolerance, never the float text itself."""

from __future__ import annotations

import math
import re

NUMBER = re.compile(r"(?<![\w.\[])[-+]?(?:inf|nan|(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?)(?![\w\]])")
"""A number in a message (not the digits of a name such as ``x1`` or ``v[2]``)."""


def split(text: str) -> tuple[str, list[float]]:
    """``text`` with every number replaced by ``#``, and the numbers."""
    return NUMBER.sub("#", text), [float(m) for m in NUMBER.findall(text)]


def assert_same_text(first: str, second: str, rtol: float) -> None:
    """The same words, and the same numbers within ``rtol`` (relative)."""
    words, numbers = split(first)
    other_words, other_numbers = split(second)
    assert words == other_words, (first, second)
    assert len(numbers) == len(other_numbers)
    for a, b in zip(numbers, other_numbers):
        assert (a == b or math.isclose(a, b, rel_tol=rtol)
                or (math.isnan(a) and math.isnan(b))), (a, b, first, second)
