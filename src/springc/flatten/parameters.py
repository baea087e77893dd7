"""Numeric values of parameters and constants, evaluated from their bindings on demand.

Input: the flat binding of each parameter and constant (an ``ir.expr`` expression, or
None). Output: numbers (or numpy arrays), cached, with cycles and missing values raised
as ``KeyError`` naming the parameter.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

from ..ir import expr as x

__all__ = ["ParameterValues"]


class ParameterValues(Mapping[str, Any]):
    """Numeric values of parameters and constants, evaluated from bindings on demand."""

    def __init__(self) -> None:
        self.bindings: dict[str, x.Expr | None] = {}
        self.cache: dict[str, Any] = {}
        self.active: set[str] = set()
        self.reads = 0  # how often a value was asked for (see equation_templates.reusable)

    def __getitem__(self, name: str) -> Any:
        self.reads += 1
        if name in self.cache:
            return self.cache[name]
        if name not in self.bindings:
            raise KeyError(f"the variable '{name}'")
        binding = self.bindings[name]
        if binding is None or name in self.active:
            raise KeyError(f"the parameter '{name}', which has no value")
        self.active.add(name)
        try:
            value = x.evaluate(binding, self)
        finally:
            self.active.discard(name)
        self.cache[name] = value
        return value

    def __iter__(self) -> Iterator[str]:
        return iter(self.bindings)

    def __len__(self) -> int:
        return len(self.bindings)
