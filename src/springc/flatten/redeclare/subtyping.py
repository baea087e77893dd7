"""Interface compatibility (subtyping) of Modelica 3.6, section 6.4, as redeclarations
and constraining clauses need it (section 7.3.2).

Input: two type names, each with the class it is written in. Output: ``None`` when the
first is a subtype of the second, else the reason in plain words. Compared: whether the
types are built-in (and which), enumerations (and their literals), the number of array
dimensions, the kind of specialized class, and for each public component of the
constraining class a public component of the same name in the other class with the same
flow, input/output prefixes, no greater variability, the same number of dimensions and
a compatible type. Public nested classes are not compared (a sound subset of the rule:
what this rejects is not a subtype).
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import ErrorGroup, SpringcError
from ...ir import syntax as s
from ...parse import ClassEntry, lookup_class
from ..scopes import BUILTIN_ENUMERATIONS, PRIMITIVES, ClassViews, ViewComponent

#: Kinds of class that are compatible with each other (section 6.4); ``class`` is
#: unrestricted and compatible with every kind.
_KIND_GROUPS = ({"function"}, {"package"}, {"connector"}, {"model", "block"},
                {"type", "record"})
_VARIABILITY = {"constant": 0, "parameter": 1, "discrete": 2, "": 3}


@dataclass(frozen=True)
class Interface:
    """The parts of a type the compatibility check compares."""

    name: str  # as written, for messages
    primitive: str | None  # Real, Integer, Boolean or String
    entry: ClassEntry | None  # the class, for a class type
    enumeration: tuple[str, ...] | None  # the literals of an enumeration type
    ndims: int
    prefixes: tuple[str, str, bool]  # variability, causality, flow of short definitions


def interface(ctx: ClassViews, ref: s.Ref, scope: ClassEntry,
              extra_dims: int = 0) -> Interface | None:
    """The interface of the type ``ref`` written in ``scope`` (with ``extra_dims``
    dimensions written next to it), or None where it cannot be resolved (an error
    reported where the type is used)."""
    try:
        rtype = ctx.resolve_type(ref, scope)
        literals = _enumeration(ctx, ref, scope)
    except (SpringcError, ErrorGroup):
        return None
    primitive = None if literals is not None else rtype.primitive
    return Interface(ref.dotted, primitive, rtype.entry, literals,
                     len(rtype.dims) + extra_dims, rtype.prefixes)


def _enumeration(ctx: ClassViews, ref: s.Ref, scope: ClassEntry) -> tuple[str, ...] | None:
    """The literals of ``ref`` if it names an enumeration type (through short
    definitions), else None."""
    name = ref.dotted
    if (name in PRIMITIVES or name == "String") and lookup_class(name, scope) is None:
        return None
    if name in BUILTIN_ENUMERATIONS and lookup_class(name, scope) is None:
        return BUILTIN_ENUMERATIONS[name].literals
    entry = ctx.resolve_class(ref, scope)
    for _ in range(100):
        if entry.defn.enumeration is not None:
            return entry.defn.enumeration
        short = entry.defn.short
        if short is None or short.base.dotted in PRIMITIVES:
            return None
        entry = ctx.resolve_class(short.base, entry.parent or entry)
    return None


def _kinds_compatible(a: str, b: str) -> bool:
    return "class" in (a, b) or a == b or any(a in g and b in g for g in _KIND_GROUPS)


def incompatibility(ctx: ClassViews, a: Interface, b: Interface,
                    seen: frozenset[tuple[ClassEntry, ClassEntry]] = frozenset()) -> str | None:
    """Why ``a`` is not a subtype of ``b`` (section 6.4), or None if it is."""
    if a.ndims != b.ndims:
        return (f"'{a.name}' has {a.ndims} array dimension(s), '{b.name}' has "
                f"{b.ndims}")
    if (a.enumeration is None) != (b.enumeration is None):
        enum, plain = (a, b) if a.enumeration is not None else (b, a)
        return f"'{enum.name}' is an enumeration type and '{plain.name}' is not"
    if a.enumeration is not None and b.enumeration and a.enumeration != b.enumeration:
        return f"'{a.name}' and '{b.name}' have different enumeration literals"
    if a.enumeration is not None:
        return None
    if a.primitive is not None or b.primitive is not None:
        if a.primitive != b.primitive:
            what = (f"the built-in type {a.primitive}" if a.primitive else
                    f"the class '{a.name}'")
            other = (f"the built-in type {b.primitive}" if b.primitive else
                     f"the class '{b.name}'")
            return f"'{a.name}' is {what}, '{b.name}' is {other}"
        return None
    assert a.entry is not None and b.entry is not None
    if a.entry is b.entry or (a.entry, b.entry) in seen:
        return None
    ka, kb = a.entry.defn.kind, b.entry.defn.kind
    if not _kinds_compatible(ka, kb):
        return f"'{a.name}' is a {ka} and '{b.name}' a {kb}, which are not compatible"
    try:
        va, vb = ctx.view(a.entry), ctx.view(b.entry)
    except (SpringcError, ErrorGroup):
        return None  # reported where the class is used
    inner_seen = seen | {(a.entry, b.entry)}
    for name, cb in vb.components.items():
        if cb.decl.protected:
            continue
        ca = va.components.get(name)
        if ca is None or ca.decl.protected:
            return f"'{a.name}' has no public element '{name}', which '{b.name}' has"
        reason = _element_incompatibility(ctx, ca, cb, inner_seen)
        if reason is not None:
            return f"its element '{name}': {reason}"
    return None


def _element_incompatibility(ctx: ClassViews, ca: ViewComponent, cb: ViewComponent,
                             seen: frozenset[tuple[ClassEntry, ClassEntry]]) -> str | None:
    ia = interface(ctx, ca.decl.type_name, ca.defined_in,
                   len(ca.decl.type_dims) + len(ca.decl.dims))
    ib = interface(ctx, cb.decl.type_name, cb.defined_in,
                   len(cb.decl.type_dims) + len(cb.decl.dims))
    if ia is None or ib is None:
        return None
    da, db = ca.decl, cb.decl
    flow_a, flow_b = da.flow or ia.prefixes[2], db.flow or ib.prefixes[2]
    if flow_a != flow_b:
        return "one is a flow variable and the other is not"
    cause_a, cause_b = da.causality or ia.prefixes[1], db.causality or ib.prefixes[1]
    if cause_a != cause_b:
        return (f"declared `{cause_a or 'neither input nor output'}` against "
                f"`{cause_b or 'neither input nor output'}`")
    var_a, var_b = da.variability or ia.prefixes[0], db.variability or ib.prefixes[0]
    if _VARIABILITY.get(var_a, 3) > _VARIABILITY.get(var_b, 3):
        return f"its variability {var_a or 'continuous'} exceeds {var_b or 'continuous'}"
    return incompatibility(ctx, ia, ib, seen)
