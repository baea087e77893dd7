"""Scalar flat variables of primitive components, with their attributes.

Input: a :class:`~springc.instance.Primitive` and its merged modification. Output:
one :class:`~springc.flat.Variable` per array element, attributes evaluated.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from typing import Any

import numpy as np

from ...errors import FlattenError, close_names
from ...ir import expr as x
from ...ir import flat
from .. import arrays as a
from .identity import Ident
from .modification import Mod, select
from .scope import ClassScope, FlattenContext, Primitive

ATTRIBUTES = {
    "Real": ("start", "fixed", "nominal", "min", "max", "unit", "displayUnit", "stateSelect",
             "quantity"),
    "Integer": ("start", "fixed", "min", "max", "quantity"),
    "Boolean": ("start", "fixed", "quantity"),
    "String": ("start", "fixed", "quantity"),
}
STATE_SELECT = ("never", "avoid", "default", "prefer", "always")


def check_attribute_mods(mod: Mod | None, primitive: str | None, name: str) -> None:
    """Every modification of a primitive variable must name one of its attributes."""
    if mod is None or primitive is None:
        return
    allowed = ATTRIBUTES[primitive]
    for key, child in mod.children.items():
        if key not in allowed:
            close = close_names(key, allowed, 1)
            raise FlattenError(
                f"'{name}' is a {primitive} and has no attribute '{key}' to modify",
                child.span, hint=f"did you mean '{close[0]}'?" if close else
                f"the attributes of {primitive} are: {', '.join(allowed)}")
        if child.children:
            raise FlattenError(f"the attribute '{key}' has no elements to modify", child.span)


def attributes_of(flattener: FlattenContext, scope: ClassScope, prim: Primitive
                  ) -> Iterator[flat.Variable]:
    """The flat variables of one primitive component."""
    names = [prim.names] if not prim.dims else list(prim.names.flat)  # type: ignore[union-attr]
    indices = [()] if not prim.dims else list(itertools.product(
        *(range(1, n + 1) for n in prim.dims)))
    bindings = flattener.parameter_values.bindings
    is_param = prim.variability == "parameter"
    for name, idx in zip(names, indices):
        mod = select(prim.mod, idx) if idx else prim.mod
        assert isinstance(name, str)
        yield flat.Variable(
            name, prim.type, prim.variability, prim.causality, prim.flow,
            bindings.get(name) if is_param else None,
            _attributes(flattener, mod, name, idx), prim.decl.description, scope.prefix,
            prim.decl.span)


def _attributes(flattener: FlattenContext, mod: Mod | None, name: str,
                index: tuple[int, ...] = ()) -> flat.Attributes:
    """The attributes given by ``mod``, remembered per combination of attribute
    modification objects: a type's modifiers (``unit = "m"``) are objects shared by all
    its variables, also where a merge with a binding built a new ``mod`` around them."""
    if mod is None or not mod.children:
        return _EMPTY
    key = tuple((k, Ident(child)) for k, child in mod.children.items())
    cached = flattener.attribute_cache.get(key)
    if cached is None:
        try:
            cached = flattener.attribute_cache[key] = _evaluate(flattener, mod, name)
        except _PerElement:  # an array type's attribute: {1, 1, 1} for Integer[3]
            return _evaluate(flattener, mod, name, index)
    return cached


class _PerElement(Exception):
    """An attribute is an array (of an array type); each element takes its own."""


def _evaluate(flattener: FlattenContext, mod: Mod, name: str,
              index: tuple[int, ...] | None = None) -> flat.Attributes:
    values: dict[str, Any] = {}
    for key, child in mod.children.items():
        if child.value is None:
            continue
        if key == "stateSelect":
            values["state_select"] = _state_select(flattener, child)
            continue
        value = flattener.mod_value(child.value)
        if a.is_array(value) and index is None and value.ndim:
            raise _PerElement
        if a.is_array(value) and index and value.ndim <= len(index):
            value = value[tuple(i - 1 for i in index[len(index) - value.ndim:])]
        if a.is_array(value):
            raise FlattenError(f"the attribute '{key}' of '{name}' must be a scalar, found an "
                               f"array of size {a.describe_shape(value.shape)}",
                               child.value.span, hint="use `each` or a scalar value")
        if key in ("unit", "displayUnit", "quantity"):
            if not isinstance(value, str):
                raise FlattenError(f"the attribute '{key}' must be a string", child.value.span)
            if key != "quantity":
                values["display_unit" if key == "displayUnit" else "unit"] = value
        elif key == "fixed":
            if isinstance(value, (str, np.ndarray)):
                raise FlattenError("the attribute 'fixed' must be a scalar Boolean",
                                   child.value.span)
            fixed = _fold(flattener, value, child, "'fixed'")
            if not isinstance(fixed, (bool, np.bool_)):
                raise FlattenError(f"the attribute 'fixed' must be a Boolean, found "
                                   f"{fixed!r}", child.value.span,
                                   hint="write fixed = true or fixed = false (Modelica "
                                   "3.6, section 4.9: fixed is a BooleanType)")
            values["fixed"] = bool(fixed)
        else:
            if isinstance(value, str):
                raise FlattenError(f"the attribute '{key}' must be a number", child.value.span)
            values[key] = value
    _check_bounds(values, mod, name)
    return flat.Attributes(**values) if values else _EMPTY


def _check_bounds(values: dict[str, Any], mod: Mod, name: str) -> None:
    """Literal bounds with min > max: the implicit ``assert(min <= value and value <=
    max)`` of every Real and Integer (Modelica 3.6, section 4.9) fails for any value."""
    low, high = (_number(values.get(key)) for key in ("min", "max"))
    if low is None or high is None or not low > high:
        return
    span = mod.children["min"].value.span  # type: ignore[union-attr]
    raise FlattenError(f"the min of '{name}' ({low:g}) is greater than its max ({high:g}): "
                       "no value lies within them", span,
                       hint="every variable holds assert(min <= value and value <= max) "
                       "(Modelica 3.6, section 4.9): swap or correct the bounds")


def _number(value: Any) -> float | None:
    """The number of a literal attribute value; None otherwise."""
    if isinstance(value, x.Const):
        value = value.value
    if isinstance(value, (int, float, np.integer, np.floating)) and \
            not isinstance(value, (bool, np.bool_)):
        return float(value)
    return None


_EMPTY = flat.Attributes()


def _fold(flattener: FlattenContext, value: a.Value, child: Mod, what: str) -> Any:
    try:
        return flattener.evaluator.fold(value)
    except KeyError as missing:
        assert child.value is not None
        raise FlattenError(f"{what} must be a parameter expression, but it depends on "
                           f"{missing.args[0]}", child.value.span) from None


def _state_select(flattener: FlattenContext, child: Mod) -> str:
    """``stateSelect = StateSelect.prefer``, or any parameter expression of that type
    (``if exact then StateSelect.default else StateSelect.prefer``)."""
    assert child.value is not None
    e = child.value.expr
    value = _fold(flattener, flattener.mod_value(child.value), child, "stateSelect")
    if isinstance(value, int | np.integer) and not isinstance(value, bool) \
            and 1 <= value <= len(STATE_SELECT):
        return STATE_SELECT[int(value) - 1]
    raise FlattenError("stateSelect must be one of "
                       + ", ".join(f"StateSelect.{n}" for n in STATE_SELECT), e.span)
