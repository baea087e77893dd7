"""A function defined by a modification of another (``function f = g(k = 2)``, as
``World.gravityAcceleration`` is, section 12.2 with 7.2): a call of ``f`` is a call of
``g`` whose inputs the modification gives default values.

Input: the name a call uses and its scope. Output: the function to run and the
default arguments, each evaluated where its modification is written (the instance
that declares the function for ``world.f(...)``, else the enclosing package).
"""

from __future__ import annotations

from ...errors import FlattenError, Span
from ...ir import syntax as s
from ...parse import ClassEntry
from .. import arrays as a
from ..redeclare import instance_scope, redeclared_class
from ..scopes import ClassScope, ExpressionEvaluator, Scope


def short_defaults(ev: ExpressionEvaluator, entry: ClassEntry, ref: s.Ref, scope: Scope
                   ) -> tuple[ClassEntry, dict[str, tuple[a.Value, Span]]]:
    """The full function behind ``entry`` and the defaults its short definitions give."""
    defaults = _redeclared_defaults(ev, ref, scope)
    if entry.defn.short is None:
        return entry, defaults
    where: Scope = _written_in(ev, entry, ref, scope)
    seen = 0
    while entry.defn.short is not None and seen < 100:
        short = entry.defn.short
        _add_defaults(ev, short, where, defaults)
        entry = ev.flattener.resolve_class(short.base, entry.parent or entry)
        where = ev.flattener.package_scope(entry.parent or entry)
        seen += 1
    return entry, defaults


def _add_defaults(ev: ExpressionEvaluator, short: s.ShortDef, where: Scope,
                  defaults: dict[str, tuple[a.Value, Span]]) -> None:
    """The input values ``short``'s modification gives, evaluated in ``where``, added
    to ``defaults`` (those already there, from an outer definition, win)."""
    for arg in short.modification.arguments if short.modification else ():
        mod = arg.modification
        if len(arg.path) != 1 or mod is None or mod.value is None or mod.arguments \
                or arg.redeclare is not None:
            raise FlattenError(f"only values of inputs may modify a function "
                               f"(`{'.'.join(arg.path)}`)", arg.span)
        if arg.path[0] not in defaults:
            defaults[arg.path[0]] = (ev.value(mod.value, where), arg.span)


def _redeclared_defaults(ev: ExpressionEvaluator, ref: s.Ref, scope: Scope
                         ) -> dict[str, tuple[a.Value, Span]]:
    """For ``a.f(...)`` where ``a`` was given ``redeclare function f = g(k = e)``: the
    values of that modification, evaluated where the redeclaration is written
    (``world(redeclare function gravityAcceleration = ...(phi = geodeticLatitude))``,
    MultiBody's UserDefinedGravityField)."""
    defaults: dict[str, tuple[a.Value, Span]] = {}
    if len(ref.parts) < 2:
        return defaults
    try:
        owner = ev.reference(s.Ref(ref.parts[:-1], ref.span), scope)
    except FlattenError:
        return defaults
    if not isinstance(owner, ClassScope):
        return defaults
    found = redeclared_class(owner, s.Ref(ref.parts[-1:], ref.span))
    if found is not None and found[0].short is not None:
        _add_defaults(ev, found[0].short, found[1], defaults)
    return defaults


def _written_in(ev: ExpressionEvaluator, entry: ClassEntry, ref: s.Ref, scope: Scope
                ) -> Scope:
    """The scope of the short definition's modification: the instance ``a`` of
    ``a.f(...)``, the current instance when ``f`` is its own class, else the package."""
    if len(ref.parts) > 1:
        try:
            owner = ev.reference(s.Ref(ref.parts[:-1], ref.span), scope)
        except FlattenError:
            owner = None
        if isinstance(owner, ClassScope):
            return owner
    instance = instance_scope(scope)
    if instance is not None and entry.parent is not None \
            and instance.entry.full_name == entry.parent.full_name:
        return instance
    return ev.flattener.package_scope(entry.parent or entry)
