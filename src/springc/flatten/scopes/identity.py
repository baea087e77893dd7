"""Cache keys that stand for one object, not for its value.

The caches of a flattening run remember what they computed for a class view, a
declaration or a syntax node. Their ``id()`` alone is not a key: once the object is
freed, another one can get the same id and hit the entry of the first. An
:class:`Ident` holds its object, so the id cannot be reused while the key is in a
cache, and it is equal only to a key of the very same object (two equal syntax trees
written in two places stay apart). The caches are owned by the run's flattener (or by
a local walk) and go with it.
"""

from __future__ import annotations

from typing import Generic, TypeVar

T = TypeVar("T")


class Ident(Generic[T]):
    """A hashable key for the identity of ``obj``."""

    __slots__ = ("_hash", "obj")

    def __init__(self, obj: T) -> None:
        self.obj = obj
        self._hash = id(obj)

    def __hash__(self) -> int:
        return self._hash

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Ident) and other.obj is self.obj

    def __repr__(self) -> str:
        return f"Ident({type(self.obj).__name__} at {self._hash:#x})"
