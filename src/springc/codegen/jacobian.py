"""Steps of the simplified system -> statements computing the analytic Jacobian.

Forward-mode differentiation through the steps: every computed variable ``v`` gets a
sparse gradient ``{state index: expression}``; for ``v := e`` the chain rule gives
``dv/dx_j = sum_u de/du * du/dx_j`` over the variables ``u`` of ``e`` (``expr.diff``),
and only structurally non-zero entries exist. Non-trivial entries are bound to locals
(``d_spring_x_d_mass_pos_1``), so the generated code grows with the number of
non-zeros, linearly for chains and grids.

Linear blocks ``A y = b`` use ``dy/dx = A^-1 (db/dx - dA/dx y)``; torn nonlinear
blocks use the implicit function theorem on the residuals with the tearing variables
held fixed, then propagate the tearing variables' gradients through the inner
assignments.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import CodegenError
from ..ir import ode
from ..ir.expr import ONE, ZERO, BinOp, Const, Expr, Neg, Var, add, diff, mul, neg, sub, variables
from .statements import Block, Let, Load, Raw, Stmt, Store, guarded_solve

Grad = dict[int, Expr]


def _atomic(e: Expr) -> bool:
    return isinstance(e, (Const, Var)) or (isinstance(e, Neg) and isinstance(e.arg, (Const, Var)))


class JacobianBuilder:
    """Accumulates the statements of ``jacobian_values`` after the primal steps."""

    def __init__(self, states: Sequence[str]) -> None:
        self.states = list(states)
        self.grads: dict[str, Grad] = {s: {i: ONE} for i, s in enumerate(states)}
        self.stmts: list[Stmt] = []

    # ------------------------------------------------------------ chain rule

    def grad_of(self, e: Expr) -> Grad:
        """The gradient of ``e`` from the gradients of its variables."""
        terms: dict[int, list[Expr]] = {}
        for u in sorted(variables(e)):
            gu = self.grads.get(u)
            if not gu:
                continue
            pd = diff(e, u)
            if pd == ZERO:
                continue
            for j, g in gu.items():
                terms.setdefault(j, []).append(mul(pd, g))
        out: Grad = {}
        for j in sorted(terms):
            total: Expr = ZERO
            for term in terms[j]:
                total = add(total, term)
            if total != ZERO:
                out[j] = total
        return out

    def bind(self, name: str, grad: Grad, comment: str, into: list[Stmt] | None = None) -> None:
        """Record ``grad`` as the gradient of ``name``, naming non-trivial entries."""
        target = self.stmts if into is None else into
        named: Grad = {}
        for j, e in grad.items():
            if _atomic(e):
                named[j] = e
                continue
            gname = f"d({name})/d({self.states[j]})"
            target.append(Let(gname, e, comment))
            named[j] = Var(gname)
        self.grads[name] = named

    # ------------------------------------------------------------ steps

    def assign(self, step: ode.Assign, comment: str) -> None:
        self.bind(step.name, self.grad_of(step.expr), comment)

    def linear(self, block: ode.LinearBlock, index: int, comment: str) -> None:
        """Gradients of the unknowns of ``A y = b`` (``_A{index}`` from the primal)."""
        n = len(block.names)
        columns: dict[int, list[Expr]] = {}
        for i, rhs in enumerate(block.rhs):
            for j, g in self.grad_of(rhs).items():
                columns.setdefault(j, [ZERO] * n)[i] = g
        for i, k, entry in block.matrix:
            for j, g in self.grad_of(entry).items():
                col = columns.setdefault(j, [ZERO] * n)
                col[i] = sub(col[i], mul(g, Var(block.names[k])))
        if not columns:
            for name in block.names:
                self.grads[name] = {}
            return
        order = sorted(columns)
        body: list[Stmt] = [Raw(f"_C{index} = np.zeros(({n}, {len(order)}))")]
        for c, j in enumerate(order):
            body += [Store(f"_C{index}[{i}, {c}]", e) for i, e in enumerate(columns[j])
                     if e != ZERO]
        body.append(Raw(guarded_solve(f"_Y{index}", f"_A{index}", f"_C{index}",
                                      f"({n}, {len(order)})")))
        defines = set()
        for k, name in enumerate(block.names):
            grad: Grad = {}
            for c, j in enumerate(order):
                gname = f"d({name})/d({self.states[j]})"
                body.append(Load(gname, f"_Y{index}[{k}, {c}]", comment))
                grad[j] = Var(gname)
                defines.add(gname)
            self.grads[name] = grad
        self.stmts.append(Block(body, f"derivatives of the {comment}", defines,
                                {f"_A{index}", *block.names}))

    def nonlinear(self, block: ode.NonlinearBlock, index: int, comment: str) -> None:
        """Implicit-function derivatives of a torn block (its primal solved already)."""
        body: list[Stmt] = []
        k = len(block.tearing)
        # Step 1: inner variables and residuals with the tearing variables held fixed.
        for t in block.tearing:
            self.grads[t] = {}
        for a in block.inner:
            self.bind(a.name, self.grad_of(a.expr), comment, body)
        residual_grads = [self.grad_of(r) for r in block.residuals]
        # Step 2: d(tearing)/dx = -J^-1 d(residual)/dx, J at the converged point.
        body += [Let(s.name, s.expr, "sensitivity") for s in block.sensitivities]
        entries = {(i, j): e for i, j, e in block.jacobian}
        order = sorted({j for g in residual_grads for j in g})
        defines: set[str] = set()
        if k == 1:
            pivot = entries.get((0, 0))
            if pivot is None:
                raise CodegenError(f"the torn system for {block.tearing[0]} has no "
                                   "Jacobian entry")
            body.append(Let(f"_J{index}", pivot))
            grad: Grad = {}
            for j, g in residual_grads[0].items():
                gname = f"d({block.tearing[0]})/d({self.states[j]})"
                body.append(Let(gname, neg(BinOp("/", g, Var(f"_J{index}"))), comment))
                grad[j] = Var(gname)
                defines.add(gname)
            self.grads[block.tearing[0]] = grad
        elif order:
            body.append(Raw(f"_J{index} = np.zeros(({k}, {k}))"))
            body += [Store(f"_J{index}[{i}, {j}]", e) for (i, j), e in entries.items()]
            body.append(Raw(f"_R{index} = np.zeros(({k}, {len(order)}))"))
            for i, residual in enumerate(residual_grads):
                body += [Store(f"_R{index}[{i}, {c}]", residual[j])
                         for c, j in enumerate(order) if j in residual]
            body.append(Raw(guarded_solve(f"_S{index}", f"_J{index}", f"_R{index}",
                                          f"({k}, {len(order)})")))
            for i, t in enumerate(block.tearing):
                grad = {}
                for c, j in enumerate(order):
                    gname = f"d({t})/d({self.states[j]})"
                    body.append(Load(gname, f"-_S{index}[{i}, {c}]", comment))
                    grad[j] = Var(gname)
                    defines.add(gname)
                self.grads[t] = grad
        # Step 3: inner variables again, now through the tearing variables.
        for a in block.inner:
            self.bind(a.name, self.grad_of(a.expr), comment, body)
            defines |= {e.name for e in self.grads[a.name].values() if isinstance(e, Var)}
        self.stmts.append(Block(body, f"derivatives of the {comment}", defines))

    def alias(self, name: str, e: Expr) -> None:
        self.bind(name, self.grad_of(e), f"{name} (alias)")


def jacobian_statements(states: Sequence[str], derivatives: Sequence[str],
                        steps: Sequence[tuple[ode.Step, int, str]],
                        aliases: dict[str, Expr]) -> tuple[list[Stmt], list[tuple[int, int]]]:
    """Statements storing the non-zeros of ``d(der(x))/dx`` into ``jv`` in CSC order,
    and the pattern as ``(row, col)`` pairs in the same order."""
    builder = JacobianBuilder(states)
    for step, index, comment in steps:
        if isinstance(step, ode.Assign):
            builder.assign(step, comment)
        elif isinstance(step, ode.LinearBlock):
            builder.linear(step, index, comment)
        else:
            builder.nonlinear(step, index, comment)
    entries: list[tuple[int, int, Expr]] = []
    for row, der in enumerate(derivatives):
        if der not in builder.grads and der in aliases:
            builder.alias(der, aliases[der])
        for col, e in builder.grads.get(der, {}).items():
            entries.append((row, col, e))
    entries.sort(key=lambda entry: (entry[1], entry[0]))
    stmts = [*builder.stmts, Raw(f"jv = np.empty({len(entries)})")]
    stmts += [Store(f"jv[{k}]", e if e != ONE else Const(1.0),
                    f"d der({states[row]}) / d {states[col]}")
              for k, (row, col, e) in enumerate(entries)]
    return stmts, [(row, col) for row, col, _ in entries]
