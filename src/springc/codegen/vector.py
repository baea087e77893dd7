"""Large systems -> loops over groups of same-shaped assignments (the vector layout).

Input: the explicit assignments of an ode.ODE (chains, cloths: thousands of them);
output: the bodies of ``rhs``, ``jacobian_values`` and ``observed`` whose size grows
with the number of distinct *shapes* of assignment, not with the number of masses.

Every assignment ``v := e`` becomes a shape (``e`` with each variable replaced by a
slot ``$0, $1, ...``) and operands (the array and index each slot reads: states
``x``, parameters ``p``, intermediate values ``w``, derivatives ``dx``). Assignments
of equal shape whose operands are ready at the same dependency level form a group;
members are ordered by their subscripts (``s[2]`` before ``s[10]``), so the
indices of chains and grids advance by constant strides. A run of members with
constant strides becomes one loop (numba) or one slice expression (numpy); other
members read their indices from the table ``_I``. The C model (:mod:`.c_model`) prints
the same loops in C (``c=True``: ``for`` loops, fixed-size work arrays, the tables as
``static const`` arrays), so one grouping serves the numba module and the C file.

The Jacobian is forward-mode over the same groups: each loop also stores the partial
derivatives of its shape in ``D``, and a precomputed tape of multiply-adds
``G[target] += D[partial] * G[source]`` (``G[0] = 1``) accumulates the gradient
entries; ``jacobian_values`` gathers them in CSC order.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import Span
from ..ir import ode
from ..ir.expr import ZERO, BinOp, Call, Const, Expr, If, Neg, Not, Time, Var, diff, to_text
from .c_printer import c_comment, c_function_body
from .context import CodegenBug, CodegenContext
from .locate import untranslatable
from .printer import NumpyWriter, function_lines
from .statements import Let, Store, escaped

VECTOR_THRESHOLD = 300
"""Systems with at least this many explicit assignments use the vector layout."""
MIN_RUN = 8
"""Shorter runs of constant strides go to the index table instead of a loop."""

_ARRAY = {"x": "x", "p": "p", "w": "w", "d": "dx", "c": "_F"}


def vector_suits(system: ode.ODE, threshold: int = VECTOR_THRESHOLD) -> bool:
    """Whether ``system``'s functions take the vector layout: at least ``threshold``
    steps, all explicit assignments (the one policy of the Python modules and the C
    file; a model with events or delays keeps scalar statements: its callers check)."""
    return (len(system.steps) >= threshold
            and all(isinstance(s, ode.Assign) for s in system.steps))


def vector_statements(m: CodegenContext, outputs: Sequence[str]
                      ) -> list[tuple[str, Expr, Span]]:
    """The assignments of ``rhs`` and ``observed`` (``outputs``) for the layout: the
    system's steps, then the aliases the derivatives and outputs read."""
    statements = [(s.name, s.expr, s.span) for s in m.ode.steps if isinstance(s, ode.Assign)]
    computed = {s[0] for s in statements}
    wanted = [d for d in m.derivatives if d not in computed] + list(outputs)
    for let in m.alias_stmts(wanted):
        assert isinstance(let, Let)
        statements.append((let.name, let.expr, m.aliases[let.name].span))
    return statements


def parameters_suit(m: CodegenContext) -> bool:
    """Whether ``parameters`` and ``start`` take the vector layout (constants lifted
    into a table): many parameters and states, no Newton guesses, no events."""
    return (m.guess_slots == {} and len(m.params) + len(m.states) >= VECTOR_THRESHOLD
            and m.events is None)


@dataclass
class _Assignment:
    name: str
    shape: Expr
    slots: list[str]  # the variable read by each slot
    kinds: tuple[str, ...]
    level: int
    expr: Expr  # the assignment's expression and location: its comment (read by
    span: Span  # the first member of each loop only, so written on demand)
    group: int  # assignments of one level, shape and operand kinds share it
    order: tuple[str, tuple[int, ...], tuple[int, ...]]  # loop order (see _order)
    out: tuple[str, int] = ("w", -1)
    operands: list[tuple[str, int]] = field(default_factory=list)

    @property
    def comment(self) -> str:
        return f"{self.name} := {to_text(self.expr)}  {self.span.file}:{self.span.line}"


@dataclass
class _Run:
    members: list[_Assignment]  # in loop order (row-major for 2-D runs)
    access: list[Callable[[str], str]]  # per slot (0: output, k + 1: slot k): "q" -> text
    dims: list[int]  # loop sizes: [] (one member), [count] or [rows, columns]


_SUBSCRIPT = re.compile(r"\[([0-9, ]+)\]")


def _order(name: str) -> tuple[str, tuple[int, ...], tuple[int, ...]]:
    """Members' loop order: by name pattern, then a trailing vector component
    (``pos[2]`` in ``p[3,4].pos[2]``), then the other subscripts in order."""
    parts = _SUBSCRIPT.split(name)  # text, subscripts, text, ...: one scan of the name
    if len(parts) == 1:
        return name, (), ()
    groups = [tuple(int(i) for i in g.split(",")) for g in parts[1::2]]
    component = groups.pop() if len(groups) > 1 else ()
    return "[]".join(parts[::2]), component, tuple(i for g in groups for i in g)


_LIFTED_OPS = frozenset("+-*/")
"""Operators whose constant operands :class:`VectorLayout` may lift into ``_F``: their
value is the same whether the constant is a literal or a float read from the table
(Modelica's ``/`` divides reals; ``^``'s integer exponents and call arguments stay)."""


def _liftable(e: Expr) -> bool:
    return isinstance(e, Const) and type(e.value) in (int, float) \
        and (type(e.value) is float or abs(e.value) < 2 ** 53)  # exactly a float


def _shape(e: Expr, slots: list[str], lift: Callable[[float], str] | None = None,
           every: bool = False) -> Expr:
    """``e`` with each variable replaced by a slot ``$k`` (``slots[k]``: its name);
    with ``lift``, also constants (``lift(value)``: the name of its slot): every number
    where ``every`` (the C model: doubles either way), else the constant operands of
    ``+ - * /`` that are exactly a float, so that ``L * 110`` and ``L * 111`` have one
    shape."""
    if isinstance(e, Var):
        slots.append(e.name)
        return _slot(len(slots) - 1)
    if every and lift is not None and isinstance(e, Const) \
            and isinstance(e.value, (int, float)) and not isinstance(e.value, bool):
        slots.append(lift(float(e.value)))
        return _slot(len(slots) - 1)
    if isinstance(e, (Const, Time)):
        return e
    if isinstance(e, (Neg, Not)):
        return type(e)(_shape(e.arg, slots, lift, every))
    if isinstance(e, BinOp):
        if lift is not None and not every and e.op in _LIFTED_OPS:
            operands = [Var(lift(float(o.value))) if _liftable(o) else o  # type: ignore[union-attr]
                        for o in (e.left, e.right)]
            return BinOp(e.op, _shape(operands[0], slots, lift),
                         _shape(operands[1], slots, lift))
        return BinOp(e.op, _shape(e.left, slots, lift, every),
                     _shape(e.right, slots, lift, every))
    if isinstance(e, Call):
        return Call(e.name, tuple(_shape(a, slots, lift, every) for a in e.args))
    if isinstance(e, If):
        return If(_shape(e.cond, slots, lift, every), _shape(e.then, slots, lift, every),
                  _shape(e.otherwise, slots, lift, every))
    raise untranslatable(f"cannot generate code for {type(e).__name__} expressions", e)


_SLOTS: list[Var] = []
"""``$0, $1, ...``: made once per process, not once per operand of every assignment."""


def _slot(k: int) -> Var:
    while len(_SLOTS) <= k:
        _SLOTS.append(Var(f"${len(_SLOTS)}"))
    return _SLOTS[k]


def _fixed(text: str) -> Callable[[str], str]:
    return lambda q: text


class VectorLayout:
    """The grouped form of a system of explicit assignments, for one backend."""

    def __init__(self, m: CodegenContext, statements: Sequence[tuple[str, Expr, Span]],
                 numba: bool, table_name: str = "_I", lift_constants: bool = False,
                 c: bool = False, float_name: str = "_F") -> None:
        # numba and C print loops with indices; numpy prints slices and gathers
        self.m, self.numba, self.c, self.table_name = m, numba or c, c, table_name
        self.arrays = {**_ARRAY, "c": float_name}
        self.table: list[int] = []
        self.floats: list[float] = []
        self.location: dict[str, tuple[str, int]] = {}
        self.location.update({s: ("x", i) for i, s in enumerate(m.states)})
        self.location.update({q: ("p", i) for i, q in enumerate(m.params)})
        self.location.update({d: ("d", i) for i, d in enumerate(m.derivatives)})
        self.assignments: dict[str, _Assignment] = {}
        self._needed: dict[tuple[str, ...], list[_Assignment]] = {}
        groups: dict[tuple[object, ...], int] = {}  # compared once here, not per grouping
        for name, e, span in statements:
            slots: list[str] = []
            if lift_constants and c:
                # Every number becomes data (C's doubles either way), so that
                # bindings such as L * 2, L * 3, ... group whatever their numbers.
                shape: Expr = _shape(e, slots, self._lift, every=True)
            elif lift_constants and isinstance(e, Const) and not isinstance(e.value, bool):
                # Constant values become data (_F), so they group whatever their value.
                slots.append(self._lift(float(e.value)))
                shape = Var("$0")
            else:
                shape = _shape(e, slots, self._lift if lift_constants else None)
            level, kinds = self._reads(name, slots)
            self.assignments[name] = _Assignment(
                name, shape, slots, kinds, level, e, span,
                groups.setdefault((level, shape, kinds), len(groups)), _order(name))
        # Intermediate values get slots of w group by group, in natural name order.
        self.w_names: list[str] = []
        for group in self._groups(list(self.assignments.values())):
            for a in group:
                if a.name in self.location:
                    a.out = self.location[a.name]
                else:
                    a.out = ("w", len(self.w_names))
                    self.location[a.name] = a.out
                    self.w_names.append(a.name)
        for a in self.assignments.values():
            a.operands = [self.location[v] for v in a.slots]

    def _lift(self, value: float) -> str:
        """The slot name of a constant ``value`` read from ``_F``."""
        name = f"#{len(self.floats)}"
        self.location[name] = ("c", len(self.floats))
        self.floats.append(value)
        return name

    def _reads(self, name: str, slots: list[str]) -> tuple[int, tuple[str, ...]]:
        """The dependency level of an assignment ``name`` reading ``slots`` (one more
        than the deepest assignment it reads) and the kind of array each slot reads
        (one pass over the slots: this runs for every assignment of a chain)."""
        level = 0
        kinds: list[str] = []
        for v in slots:
            done = self.assignments.get(v)
            if done is not None and done.level > level:
                level = done.level
            where = self.location.get(v)
            if where is not None:
                kinds.append(where[0])
            elif done is None:
                raise CodegenBug(f"'{name}' reads '{v}', which nothing computes")
            else:
                kinds.append("d" if v in self.m.derivative_set else "w")
        return level + 1, tuple(kinds)

    @staticmethod
    def _groups(assignments: list[_Assignment]) -> list[list[_Assignment]]:
        groups: dict[int, list[_Assignment]] = {}
        for a in assignments:
            groups.setdefault(a.group, []).append(a)
        ordered = sorted(groups.values(), key=lambda g: g[0].level)
        return [sorted(g, key=lambda a: a.order) for g in ordered]

    def needed(self, targets: Sequence[str]) -> list[_Assignment]:
        """The assignments that ``targets`` depend on (found once per list of targets:
        ``rhs`` and the Jacobian ask for the derivatives' three times)."""
        key = tuple(targets)
        if key not in self._needed:
            self._needed[key] = self._dependencies(targets)
        return list(self._needed[key])

    def _dependencies(self, targets: Sequence[str]) -> list[_Assignment]:
        seen: set[str] = set()
        stack = [t for t in targets if t in self.assignments]
        while stack:
            name = stack.pop()
            if name in seen:
                continue
            seen.add(name)
            stack += [v for v in self.assignments[name].slots if v in self.assignments]
        return [a for a in self.assignments.values() if a.name in seen]

    # ------------------------------------------------------------ runs

    def _index(self, values: Sequence[int]) -> int:
        offset = len(self.table)
        self.table.extend(values)
        return offset

    def _runs(self, group: list[_Assignment]) -> list[_Run]:
        """Loops over ``group``: affine runs (merged into 2-D blocks when rows repeat
        with a constant offset) for numba; one slice or one gather for numpy."""
        matrix = np.array([[a.out[1]] + [o[1] for o in a.operands] for a in group],
                          dtype=np.int64).reshape(len(group), -1)
        arrays = [self.arrays[group[0].out[0]]] + [self.arrays[k] for k in group[0].kinds]
        spans: list[tuple[int, int]] = []  # maximal runs of constant strides
        # Row differences compared once, for the whole group (not per row pair):
        # forward[k]: the stride from row k to k + 1 is >= 0 and moves the output;
        # same[k]: the stride from row k + 1 equals the one from row k.
        strides = matrix[1:] - matrix[:-1]
        forward = ((strides >= 0).all(axis=1) & (strides[:, 0] > 0)).tolist()
        same = (strides[1:] == strides[:-1]).all(axis=1).tolist()
        i = 0
        while i < len(group):
            j = i + 1
            if j < len(group) and forward[i]:
                j += 1
                while j < len(group) and same[j - 2]:
                    j += 1
            spans.append((i, j))
            i = j
        if len(spans) == 1:
            i, j = spans[0]
            step = matrix[1] - matrix[0] if j - i > 1 else matrix[0] * 0
            return [self._affine(group, matrix[0], [(j - i, step)], arrays)]
        if not self.numba:
            return [self._tabled(group, matrix, arrays)]
        runs: list[_Run] = []
        table = [t for i, j in spans if j - i < MIN_RUN for t in range(i, j)]
        spans = [(i, j) for i, j in spans if j - i >= MIN_RUN]
        k = 0
        while k < len(spans):
            i, j = spans[k]
            step = matrix[i + 1] - matrix[i]
            # Step 2: rows of equal length and stride, each offset by the same amount.
            rows = 1
            while k + rows < len(spans):
                a, b = spans[k + rows]
                if (b - a != j - i or not (matrix[a + 1] - matrix[a] == step).all()
                        or not (matrix[a] - matrix[spans[k + rows - 1][0]]
                                == matrix[spans[k + 1][0]] - matrix[i]).all()):
                    break
                rows += 1
            members = [m for lo, hi in spans[k:k + rows] for m in group[lo:hi]]
            dims = [(j - i, step)] if rows == 1 else [
                (rows, matrix[spans[k + 1][0]] - matrix[i]), (j - i, step)]
            runs.append(self._affine(members, matrix[i], dims, arrays))
            k += rows
        if table:
            runs.append(self._tabled([group[t] for t in table], matrix[table], arrays))
        return runs

    def _affine(self, members: list[_Assignment], start: np.ndarray,
                dims: list[tuple[int, np.ndarray]], arrays: list[str]) -> _Run:
        n = len(members)
        loops = ["_r", "_q"][-len(dims):]
        sizes = [count for count, _ in dims]

        def access(array: str, slot: int) -> Callable[[str], str]:
            a = int(start[slot])
            if n == 1:
                return lambda q: f"{array}[{a}]"
            if self.numba:
                terms = [str(a)] if a else []
                for var, (_, stride) in zip(loops, dims):
                    s = int(stride[slot])
                    if s:
                        terms.append(var if s == 1 else f"{s} * {var}")
                text = " + ".join(terms) or "0"
                return lambda q: f"{array}[{text}]"
            s = int(dims[0][1][slot])  # numpy: one dimension (see _runs)
            if s == 0:
                return lambda q: f"{array}[{a}]"
            stop = a + s * (n - 1) + 1
            return lambda q: f"{array}[{a}:{stop}{'' if s == 1 else f':{s}'}]"

        return _Run(members, [access(arr, k) for k, arr in enumerate(arrays)],
                    sizes if n > 1 else [])

    def _tabled(self, members: list[_Assignment], matrix: np.ndarray,
                arrays: list[str]) -> _Run:
        n = len(members)

        def access(array: str, column: np.ndarray) -> Callable[[str], str]:
            if self.numba and n == 1:  # no loop around a single member: its own index
                return lambda q: f"{array}[{int(column[0])}]"
            offset = self._index(column.tolist())
            t = self.table_name
            if self.numba:
                return lambda q: f"{array}[{t}[{offset} + {q}]]"
            return lambda q: f"{array}[{t}[{offset}:{offset + n}]]"

        return _Run(members, [access(arr, matrix[:, k]) for k, arr in enumerate(arrays)],
                    [n] if n > 1 else [])

    # ------------------------------------------------------------ printing

    def _loop(self, run: _Run, stores: list[tuple[Callable[[str], str], Expr]],
              helpers: set[str], lines: list[str]) -> None:
        """``stores`` of (target access, expression over slots) for every member."""
        first = run.members[0]
        count = len(run.members)
        if self.c:
            text = c_comment(f"{count} x {first.comment}" if count > 1 else first.comment)
            lines.append(f"    /* {text} */")
        else:
            comment = escaped(first.comment)
            lines.append(f"    # {count} x {comment}" if count > 1 else f"    # {comment}")
        looped = self.numba and count > 1
        names = {f"${k}": acc("_q") for k, acc in enumerate(run.access[1:])}
        stmts = [Store(target("_q"), e) for target, e in stores]
        indent = "    "
        loops = list(zip(["_r", "_q"][-len(run.dims):], run.dims)) if looped else []
        for var, size in loops:
            lines.append(f"{indent}for (int {var} = 0; {var} < {size}; {var}++) {{"
                         if self.c else f"{indent}for {var} in range({size}):")
            indent += "    "
        if self.c:
            lines += c_function_body(lambda n: names.get(n, n), helpers, stmts, indent)
            lines += [f"{'    ' * k}}}" for k in range(len(loops), 0, -1)]
            return
        writer = None if self.numba else NumpyWriter
        lines += function_lines(lambda n: names.get(n, n), helpers, stmts, indent, writer)

    def _sizes(self, needed: Sequence[_Assignment], dx: bool) -> list[tuple[str, int]]:
        kinds = {a.out[0] for a in needed} | {k for a in needed for k in a.kinds}
        sizes = [("w", max(1, len(self.w_names)))] if "w" in kinds else []
        if "d" in kinds and dx:
            sizes.append(("dx", len(self.m.states)))
        return sizes

    def _arrays(self, needed: Sequence[_Assignment], dx: bool = True) -> list[str]:
        """The work arrays ``needed`` writes: ``w``, and ``dx`` unless ``dx`` is False
        (the caller's own array: C's ``springc_rhs``)."""
        if self.c:
            return [f"    double {name}[{size}];" for name, size in self._sizes(needed, dx)]
        return [f"    {name} = np.empty({size})" for name, size in self._sizes(needed, dx)]

    def work_doubles(self, targets: Sequence[str], dx: bool = True) -> int:
        """The doubles of :meth:`body`'s work arrays for ``targets`` (C: on the stack)."""
        return sum(size for _, size in self._sizes(self.needed(targets), dx))

    def body(self, targets: Sequence[str], helpers: set[str],
             after_level: Sequence[str] = (), dx: bool = True,
             kept: Callable[[str], str] | None = None) -> list[str]:
        """Statements computing ``targets`` (and what they read) into ``w``/``dx``;
        ``after_level`` lines run after each dependency level. ``dx`` False: the
        caller holds ``dx`` (C). ``kept`` (C): the text of a condition on an output's
        index (``q``) under which the output keeps its value (a given parameter)."""
        needed = self.needed(targets)
        lines = self._arrays(needed, dx)
        level = None
        for group in self._groups(needed):
            if level is not None and group[0].level != level:
                lines += after_level
            level = group[0].level
            for run in self._runs(group):
                shape = run.members[0].shape
                if kept is not None:  # two more slots: the condition, the old value
                    slot = len(run.access) - 1
                    condition: str = kept(run.access[0]("_q"))
                    run.access += [_fixed(condition), run.access[0]]
                    shape = If(Var(f"${slot}"), Var(f"${slot + 1}"), shape)
                self._loop(run, [(run.access[0], shape)], helpers, lines)
        return lines + list(after_level)

    def jacobian_body(self, helpers: set[str]) -> tuple[list[str], list[tuple[int, int]]]:
        """Primal values, partials ``D``, the tape into ``G``, then ``jv`` in CSC order."""
        lines = self._arrays(self.needed(self.m.derivatives))
        partial_index: dict[tuple[str, int], int] = {}
        nd = 0
        order: list[_Assignment] = []
        for group in self._groups(self.needed(self.m.derivatives)):
            shape = group[0].shape
            partials = [(k, diff(shape, f"${k}")) for k in range(len(group[0].slots))
                        if group[0].kinds[k] in ("x", "w", "d")]
            partials = [(k, pd) for k, pd in partials if pd != ZERO]
            for run in self._runs(group):
                stores: list[tuple[Callable[[str], str], Expr]] = [(run.access[0], shape)]
                for k, pd in partials:
                    base = nd
                    nd += len(run.members)
                    for q, a in enumerate(run.members):
                        partial_index[(a.name, k)] = base + q
                    stores.append((self._d_access(base, run.dims), pd))
                self._loop(run, stores, helpers, lines)
                order += run.members
        # The tape: gradient entries per variable, multiply-adds ordered by level.
        entries: dict[str, dict[int, int]] = {s: {j: 0} for j, s in enumerate(self.m.states)}
        ops: list[tuple[int, int, int, int]] = []
        count = 1
        for a in sorted(order, key=lambda a: a.level):
            mine = entries.setdefault(a.name, {})
            for k, v in enumerate(a.slots):
                d = partial_index.get((a.name, k))
                if d is None:
                    continue
                for j, src in entries.get(v, {}).items():
                    if j not in mine:
                        mine[j] = count
                        count += 1
                    ops.append((a.level, mine[j], d, src))
        pattern = sorted(((row, col, e) for row, der in enumerate(self.m.derivatives)
                          for col, e in entries.get(der, {}).items()),
                         key=lambda r: (r[1], r[0]))
        lines += [f"    G = np.zeros({count})", "    G[0] = 1.0"]
        lines += self._tape(ops)
        offset = self._index([e for _, _, e in pattern])
        lines.append(f"    jv = G[_I[{offset}:{offset + len(pattern)}]]")
        lines.insert(0, f"    D = np.empty({max(1, nd)})")
        return lines, [(r, c) for r, c, _ in pattern]

    def _d_access(self, base: int, dims: list[int]) -> Callable[[str], str]:
        if not dims:
            return lambda q: f"D[{base}]"
        if not self.numba:
            return lambda q: f"D[{base}:{base + int(np.prod(dims))}]"
        if len(dims) == 2:
            return lambda q: f"D[{base} + {dims[1]} * _r + _q]"
        return lambda q: f"D[{base} + _q]"

    def _tape(self, ops: list[tuple[int, int, int, int]]) -> list[str]:
        if not ops:
            return []
        t = self._index([o[1] for o in ops])
        d = self._index([o[2] for o in ops])
        s = self._index([o[3] for o in ops])
        if self.numba:
            return ["    # chain rule: G[target] += D[partial] * G[source], by level",
                    f"    for _e in range({len(ops)}):",
                    f"        G[_I[{t} + _e]] += D[_I[{d} + _e]] * G[_I[{s} + _e]]"]
        lines = ["    # chain rule: G[target] += D[partial] * G[source], level by level"]
        start = 0
        levels = [o[0] for o in ops]
        while start < len(ops):
            end = start
            while end < len(ops) and levels[end] == levels[start]:
                end += 1
            lines.append(f"    G += np.bincount(_I[{t + start}:{t + end}], "
                         f"weights=D[_I[{d + start}:{d + end}]] * G[_I[{s + start}:{s + end}]],"
                         f" minlength=G.shape[0])")
            start = end
        return lines

    def gather(self, names: Sequence[str]) -> list[str]:
        """``out`` holding ``names`` (computed by :meth:`body`; C: the caller's ``out``)."""
        w = [self.location[n] for n in names]
        t = self.table_name
        lines = [] if self.c else [f"    out = np.empty({len(names)})"]
        for kind in ("w", "d", "x", "p"):
            pos = [i for i, (k, _) in enumerate(w) if k == kind]
            if not pos:
                continue
            src = self._index([w[i][1] for i in pos])
            dst = self._index(pos)
            array = self.arrays[kind]
            if self.c:
                lines += [f"    for (int _q = 0; _q < {len(pos)}; _q++) "
                          f"out[{t}[{dst} + _q]] = {array}[{t}[{src} + _q]];"]
            elif self.numba:
                lines += [f"    for _q in range({len(pos)}):",
                          f"        out[{t}[{dst} + _q]] = {array}[{t}[{src} + _q]]"]
            else:
                lines.append(f"    out[{t}[{dst}:{dst + len(pos)}]] = "
                             f"{array}[{t}[{src}:{src + len(pos)}]]")
        return lines
