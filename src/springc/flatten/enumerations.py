"""The predefined enumeration types of Modelica (section 4.9.5): ``StateSelect``.

An enumeration value is the ordinal of its literal (1 for the first), for predefined
and user-defined enumerations alike.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class BuiltinEnumeration:
    """A predefined enumeration type; ``literals`` in order."""

    name: str
    literals: tuple[str, ...]


STATE_SELECT = BuiltinEnumeration("StateSelect", ("never", "avoid", "default", "prefer",
                                                  "always"))
BUILTIN_ENUMERATIONS = {"StateSelect": STATE_SELECT}
