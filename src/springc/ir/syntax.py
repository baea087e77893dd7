"""The typed syntax tree produced by :mod:`springc.parse`.

Every node is a frozen dataclass carrying the :class:`~springc.errors.Span` of the text
it came from. Names are plain strings; dotted names are tuples of strings.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from operator import attrgetter
from typing import Any

from ..errors import ParseError, Span

# ---------------------------------------------------------------- expressions


@dataclass(frozen=True, slots=True)
class Number:
    """A numeric literal: ``int`` for ``1``, ``float`` for ``1.0`` or ``1e3``."""

    value: int | float
    span: Span


@dataclass(frozen=True, slots=True)
class Bool:
    value: bool
    span: Span


@dataclass(frozen=True, slots=True)
class String:
    """A string literal (only legal in attributes such as ``unit`` and in annotations)."""

    value: str
    span: Span


@dataclass(frozen=True, slots=True)
class RefPart:
    """One segment of a component reference: ``pos[i]`` in ``ms[3].pos[i]``."""

    name: str
    subscripts: tuple[Expr, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Ref:
    """A component or class reference such as ``ms[i].flange.f`` or ``Modelica.Constants.pi``;
    ``is_global`` for ``.A.B``, looked up from the top-level package (section 5.3.3)."""

    parts: tuple[RefPart, ...]
    span: Span
    is_global: bool = False

    @property
    def dotted(self) -> str:
        return ".".join(p.name for p in self.parts)


@dataclass(frozen=True, slots=True)
class Colon:
    """The ``:`` subscript selecting a whole dimension."""

    span: Span


@dataclass(frozen=True, slots=True)
class End:
    """``end`` inside a subscript: the size of that dimension."""

    span: Span


@dataclass(frozen=True, slots=True)
class Unary:
    """``op`` is ``"-"``, ``"+"`` or ``"not"``."""

    op: str
    operand: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Binary:
    """``op`` is one of ``+ - * / ^ .+ .- .* ./ .^ < <= > >= == <> and or``."""

    op: str
    left: Expr
    right: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class IfExpr:
    """``if c1 then e1 elseif c2 then e2 else e3``."""

    branches: tuple[tuple[Expr, Expr], ...]
    otherwise: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class NamedArg:
    name: str
    value: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Call:
    """A function call, including built-ins such as ``der(x)`` and ``sum(v)``."""

    func: Ref
    args: tuple[Expr, ...]
    named: tuple[NamedArg, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class ForIndex:
    """``i in 1:N``; ``range`` is ``None`` for the implicit-range form ``for i loop``."""

    name: str
    range: Expr | None
    span: Span


@dataclass(frozen=True, slots=True)
class Comprehension:
    """``{e for i in r}`` or the argument of ``sum(e for i in r)``."""

    body: Expr
    indices: tuple[ForIndex, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class ArrayLit:
    """``{a, b, c}``."""

    items: tuple[Expr, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class MatrixLit:
    """``[a, b; c, d]``: rows of horizontally concatenated expressions."""

    rows: tuple[tuple[Expr, ...], ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Range:
    """``start:stop`` or ``start:step:stop``."""

    start: Expr
    step: Expr | None
    stop: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Tuple:
    """``(a, , c)``: the output list on the left of ``(a, b) = f(x)`` (``None``: a gap)."""

    items: tuple[Expr | None, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class FieldOf:
    """The field ``name`` of a record-valued expression (``f(x)`` returning a record):
    never parsed, made by flattening when a record is bound to such an expression."""

    record: Expr
    name: str
    span: Span


Expr = (
    Number | Bool | String | Ref | Colon | End | Unary | Binary | IfExpr | Call
    | Comprehension | ArrayLit | MatrixLit | Range | Tuple | FieldOf
)

# -------------------------------------------------------------- modifications


@dataclass(frozen=True, slots=True)
class Modification:
    """``(arg, ...) = value``; either part may be absent."""

    arguments: tuple[ElementModification, ...]
    value: Expr | None
    span: Span


@dataclass(frozen=True, slots=True)
class ElementModification:
    """``each final a.b(c = 1) = 2 "description"``; ``path`` is the dotted target."""

    path: tuple[str, ...]
    modification: Modification | None
    each: bool
    final: bool
    span: Span
    # `redeclare Steel m(k = 2)` or `redeclare model M = Other` (Modelica 7.3): the new
    # declaration of the element ``path`` names.
    redeclare: Component | ClassDef | None = None


# ------------------------------------------------------------------- elements


@dataclass(frozen=True, slots=True)
class Component:
    """One declared component; ``Real a, b;`` yields two of these.

    ``variability`` is ``""``, ``"parameter"``, ``"constant"`` or ``"discrete"``;
    ``causality`` is ``""``, ``"input"`` or ``"output"``. ``type_dims`` are the
    dimensions written on the type (``Real[2] x``), ``dims`` those on the name.
    """

    name: str
    type_name: Ref
    type_dims: tuple[Expr, ...]
    dims: tuple[Expr, ...]
    modification: Modification | None
    variability: str
    causality: str
    flow: bool
    final: bool
    protected: bool
    description: str
    span: Span
    # `Support support if useSupport`: the component exists only when this parameter
    # expression is true (Modelica 4.4.5).
    condition: Expr | None = None
    inner: bool = False
    outer: bool = False
    replaceable: bool = False
    # The type and modification of `constrainedby T(...)` (Modelica 7.3.2).
    constraint: tuple[Ref, Modification | None] | None = None
    redeclare: bool = False  # an element `redeclare T x;` replacing an inherited one
    stream: bool = False  # `stream Real h` (section 15): outside the subset, rules checked
    # `annotation(Evaluate = true)` (Modelica 18.3): the parameter's value is folded into
    # the model as a constant's is
    evaluate: bool = False


@dataclass(frozen=True, slots=True)
class Extends:
    """``extends Base(k = 1)``; ``protected`` when written in a protected section (the
    inherited elements are then protected)."""

    base: Ref
    modification: Modification | None
    span: Span
    protected: bool = False


@dataclass(frozen=True, slots=True)
class Import:
    """``import A.B.C;`` (``names=("C",)``, alias ``None``), ``import D = A.B.C;``
    (alias ``"D"``), ``import A.B.*;`` (``wildcard``), ``import A.B.{C, D};`` (``names``).
    ``path`` is the package part, without the imported names."""

    path: tuple[str, ...]
    names: tuple[str, ...]
    alias: str | None
    wildcard: bool
    span: Span


@dataclass(frozen=True, slots=True)
class ShortDef:
    """The right-hand side of ``type Force = Real(unit = "N")`` or ``model M2 = M(k = 2)``.

    ``variability``/``causality``/``flow`` are base prefixes such as in
    ``connector RealInput = input Real``.
    """

    base: Ref
    dims: tuple[Expr, ...]
    modification: Modification | None
    variability: str
    causality: str
    flow: bool
    span: Span


# ------------------------------------------------------------------ equations


@dataclass(frozen=True, slots=True)
class Equality:
    lhs: Expr
    rhs: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Connect:
    a: Ref
    b: Ref
    span: Span


@dataclass(frozen=True, slots=True)
class ForEquation:
    indices: tuple[ForIndex, ...]
    body: tuple[Equation, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class IfEquation:
    branches: tuple[tuple[Expr, tuple[Equation, ...]], ...]
    otherwise: tuple[Equation, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class CallEquation:
    """A call standing as an equation, such as ``assert(...)``."""

    call: Call
    span: Span


@dataclass(frozen=True, slots=True)
class WhenEquation:
    """``when c1 then ... elsewhen c2 then ... end when``: one (condition, body) per
    branch, in order (Modelica 3.6, 8.3.5)."""

    branches: tuple[tuple[Expr, tuple[Equation, ...]], ...]
    span: Span


@dataclass(frozen=True, slots=True)
class AlgorithmSection:
    """An ``algorithm`` (or ``initial algorithm``) section of a model or block, kept
    among the class's (initial) equations in order; section 11.1 of the specification."""

    body: tuple[Statement, ...]
    span: Span


Equation = (Equality | Connect | ForEquation | IfEquation | CallEquation | WhenEquation
            | AlgorithmSection)

# ----------------------------------------------------------------- statements


@dataclass(frozen=True, slots=True)
class Assign:
    """``target := value``; ``(a, b) := f(x)`` has several targets (``None`` for a gap)."""

    targets: tuple[Ref | None, ...]
    value: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class IfStatement:
    branches: tuple[tuple[Expr, tuple[Statement, ...]], ...]
    otherwise: tuple[Statement, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class ForStatement:
    indices: tuple[ForIndex, ...]
    body: tuple[Statement, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class CallStatement:
    """A call standing as a statement, such as ``assert(...)``."""

    call: Call
    span: Span


@dataclass(frozen=True, slots=True)
class WhileStatement:
    condition: Expr
    body: tuple[Statement, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Jump:
    """``break`` or ``return`` (``kind``)."""

    kind: str
    span: Span


@dataclass(frozen=True, slots=True)
class WhenStatement:
    """``when c then ... elsewhen d then ... end when;`` in an algorithm (11.2.7)."""

    branches: tuple[tuple[Expr, tuple[Statement, ...]], ...]
    span: Span


Statement = (Assign | IfStatement | ForStatement | CallStatement | WhileStatement | Jump
             | WhenStatement)

# -------------------------------------------------------------------- classes


@dataclass(frozen=True, slots=True)
class ClassDef:
    """A class of any kind (``model``, ``connector``, ``record``, ``package``, ``type``,
    ``function``, ``block``, ``class``). A short definition has ``short`` set and no
    elements. ``annotation`` keeps the class annotation (for ``experiment``)."""

    name: str
    kind: str
    partial: bool
    encapsulated: bool
    description: str
    elements: tuple[Element, ...]
    equations: tuple[Equation, ...]
    initial_equations: tuple[Equation, ...]
    algorithm: tuple[Statement, ...]
    short: ShortDef | None
    annotation: Modification | None
    protected: bool
    span: Span
    # The literals of `type E = enumeration(a, b)`, in order (values 1, 2, ...).
    enumeration: tuple[str, ...] | None = None
    replaceable: bool = False
    redeclare: bool = False  # an element `redeclare model M = T;` of an extending class
    # `model extends M ... end M;` (section 7.3.1): its first element `extends M(...)`
    # names the class M that the enclosing class inherits.
    class_extends: bool = False
    # `constrainedby T(...)` of a replaceable class (Modelica 7.3.2)
    constraint: tuple[Ref, Modification | None] | None = None
    final: bool = False  # declared `final model M ...`: it cannot be redeclared
    inner: bool = False  # `inner function f = B;` (section 5.4)
    outer: bool = False  # `outer function f = A;`: the inner class of an enclosing instance
    # Constructs outside springc's subset written in this class (``... not supported
    # yet`` errors, errors.ParseError), reported when a model uses the class.
    unsupported: tuple[ParseError, ...] = ()
    # `external "C" ...` of a function springc evaluates natively (ir.native_externals)
    external: ExternalCall | None = None
    # `expandable connector C ... end C;` (section 9.1.3)
    expandable: bool = False
    # `operator record`, `operator '+'`, `operator function` (section 14): outside the
    # subset, but their static rules are checked (flatten/checks/unsupported_rules.py)
    operator: bool = False


Element = Component | Extends | Import | ClassDef


@dataclass(frozen=True, slots=True)
class ExternalCall:
    """The external clause of a function springc evaluates natively
    (``external "C" y = name(a, b)``, section 12.9): the foreign function's name, the
    output it assigns, and its arguments as written; ``annotation`` is the clause's own
    (``Include``, ``IncludeDirectory``, ``Library``, ``LibraryDirectory``: 12.9.4)."""

    language: str
    name: str
    output: str | None
    args: tuple[Expr, ...]
    span: Span
    annotation: Modification | None = None


@dataclass(frozen=True, slots=True)
class StoredDefinition:
    """One parsed file: an optional ``within`` path and its top-level classes."""

    file: str
    within: tuple[str, ...] | None
    classes: tuple[ClassDef, ...]


def _pickled_as_calls(cls: type) -> None:
    """Pickle the nodes of ``cls`` as a call of the class on its field values: loading
    one is one call of its ``__init__``, where the generic state of a slotted dataclass
    walks ``fields()`` per node (0.5 s of the 0.6 s that loading the 44 parsed files of
    an MSL example took, ``parse.parse_cache``'s store on disk)."""
    names = tuple(f.name for f in fields(cls))
    values = attrgetter(*names)
    reduce: Callable[[Any], tuple[type, tuple[Any, ...]]]
    if len(names) == 1:
        reduce = lambda node: (type(node), (values(node),))  # noqa: E731
    else:
        reduce = lambda node: (type(node), values(node))  # noqa: E731
    cls.__reduce__ = reduce  # type: ignore[assignment, method-assign]


for _node in (Number, Bool, String, RefPart, Ref, Colon, End, Unary, Binary, IfExpr,
              NamedArg, Call, ForIndex, Comprehension, ArrayLit, MatrixLit, Range, Tuple,
              FieldOf, Modification, ElementModification, Component, Extends, Import,
              ShortDef, Equality, Connect, ForEquation, IfEquation, CallEquation,
              WhenEquation, AlgorithmSection, Assign, IfStatement, ForStatement,
              CallStatement, WhileStatement, Jump, WhenStatement, ClassDef, ExternalCall,
              StoredDefinition):
    _pickled_as_calls(_node)
