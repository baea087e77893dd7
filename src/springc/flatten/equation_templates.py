"""Equation templates: flatten a class's equations once, then rename them per instance.

Input: the flat equations of the first instance of a class. Output: the same equations
for any further instance of that class, with the instance prefix swapped
(``sv[1,1].len`` -> ``sv[7,3].len``). A cloth has 40,000 springs of four kinds; each
spring's equations differ only in these names as long as evaluating them did not depend
on the instance's parameter values. :func:`reusable` decides that for a class (no
parameter value was read, no connections, array sizes that are literals, no constants);
anything else is flattened instance by instance as before.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from ..ir import expr as x
from ..ir import flat
from ..ir import syntax as s
from .natives import is_external_object
from .scopes import ClassView, FlattenContext, Ident, ViewComponent


@dataclass(frozen=True)
class Template:
    """The equations of one instance (``prefix``) of a class, ready to be renamed."""

    prefix: str
    equations: tuple[flat.Equation, ...]

    def instantiate(self, prefix: str) -> list[flat.Equation]:
        """The equations of the instance named ``prefix``."""
        rename = renamer(self.prefix, prefix)
        return [flat.Equation(rename(eq.lhs), rename(eq.rhs), eq.span,
                              flat.Origin(eq.origin.kind, prefix, eq.origin.detail))
                for eq in self.equations]


def make_template(prefix: str, equations: list[flat.Equation]) -> Template | None:
    """A template from an instance's equations, or None if some variable lies outside
    the instance (then renaming by prefix would be wrong)."""
    inside = prefix + "."
    for eq in equations:
        for side in (eq.lhs, eq.rhs):
            if not all(n.startswith(inside) for n in x.variables(side)):
                return None
    return Template(prefix, tuple(equations))


def reusable(flattener: FlattenContext, view: ClassView, known: dict[Ident[ClassView], bool]
             ) -> bool:
    """Whether every instance of ``view`` has the same equations up to its prefix, as
    far as the class's text shows: only equalities (loops and ifs of them), no
    constants (their values may be modified per instance) and literal array sizes, in
    the class and in all its components. Parameter reads are checked by the caller.
    ``known``: the answers so far (the caller's cache, by view)."""
    found = known.get(Ident(view))
    if found is None:
        known[Ident(view)] = False  # a class containing itself
        outer_classes = any(isinstance(e, s.ClassDef) and e.outer  # differ per instance
                            for e in view.entry.defn.elements)
        found = not outer_classes \
            and _equations_only(eq.equation for eq in view.equations) \
            and _equations_only(eq.equation for eq in view.initial_equations) \
            and all(_component_reusable(flattener, comp, known)
                    for comp in view.components.values())
        known[Ident(view)] = found
    return found


def fixed_shape(flattener: FlattenContext, comp: ViewComponent,
                class_ok: Callable[[ClassView], bool]) -> bool:
    """Literal sizes and no constants: ``comp`` has the same members in every instance
    (for a component of class type, when ``class_ok`` accepts its class)."""
    decl = comp.decl
    if decl.condition is not None or decl.outer or decl.inner or decl.replaceable:
        return False  # members, types or equations may differ per instance
    declared = flattener.declared_type(comp)
    rtype = declared.rtype
    if declared.dims is None or "constant" in (comp.decl.variability, rtype.prefixes[0]) \
            or rtype.primitive == "String" or comp.decl.evaluate:
        return False
    if rtype.entry is None:
        return True
    if is_external_object(rtype.entry):
        return False  # a table: numbers folded from each instance's parameters
    return rtype.entry.defn.kind not in ("function", "package") \
        and class_ok(flattener.view(rtype.entry))


def _component_reusable(flattener: FlattenContext, comp: ViewComponent,
                        known: dict[Ident[ClassView], bool]) -> bool:
    return fixed_shape(flattener, comp, lambda view: reusable(flattener, view, known))


def _equations_only(equations: Iterable[s.Equation]) -> bool:
    for eq in equations:
        if isinstance(eq, s.ForEquation):
            if not _equations_only(eq.body):
                return False
        elif isinstance(eq, s.IfEquation):
            if not all(_equations_only(body) for _, body in eq.branches) \
                    or not _equations_only(eq.otherwise):
                return False
        elif not isinstance(eq, s.Equality):
            return False
    return True


def renamer(old: str, new: str) -> Callable[[x.Expr], x.Expr]:
    """A function that renames the variables ``old.*`` to ``new.*`` in an expression."""
    return _Renamer(old, new)


class _Renamer:
    """:func:`renamer`'s function: an object, not a recursive closure, which would be a
    reference cycle (function -> cell -> function) left to the cyclic collector with
    its names, one per instance, while a model compiles with the collector paused."""

    __slots__ = ("cut", "names", "new")

    def __init__(self, old: str, new: str) -> None:
        self.cut = len(old)
        self.new = new
        self.names: dict[str, x.Var] = {}

    def __call__(self, e: x.Expr) -> x.Expr:
        if isinstance(e, x.Var):
            found = self.names.get(e.name)
            if found is None:
                found = self.names[e.name] = x.Var(self.new + e.name[self.cut:])
            return found
        if isinstance(e, x.BinOp):
            return x.BinOp(e.op, self(e.left), self(e.right))
        if isinstance(e, (x.Const, x.Time)):
            return e
        if isinstance(e, x.Call):
            return x.Call(e.name, tuple(self(a) for a in e.args))
        if isinstance(e, x.If):
            return x.If(self(e.cond), self(e.then), self(e.otherwise))
        return type(e)(self(e.arg))  # Neg, Not, Der
