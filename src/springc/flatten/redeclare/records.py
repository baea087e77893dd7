"""Records as values (sections 12.6 and 10.6.1 for records): a record component given a
value (``R r = R(1, 2)``, ``parameter R r = R(k = 3)``, ``R s = r``) and equations
between records (``r1 = r2``).

Input: the value of a record component, or an equation whose left side names a record
instance. Output: the value becomes modifications of the fields (``r(x = 1, y = 2)``),
so each field gets its own binding, with the defaults of the record where the
constructor call leaves a field out; an equation becomes one equation per field. The
record constructor's inputs are the record's public components that are not constants
(section 12.6), in declaration order.
"""

from __future__ import annotations

from typing import Any

from ...errors import FlattenError, Note
from ...ir import syntax as s
from ...parse import ClassEntry, lookup_class
from ..scopes import ClassScope, ClassView, ClassViews, FlattenContext, Mod, ModValue, Scope, merge

HINT = ("a record value is a record constructor call R(...) or another record "
        "component; other record expressions are not supported yet")


def is_record(value: Any) -> bool:
    return isinstance(value, ClassScope) and value.kind == "record"


def _is_input(decl: s.Component) -> bool:
    """Whether a record component is an input of the record constructor: public, and
    not a constant or final element that has a value (section 12.6)."""
    bound = decl.modification is not None and decl.modification.value is not None
    return not decl.protected and not (bound and (decl.variability == "constant"
                                                  or decl.final))


def constructor_fields(view: ClassView) -> list[s.Component]:
    """The inputs of the record constructor of ``view``, in order."""
    return [c.decl for c in view.components.values() if _is_input(c.decl)]


def record_mod(fl: FlattenContext, mod: Mod, view: ClassView, name: str) -> Mod:
    """``mod`` of a record component with its value turned into field modifications."""
    assert mod.value is not None
    if mod.value.index:
        raise FlattenError(f"a value for an array of records ('{name}') is not supported "
                           "yet", mod.value.span, hint=HINT)
    fields = field_values(fl, mod.value.expr, mod.value.scope, view, name)
    children = {key: Mod(ModValue(expr, where), span=expr.span)
                for key, (expr, where) in fields.items()}
    # the value replaces the fields' modifications written with the declaration
    # (`final R = f(x)` makes the whole final, not the fields against its own value)
    explicit = Mod(None, mod.children, mod.each, False, mod.span)
    merged = merge(Mod(None, children, span=mod.span), explicit, name)
    assert merged is not None
    return Mod(None, merged.children, merged.each, mod.final, merged.span,
               merged.redeclare)


def field_values(fl: FlattenContext, expr: s.Expr, where: Any, view: ClassView,
                 name: str) -> dict[str, tuple[s.Expr, Any]]:
    """The expression (and its scope) of each field of ``view`` that ``expr`` gives;
    fields a constructor call leaves out keep their declared default."""
    if isinstance(expr, s.Call):
        entry = _constructor(fl, expr, where)
        if entry is not None:
            _check_type(entry, view, expr, name)
            return _arguments(expr, where, constructor_fields(view), entry)
    if isinstance(expr, s.Ref):
        target = fl.evaluator.reference(expr, where)
        if is_record(target):
            _check_type(target.entry, view, expr, name)
            return {f.name: (s.Ref((*expr.parts, s.RefPart(f.name, (), expr.span)),
                                   expr.span), where)
                    for f in constructor_fields(view)}
    if isinstance(expr, s.Call | s.IfExpr | s.FieldOf):  # a function returning a record
        return {f.name: (field_of(expr, f.name), where) for f in constructor_fields(view)}
    raise FlattenError(f"the value of record '{name}' must be a record", expr.span,
                       hint=HINT)


def field_of(expr: s.Expr, name: str) -> s.Expr:
    """The field ``name`` of the record value ``expr``; of each branch of an
    if-expression (``if c then f(x) else g(x)``), so that the branches are records."""
    if isinstance(expr, s.IfExpr):
        return s.IfExpr(tuple((c, field_of(v, name)) for c, v in expr.branches),
                        field_of(expr.otherwise, name), expr.span)
    return s.FieldOf(expr, name, expr.span)


def _constructor(fl: ClassViews, call: s.Call, where: Any) -> ClassEntry | None:
    scope_entry = where.entry
    if lookup_class(call.func.parts[0].name, scope_entry) is None:
        return None
    entry = fl.resolve_class(call.func, scope_entry)
    return entry if entry.defn.kind == "record" else None


def _check_type(entry: ClassEntry, view: ClassView, expr: s.Expr, name: str) -> None:
    if entry is not view.entry and [c.name for c in constructor_fields(view)] != \
            [f.name for f in _fields_of(entry)]:
        raise FlattenError(f"'{name}' is a record '{view.entry.full_name}', but its value "
                           f"is a '{entry.full_name}'", expr.span,
                           [Note(f"'{view.entry.full_name}' is defined here",
                                 view.entry.defn.span)])


def _fields_of(entry: ClassEntry) -> list[s.Component]:
    return [e for e in entry.defn.elements if isinstance(e, s.Component) and _is_input(e)]


def _arguments(call: s.Call, where: Any, fields: list[s.Component], entry: ClassEntry
               ) -> dict[str, tuple[s.Expr, Any]]:
    if len(call.args) > len(fields):
        raise FlattenError(f"record constructor '{entry.full_name}' takes {len(fields)} "
                           f"argument(s), {len(call.args)} given", call.span,
                           [Note("record defined here", entry.defn.span)])
    given = {f.name: (arg, where) for f, arg in zip(fields, call.args)}
    names = {f.name for f in fields}
    for named in call.named:
        if named.name not in names:
            raise FlattenError(f"record '{entry.full_name}' has no field '{named.name}' "
                               "to set", named.span,
                               hint=f"its fields are: {', '.join(sorted(names))}")
        if named.name in given:
            raise FlattenError(f"field '{named.name}' is given twice", named.span)
        given[named.name] = (named.value, where)
    return given


def record_equation(fl: FlattenContext, eq: s.Equality, where: Scope) -> list[s.Equality] | None:
    """``r1 = r2`` (or ``r = R(...)``) as one equation per field; None when the left
    side is not a record."""
    if not isinstance(eq.lhs, s.Ref):
        return None
    try:
        left = fl.evaluator.reference(eq.lhs, where)
    except FlattenError:
        return None
    if not is_record(left):
        return None
    fields = field_values(fl, eq.rhs, where, left.view, eq.lhs.dotted)
    out = []
    for field in constructor_fields(left.view):
        if field.name not in fields:
            raise FlattenError(f"field '{field.name}' of '{eq.lhs.dotted}' needs a value in "
                               "this equation", eq.rhs.span,
                               hint="give every field in the record constructor")
        lhs = s.Ref((*eq.lhs.parts, s.RefPart(field.name, (), eq.lhs.span)), eq.lhs.span)
        out.append(s.Equality(lhs, fields[field.name][0], eq.span))
    return out
