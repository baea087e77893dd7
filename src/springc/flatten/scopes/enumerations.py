"""Enumeration types (Modelica 3.6, section 4.9.5): the predefined ``StateSelect`` and
user-defined ``type E = enumeration(a, b)``, their values, and the kinds of array
dimensions (section 10.1: an Integer size, ``Boolean`` or an enumeration type).

An enumeration value is the ordinal of its literal (1 for the first), for predefined
and user-defined enumerations alike: an :class:`EnumLiteral`, an ``int`` that also
knows its type, so that flattening can tell ``E.b`` from ``2`` (an index of a
dimension ``[E]``, a binding of a variable of type ``E``) while every later stage
sees the number.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import expr as x
from ...parse import ClassEntry


@dataclass(frozen=True)
class Enumeration:
    """An enumeration type: its full name and its ``literals`` in order."""

    name: str
    literals: tuple[str, ...]


#: The predefined enumeration types (kept under their historical name).
BuiltinEnumeration = Enumeration

STATE_SELECT = Enumeration("StateSelect", ("never", "avoid", "default", "prefer", "always"))
BUILTIN_ENUMERATIONS = {"StateSelect": STATE_SELECT}


class EnumLiteral(int):
    """The value of a literal of an enumeration: its ordinal, with its type."""

    enumeration: Enumeration

    def __new__(cls, enumeration: Enumeration, ordinal: int) -> EnumLiteral:
        value = super().__new__(cls, ordinal)
        value.enumeration = enumeration
        return value

    def __reduce__(self) -> tuple[type[EnumLiteral], tuple[Enumeration, int]]:
        # int's pickling would call ``EnumLiteral(ordinal)`` and lose the type
        return EnumLiteral, (self.enumeration, int(self))

    @property
    def literal(self) -> str:
        return self.enumeration.literals[int(self) - 1]


def enumeration_of(entry: ClassEntry) -> Enumeration:
    """The enumeration type a class ``type E = enumeration(...)`` defines."""
    assert entry.defn.enumeration is not None
    return Enumeration(entry.full_name, entry.defn.enumeration)


def literal_value(enumeration: Enumeration, ordinal: int) -> x.Const:
    """``E.<literal number ordinal>`` as a flat constant."""
    return x.Const(EnumLiteral(enumeration, ordinal))


def literal_values(enumeration: Enumeration) -> list[x.Expr]:
    """Every value of an enumeration type, in order (a ``for e in E`` range)."""
    return [literal_value(enumeration, k + 1) for k in range(len(enumeration.literals))]


#: The kind of an array dimension, and of the values that index it: None for Integer
#: sizes, ``BOOLEAN`` for ``[Boolean]``, or the enumeration of ``[E]``.
BOOLEAN = "Boolean"
DimensionKind = Enumeration | str | None


def kind_name(kind: DimensionKind) -> str:
    """How a dimension kind reads in a message."""
    if kind is None:
        return "Integer"
    return kind if isinstance(kind, str) else f"enumeration '{kind.name}'"


def value_kind(value: object) -> DimensionKind:
    """The kind of a folded subscript value: an enumeration, Boolean, or Integer (None)."""
    if isinstance(value, EnumLiteral):
        return value.enumeration
    if isinstance(value, bool):
        return BOOLEAN
    return None
