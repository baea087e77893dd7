"""Faster calls of the kernels: the addresses of the model functions, remembered.

A kernel takes the model's functions as first-class function values. On every call,
numba unboxes each one by asking ``numba.experimental.function_type`` for two addresses
(its C wrapper and its jitted entry point), and each answer is a compile-result
lookup of a few tens of microseconds: with three to five functions per kernel, over
half of a call's fixed cost (a one-step ``dop853`` call on the seed: 100 us, 43 us
with the addresses remembered; ``radau``: 140 and 63 us). A dispatcher's
compile result for a signature never changes once made, so the answers are remembered
per dispatcher (weakly: a module's functions are forgotten with it) and per signature
object (numba unpickles a call site's signature once and hands the same object every
time; any other object is looked up afresh and at most :data:`SIGNATURES` are kept).

:func:`install` wraps numba's two lookups, which its unboxing code fetches by name at
each call; with a numba that lacks them nothing is installed and calls stay as fast as
numba makes them.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any

SIGNATURES = 8
"""Signature objects remembered per function (one per kernel that takes it)."""
LOOKUPS = ("_get_wrapper_address", "_get_jit_address")

Lookup = Callable[[Any, Any], int]


def remembered(lookup: Lookup) -> Lookup:
    """``lookup(func, sig)`` remembered for numba dispatchers (other callables, such as
    cfuncs or objects of numba's wrapper-address protocol, are asked every time)."""
    from numba.core.dispatcher import Dispatcher

    known: weakref.WeakKeyDictionary[Any, list[tuple[Any, int]]] = \
        weakref.WeakKeyDictionary()

    def address(func: Any, sig: Any) -> int:
        entries = known.get(func) if isinstance(func, Dispatcher) else None
        if entries is not None:
            for seen, value in entries:
                if seen is sig:
                    return value
        value = lookup(func, sig)
        if isinstance(func, Dispatcher) and sig.is_precise():
            entries = known.setdefault(func, [])
            if len(entries) < SIGNATURES:
                entries.append((sig, value))
        return value

    address.remembers = lookup  # type: ignore[attr-defined]
    return address


def install() -> bool:
    """Remember numba's address lookups (once per process); whether they are."""
    from numba.experimental import function_type

    if not all(callable(getattr(function_type, name, None)) for name in LOOKUPS):
        return False
    for name in LOOKUPS:
        current = getattr(function_type, name)
        if not hasattr(current, "remembers"):
            setattr(function_type, name, remembered(current))
    return True
