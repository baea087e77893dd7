"""Class lookup while flattening: type names, short class definitions, functions,
package constants and global names, as methods of :class:`~springc.flatten.Flattener`.

Input: references written in a class (``P.Mass``, ``Units.Length``, ``sin``) and the
class they are written in. Output: class entries, resolved types or values. Also
:func:`select_model`, which picks the class to flatten from a class tree.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from ...errors import (
    ErrorGroup,
    FlattenError,
    FollowUpError,
    Note,
    Span,
    close_names,
    did_you_mean,
    printable,
)
from ...ir import expr as x
from ...ir import syntax as s
from ...parse import ClassEntry, ClassTree, imported_element, lookup_class, member_class
from ..calls import CONSTANTS
from ..checks import (
    check_access_component,
    check_access_path,
    check_class,
    check_conditional_uses,
    check_extends,
    check_inside,
    check_outer_uses,
    check_unsupported_class,
    rule_error,
)
from ..natives import is_external_object
from ..redeclare import check_replaceables, class_in_instance, inner_class, instance_scope
from ..scopes import (
    BUILTIN_ENUMERATIONS,
    PRIMITIVES,
    ClassScope,
    ClassView,
    FlattenContext,
    Mod,
    ResolvedType,
    Scope,
    build_view,
    check_class_redeclarations,
    enumeration_of,
    from_syntax,
    instance_mod,
    literal_value,
    merge_all,
)
from .inherited_rules import check_inherited_names


class ClassLookup(FlattenContext):
    """Class and name lookup; mixed into the Flattener, which provides the caches."""

    tree: ClassTree
    views: dict[ClassEntry, ClassView]  # a ClassEntry is hashed by identity
    package_scopes: dict[ClassEntry, ClassScope]
    rule_errors: dict[ClassEntry, FlattenError]  # classes breaking a rule of rules.py

    def view(self, entry: ClassEntry, seen: tuple[ClassEntry, ...] = ()) -> ClassView:
        found = self.views.get(entry)
        if found is None and entry not in self.rule_errors:
            unsupported = entry.defn.unsupported
            if unsupported:  # a construct outside the subset, in a class the model uses
                check_unsupported_class(self, entry)  # unless it breaks a rule of theirs
                raise unsupported[0] if len(unsupported) == 1 else ErrorGroup(unsupported)
            try:
                check_extends(self, entry)
            except FlattenError as err:
                self.rule_errors[entry] = err
                raise
            found = self.views[entry] = build_view(entry, self, seen)
            try:
                check_class(self, found)
                check_class_redeclarations(self.resolve_class, entry)
                check_inherited_names(self, found)
                check_replaceables(self, found)
                check_outer_uses(self, found)
                check_conditional_uses(found)
            except FlattenError as err:
                self.rule_errors[entry] = err
        broken = self.rule_errors.get(entry)
        if broken is not None:
            raise FollowUpError(broken)
        assert found is not None
        return found

    def resolve_class(self, ref: s.Ref, scope: ClassEntry, owner: ClassEntry | None = None
                      ) -> ClassEntry:
        for part in ref.parts:
            if part.subscripts:
                raise FlattenError("a class name cannot have subscripts", part.span)
        names = [p.name for p in ref.parts]
        if ref.is_global:  # .A.B: from the top-level package (section 5.3.3)
            scope, owner = self.tree.root, None
        found = self.tree.resolve(names, scope, ref.span, owner)
        if len(names) > 1:
            chain = [self.tree.resolve(names[:k], scope, ref.span, owner)
                     for k in range(1, len(names))]
            check_access_path([*chain, found], ref)
        return found

    def resolve_type(self, ref: s.Ref, scope: ClassEntry) -> ResolvedType:
        """Follow short class definitions down to a primitive type or a full class."""
        name = ref.dotted
        dims: list[tuple[s.Expr, Any]] = []
        mods: list[tuple[s.Modification, ClassEntry]] = []
        prefixes = ("", "", False)
        if name in PRIMITIVES and lookup_class(name, scope) is None:
            return ResolvedType(name, None, (), (), prefixes)
        if name in BUILTIN_ENUMERATIONS and lookup_class(name, scope) is None:
            return ResolvedType("Integer", None, (), (), prefixes,
                                enumeration=BUILTIN_ENUMERATIONS[name])
        if name == "String" and lookup_class(name, scope) is None:
            return ResolvedType("String", None, (), (), prefixes)
        entry = self.resolve_class(ref, scope)
        connector = False
        for _ in range(100):
            short = entry.defn.short or self._extended_type(entry)
            if entry.defn.enumeration is not None:
                # Enumeration values are their ordinals (1, 2, ...): an Integer.
                # `connector DigitalSignal = Logic` (an enumeration): a signal connector
                return ResolvedType("Integer", None, tuple(dims), tuple(mods), prefixes,
                                    connector, enumeration=enumeration_of(entry))
            if short is None:
                return ResolvedType(None, entry, tuple(dims), tuple(mods), prefixes)
            if short.modification is not None:
                mods.append((short.modification, entry))
            dims += [(d, entry) for d in short.dims]
            prefixes = (prefixes[0] or short.variability, prefixes[1] or short.causality,
                        prefixes[2] or short.flow)
            connector = connector or entry.defn.kind == "connector"
            base = short.base.dotted
            if (base in PRIMITIVES or base == "String") \
                    and lookup_class(base, entry.parent or entry) is None:
                return ResolvedType(base, None, tuple(dims), tuple(mods), prefixes, connector)
            entry = self.resolve_class(short.base, entry.parent or entry,
                                       entry if entry.defn.short is None else None)
        raise FlattenError(f"type '{name}' is defined in terms of itself", ref.span)

    def _extended_type(self, entry: ClassEntry) -> s.ShortDef | None:
        """``type T extends Real(unit = "m"); end T;``, ``connector D extends Base;`` with
        ``type Base = output Real``: a class that only extends a predefined type (its
        other elements may be classes, such as an ``equalityConstraint``), read as the
        short definition ``= Base(...)`` (section 4.5.2)."""
        defn = entry.defn
        extends = [e for e in defn.elements if isinstance(e, s.Extends)]
        if len(extends) != 1 or defn.equations or defn.initial_equations or defn.algorithm \
                or any(isinstance(e, s.Component) for e in defn.elements):
            return None
        element = extends[0]
        ref: s.Ref = element.base
        scope: ClassEntry = entry.parent or entry
        owner: ClassEntry | None = entry
        for _ in range(100):
            if (ref.dotted in PRIMITIVES or ref.dotted == "String") \
                    and lookup_class(ref.dotted, scope) is None:  # String: Icons.TypeString
                if ref is not element.base:
                    check_extends(self, entry)  # the kinds that may extend a type (7.1.3)
                elif defn.kind not in ("type", "connector"):
                    return None
                return s.ShortDef(element.base, (), element.modification, "", "", False,
                                  element.span)
            try:
                base = self.resolve_class(ref, scope, owner)
            except FlattenError:
                return None
            nested = base.defn.short or next(
                (e.base for e in base.defn.elements if isinstance(e, s.Extends)), None)
            if isinstance(nested, s.ShortDef):
                ref, scope, owner = nested.base, base.parent or base, None
            elif nested is not None and base.defn.kind == "type":
                ref, scope, owner = nested, base.parent or base, base
            else:
                return None
        return None

    def follow_short(self, entry: ClassEntry) -> tuple[ClassEntry, list[Mod | None]]:
        """``model M2 = M(k = 2)``: the full class behind a short definition, and the
        modifications met on the way (outermost first)."""
        mods: list[Mod | None] = []
        seen = 0
        while entry.defn.short is not None and seen < 100:
            short = entry.defn.short
            if short.dims:
                raise FlattenError("a model defined as an array is not supported", short.span)
            mods.append(from_syntax(short.modification, self.package_scope(entry.parent
                                                                            or entry)))
            entry = self.resolve_class(short.base, entry.parent or entry)
            seen += 1
        if entry.defn.short is not None:
            raise FlattenError(f"'{entry.full_name}' is defined in terms of itself",
                               entry.defn.span)
        return entry, mods

    def find_function(self, name: str, scope: Scope) -> ClassEntry | None:
        entry = lookup_class(name, scope.entry)
        return entry if entry is not None and entry.defn.kind == "function" else None

    def resolve_function(self, ref: s.Ref, scope: Scope) -> ClassEntry:
        base = self.written_in
        if not ref.is_global and lookup_class(ref.parts[0].name, scope.entry) is None \
                and base is not None and lookup_class(ref.parts[0].name, base) is not None:
            return self.resolve_function(ref, self.package_scope(base))
        if not ref.is_global and lookup_class(ref.parts[0].name, scope.entry) is None:
            close = close_names(ref.dotted, sorted(self.evaluator.builtins.table), 1)
            raise FlattenError(f"unknown function '{ref.dotted}'", ref.span,
                               hint=f"did you mean '{close[0]}'?" if close else
                               "define it as a `function`, or load the file that defines it")
        instance = instance_scope(scope)
        entry = class_in_instance(self, instance, ref) if instance is not None \
            else self.resolve_class(ref, scope.entry)  # f redeclared in this instance
        if entry.defn.outer:  # `outer function f = A;`: the inner one (section 5.4)
            entry = inner_class(scope, entry, ref.span)
        short = entry.defn.short
        if short is not None and entry.defn.kind == "function" \
                and short.modification is None:  # function f = g; (f = g(k = 1): calls)
            entry = self.follow_short(entry)[0]
        constructor = member_class(entry, "constructor") \
            if entry.defn.kind == "class" and is_external_object(entry) else None
        if constructor is not None:  # `E(...)` of an external object (section 12.9.7)
            entry = constructor
        if entry.defn.kind == "record":  # a record constructor (section 12.6)
            return self.follow_short(entry)[0] if short is not None else entry
        if entry.defn.kind != "function":
            raise FlattenError(f"'{ref.dotted}' is a {entry.defn.kind}, not a function",
                               ref.span, [Note("defined here", entry.defn.span)])
        if entry.defn.partial:
            raise rule_error(f"the partial function '{ref.dotted}' cannot be called",
                             ref.span, "a function called in a simulation model is not "
                             "partial", "12.2", (Note("declared partial here",
                                                      entry.defn.span),))
        return entry

    def class_member(self, entry: ClassEntry, name: str, span: Span) -> Any:
        """``P.c``: a nested class or a constant of a package, or ``E.a``: a literal of
        an enumeration (its ordinal)."""
        ref = s.Ref((s.RefPart(entry.name, (), span), s.RefPart(name, (), span)), span)
        target = self.follow_short(entry)[0] if entry.defn.short is not None else entry
        literals = target.defn.enumeration
        if literals is not None:
            if name not in literals:
                raise FlattenError(f"enumeration '{entry.full_name}' has no literal '{name}'",
                                   span, hint="its literals are: " + ", ".join(literals))
            return literal_value(enumeration_of(target), literals.index(name) + 1)
        nested = member_class(entry, name)
        if nested is not None:
            check_access_path([entry, nested], ref)
            return nested
        package = self.package_scope(entry)
        if package.has_member(name):
            check_access_component(package.view, name, span, entry.full_name)
            check_inside(entry, name, False, ref)
            return package.member(name, span)
        raise FlattenError(f"'{entry.full_name}' has no element '{name}'", span)

    def inherited_name(self, scope: ClassScope, name: str, span: Span) -> Any:
        """A name that an inherited element uses, not visible from the instance's class:
        a constant of the package its base class is named through (``extends
        Medium.BaseProperties``), or a name visible where a base class is written
        (sections 5.6.1, 7.1); None if there is none, or if the class itself uses
        the name (it is not visible there)."""
        if _names(scope.entry.defn, name):
            return None
        for element, writer, base in _bases(self, scope.entry):
            if len(element.base.parts) > 1:
                prefix = s.Ref(element.base.parts[:-1], element.base.span)
                try:
                    package = self.resolve_class(prefix, writer.parent or writer, writer)
                except FlattenError:
                    package = None
                if package is not None and package.defn.kind == "package" \
                        and self.package_scope(package).has_member(name):
                    return self.package_scope(package).member(name, span)
            try:
                return self.lookup_global(name, base, span)
            except FlattenError as err:
                if not err.message.startswith("undefined name"):
                    raise
        return None

    def package_scope(self, entry: ClassEntry) -> ClassScope:
        """The instance of a package whose constants are read: ``package M2 = M1(y =
        2)`` is ``M1`` with that modification, and a package extending another with a
        modification (``extends Base(n = 3)``) has it."""
        scope = self.package_scopes.get(entry)
        if scope is None:
            target, mods = self._short_package(entry)
            view = self.view(target)
            scope = ClassScope(self, entry.full_name, view, None, entry.defn.span)
            if view.extends_mods or any(m is not None for m in mods):
                scope.mod = instance_mod(merge_all(mods), view, scope)
            self.package_scopes[entry] = scope
        return scope

    def _short_package(self, entry: ClassEntry) -> tuple[ClassEntry, list[Mod | None]]:
        short = entry.defn.short
        if short is None or short.dims or short.base.dotted in PRIMITIVES:
            return entry, []
        try:
            return self.follow_short(entry)
        except FlattenError:  # reported where the class is used
            return entry, []

    def lookup_global(self, name: str, entry: ClassEntry, span: Span) -> Any:
        """A name not declared in the instance: time, a constant of an enclosing class,
        a class (for dotted references), or a built-in constant."""
        if name == "time":
            return x.TIME
        enclosing: ClassEntry | None = entry
        encapsulated: ClassEntry | None = None
        while enclosing is not None:
            view = self.view(enclosing) if enclosing.parent is not None else None
            if view is not None and name in view.components and enclosing is not entry:
                decl = view.components[name].decl
                if decl.variability != "constant":
                    raise FlattenError(
                        f"'{name}' belongs to the enclosing class '{enclosing.full_name}'; "
                        "only its constants are visible here", span,
                        [Note("declared here", decl.span)])
                return self.package_scope(enclosing).member(name, span)
            if enclosing.defn.encapsulated:  # lookup stops here (section 5.3.1)
                encapsulated = enclosing
                break
            enclosing = enclosing.parent
        found = lookup_class(name, entry)
        if found is not None:
            return found
        constant = imported_element(entry, name)
        if constant is not None:
            return self.class_member(constant[0], constant[1], span)
        if name in BUILTIN_ENUMERATIONS:
            return BUILTIN_ENUMERATIONS[name]
        if name in CONSTANTS:
            return x.Const(CONSTANTS[name])
        if encapsulated is not None and encapsulated.parent is not None \
                and lookup_global_visible(self, name, encapsulated.parent):
            raise FlattenError(
                f"undefined name '{name}': '{encapsulated.full_name}' is encapsulated",
                span, [Note(f"'{encapsulated.full_name}' is declared encapsulated here",
                            encapsulated.defn.span)],
                "name lookup stops at an encapsulated class; import what it needs "
                "(Modelica 3.6, section 5.3.1)")
        raise FlattenError(f"undefined name '{name}'", span,
                           hint=did_you_mean(name, self.visible_names(entry))
                           or "declare it, or check the spelling")

    def visible_names(self, entry: ClassEntry) -> list[str]:
        """The names a reference in ``entry`` may use: its components, the constants of
        its enclosing classes, ``time`` (for the hint of an undefined name)."""
        names = ["time"]
        enclosing: ClassEntry | None = entry
        while enclosing is not None and enclosing.parent is not None:
            try:
                components = self.view(enclosing).components
            except (FlattenError, ErrorGroup):
                break
            names += [n for n, c in components.items()
                      if enclosing is entry or c.decl.variability == "constant"]
            enclosing = enclosing.parent
        return names


def _names(node: object, name: str) -> bool:
    """Whether a reference in ``node`` (a class's own text, nested classes excluded)
    starts with ``name``."""
    if isinstance(node, s.Ref):
        return node.parts[0].name == name or any(
            _names(sub, name) for part in node.parts for sub in part.subscripts)
    if isinstance(node, tuple):
        return any(_names(item, name) for item in node if not isinstance(item, s.ClassDef))
    fields = getattr(node, "__dataclass_fields__", None)
    if fields is None or isinstance(node, Span):
        return False
    return any(_names(getattr(node, f), name) for f in fields
               if f != "annotation" and not isinstance(getattr(node, f), s.ClassDef))


def _bases(ctx: ClassLookup, entry: ClassEntry, depth: int = 0
           ) -> Iterator[tuple[s.Extends, ClassEntry, ClassEntry]]:
    """The extends clauses of ``entry`` and of its base classes, depth first: each with
    the class that writes it and its base class."""
    for element in entry.defn.elements:
        if isinstance(element, s.Extends) and depth < 50:
            try:
                base = ctx.resolve_class(element.base, entry.parent or entry, entry)
            except FlattenError:
                continue
            yield element, entry, base
            yield from _bases(ctx, base, depth + 1)


def lookup_global_visible(ctx: ClassLookup, name: str, entry: ClassEntry) -> bool:
    """Whether ``name`` is a component of ``entry`` or of a class enclosing it."""
    enclosing: ClassEntry | None = entry
    while enclosing is not None and enclosing.parent is not None:
        if name in ctx.view(enclosing).components:
            return True
        enclosing = enclosing.parent
    return False


def select_model(tree: ClassTree, model: str | None) -> ClassEntry:
    """The class to flatten: ``model`` by dotted name, else the last model of the last
    user file."""
    if model is not None:
        parts = model.split(".")
        entry: ClassEntry | None = tree.root
        for part in parts:
            entry = entry.child(part) if entry is not None else None
        if entry is None:
            raise FlattenError(f"no class named '{model}' is loaded",
                               hint=_model_hint(tree, model))
        if entry.defn.kind not in ("model", "block", "class"):
            inner = [e.full_name for e in entry.classes.values()
                     if e.defn.kind in ("model", "block", "class")]
            raise FlattenError(f"'{model}' is a {entry.defn.kind}, not a model",
                               hint=("its models are: " + ", ".join(inner)) if inner
                               else "give the dotted name of a model")
        return entry
    user_files = [f for f in tree.user_files if _from_user(tree, f)]
    for stored in reversed(user_files):
        for defn in reversed(stored.classes):
            if defn.kind in ("model", "block", "class"):
                return _entry_of(tree, stored, defn)
    nested = [name for f in user_files + tree.named_packages for d in f.classes
              for name in _models_below(_entry_of(tree, f, d))]
    if nested:
        listed = ", ".join(nested[:5]) + (f" and {len(nested) - 5} more"
                                          if len(nested) > 5 else "")
        raise FlattenError("no model at the top level of the given files: their models sit "
                           f"in packages ({listed})",
                           hint=f"choose one by its dotted name, e.g. --model {nested[0]}")
    named = ", ".join(printable(f.file) for f in tree.user_files) or "the given files"
    raise FlattenError(f"no model found in {named}",
                       hint="name a file that defines a model, or use --model")


def _models_below(entry: ClassEntry) -> list[str]:
    """Dotted names of the models nested in ``entry`` (depth first)."""
    found = []
    for inner in filter(None, map(entry.child, entry.member_names())):
        if inner.defn.kind in ("model", "block", "class"):
            found.append(inner.full_name)
        found += _models_below(inner)
    return found


def _model_hint(tree: ClassTree, model: str) -> str:
    names: list[str] = []
    pending = list(tree.root.classes.values())
    while pending:
        entry = pending.pop()
        if entry.defn.kind in ("model", "block", "class"):
            names.append(entry.full_name)
        pending += entry.classes.values()
    hint = did_you_mean(model, sorted(names))
    if hint:
        return hint
    example = min(names, key=lambda n: (n.count("."), n)) if names else "Scenes.Chain"
    return f"give the dotted name of a model in the loaded files, e.g. --model {example}"


def _from_user(tree: ClassTree, stored: s.StoredDefinition) -> bool:
    package = tree.root
    for part in stored.within or ():
        package = package.classes.get(part, package)
    return any(package.classes.get(d.name) is not None and package.classes[d.name].from_user
               and package.classes[d.name].defn is d for d in stored.classes)


def _entry_of(tree: ClassTree, stored: s.StoredDefinition, defn: s.ClassDef) -> ClassEntry:
    package = tree.root
    for part in stored.within or ():
        package = package.classes[part]
    return package.classes[defn.name]
