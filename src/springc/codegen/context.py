"""Code generation: ode.ODE (+ flat.FlatModel) -> GeneratedModel (a Python module's text).

The module runs with numpy and scipy only (plus numba for the ``numba`` backend) and
exposes, over a state vector ``x``, a parameter vector ``p`` and Newton warm starts
``z``: ``parameters(values)``, ``start(p)``, ``guesses(p)``, ``rhs(t, x, p, z)``,
``jacobian_values``/``jacobian``/``jacobian_dense`` with the sparsity pattern
(``JAC_ROWS``, ``JAC_COLS``; ``JAC_INDICES``, ``JAC_INDPTR`` in CSC order),
``observed(t, x, p, z)`` and ``observed_grid(ts, X, p, z)`` for the requested observed
variables only, and the names, units and experiment settings as constants.

Every assignment carries a comment with its flat name and source ``file:line``;
common subexpressions are shared (:mod:`springc.codegen_print`); the Jacobian is
analytic (:mod:`springc.codegen_jac`). Systems of thousands of explicit assignments
(chains, cloths) use the vector layout of :mod:`springc.codegen_vector` instead, whose
code grows with the number of distinct equation shapes; :mod:`springc.codegen_module`
writes the rest of the module.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import Span
from ..ir import flat, ode
from ..ir.expr import ZERO, BinOp, Call, Const, Expr, Var, add, mul, sub, variables
from .jacobian import jacobian_statements
from .module_text import (
    _comment,
    _where,
    module_text,
    parameter_value,
    topological,
)
from .printer import (
    Block,
    CodegenError,
    Let,
    Load,
    Loop,
    Namer,
    Raw,
    Stmt,
    Store,
    function_lines,
)
from .vector import (
    VECTOR_THRESHOLD,
    VectorLayout,
)

BACKENDS = ("python", "numba")
NEWTON_ITERATIONS = 50
NEWTON_TOLERANCE = 1e-10


@dataclass(frozen=True)
class CodegenOptions:
    """``outputs``: observed variables to generate (``None``: all of them);
    ``vector``: loops over groups of same-shaped assignments (large systems)."""

    backend: str = "python"
    outputs: tuple[str, ...] | None = None
    vector: bool | None = None  # None: by size (codegen_vector.VECTOR_THRESHOLD)


@dataclass(frozen=True)
class GeneratedModel:
    """The text of a generated module and what it contains."""

    name: str
    source: str
    backend: str
    states: tuple[str, ...]
    observed: tuple[str, ...]
    parameters: tuple[str, ...]
    structural: tuple[str, ...]


class _Model:
    """Names and lookups shared by the generated functions."""

    def __init__(self, system: ode.ODE, flat_model: flat.FlatModel | None) -> None:
        self.ode = system
        self.states = [s.name for s in system.states]
        self.derivatives = [s.derivative for s in system.states]
        self.params = [q.name for q in system.parameters]
        self.param_set = set(self.params)
        self.derivative_set = set(self.derivatives)
        self.aliases = {a.name: a for a in system.observed}
        self.variables = {v.name: v for v in flat_model.variables} if flat_model else {}
        self.unknowns = {u.name: u for u in system.dae.unknowns}
        self.guess_slots: dict[str, int] = {}
        for step in system.steps:
            if isinstance(step, ode.NonlinearBlock):
                for t in step.tearing:
                    self.guess_slots[t] = len(self.guess_slots)

    def loads(self) -> list[Stmt]:
        out: list[Stmt] = [Load(n, f"p[{i}]", n) for i, n in enumerate(self.params)]
        out += [Load(n, f"x[{i}]", n) for i, n in enumerate(self.states)]
        return out

    def newton_systems(self) -> dict[int, tuple[str, ...]]:
        """Failure flag value -> tearing variables of that torn system."""
        return {i + 1: step.tearing for i, step in enumerate(self.ode.steps)
                if isinstance(step, ode.NonlinearBlock)}

    def type(self, name: str) -> str:
        v = self.variables.get(name)
        return v.type if v is not None else "Real"

    def unit(self, name: str) -> str:
        v = self.variables.get(name)
        if v is not None and v.attributes.unit:
            return v.attributes.unit
        u = self.unknowns.get(name)
        return (u.unit or "") if u is not None else ""

    # -------------------------------------------------------------- primal

    def step_stmts(self) -> tuple[list[Stmt], list[tuple[ode.Step, int, str]]]:
        stmts: list[Stmt] = []
        described: list[tuple[ode.Step, int, str]] = []
        for index, step in enumerate(self.ode.steps):
            if isinstance(step, ode.Assign):
                comment = _comment(step.name, step.span)
                stmts.append(Let(step.name, step.expr, comment))
            elif isinstance(step, ode.LinearBlock):
                comment = _block_comment("linear system for", step.names, step.spans)
                stmts.append(self._linear(step, index, comment))
            else:
                comment = _block_comment("nonlinear system, tearing", step.tearing, step.spans)
                stmts.append(self._nonlinear(step, index, comment))
            described.append((step, index, comment))
        return stmts, described

    def _linear(self, block: ode.LinearBlock, index: int, comment: str) -> Stmt:
        n = len(block.names)
        body: list[Stmt] = [Raw(f"_A{index} = np.zeros(({n}, {n}))")]
        body += [Store(f"_A{index}[{i}, {j}]", e) for i, j, e in block.matrix]
        body.append(Raw(f"_b{index} = np.empty({n})"))
        body += [Store(f"_b{index}[{i}]", e) for i, e in enumerate(block.rhs)]
        body.append(Raw(f"_y{index} = np.linalg.solve(_A{index}, _b{index})"))
        body += [Load(name, f"_y{index}[{k}]", name) for k, name in enumerate(block.names)]
        return Block(body, comment, {*block.names, f"_A{index}"})

    def _nonlinear(self, block: ode.NonlinearBlock, index: int, comment: str) -> Stmt:
        k = len(block.tearing)
        slots = [self.guess_slots[t] for t in block.tearing]
        body: list[Stmt] = [Load(t, f"float(z[{s}])", f"{t} (warm start)")
                            for t, s in zip(block.tearing, slots)]
        body.append(Raw(f"_ok{index} = False\n_done{index} = False"))
        loop: list[Stmt] = [Let(a.name, a.expr, _comment(a.name, a.span)) for a in block.inner]
        loop += [Let(f"_r{index}_{i}", r, "residual") for i, r in enumerate(block.residuals)]
        loop.append(Raw(f"if _done{index}:\n    _ok{index} = True\n    break"))
        loop += [Let(s.name, s.expr, "sensitivity") for s in block.sensitivities]
        entries = {(i, j): e for i, j, e in block.jacobian}
        if k == 1:
            pivot = entries.get((0, 0), ZERO)
            loop.append(Let(f"_d{index}_0", BinOp("/", Var(f"_r{index}_0"), pivot)))
        else:
            loop.append(Raw(f"_J{index} = np.zeros(({k}, {k}))"))
            loop += [Store(f"_J{index}[{i}, {j}]", e) for (i, j), e in entries.items()]
            loop.append(Raw(f"_R{index} = np.empty({k})"))
            loop += [Store(f"_R{index}[{i}]", Var(f"_r{index}_{i}")) for i in range(k)]
            loop.append(Raw(f"_D{index} = np.linalg.solve(_J{index}, _R{index})"))
            loop += [Load(f"_d{index}_{i}", f"_D{index}[{i}]") for i in range(k)]
        done: Expr | None = None
        for i, t in enumerate(block.tearing):
            loop.append(Let(t, sub(Var(t), Var(f"_d{index}_{i}")), f"{t} (Newton step)"))
            small = BinOp("<=", Call("abs", (Var(f"_d{index}_{i}"),)),
                          mul(Const(NEWTON_TOLERANCE), add(Const(1.0), Call("abs", (Var(t),)))))
            done = small if done is None else BinOp("and", done, small)
        assert done is not None
        loop.append(Let(f"_done{index}", done))
        body.append(Loop(f"for _it in range({NEWTON_ITERATIONS}):", loop))
        body.append(Raw(f"if not _ok{index}:\n    z[{len(self.guess_slots)}] = "
                        f"{float(index + 1)}"))
        body += [Store(f"z[{s}]", Var(t)) for t, s in zip(block.tearing, slots)]
        names = {*block.tearing, *(a.name for a in block.inner),
                 *(s.name for s in block.sensitivities)}
        return Block(body, comment, names)

    def alias_stmts(self, names: Sequence[str]) -> list[Stmt]:
        """Lets for the aliases among ``names`` and the aliases they read, in order."""
        out: list[Stmt] = []
        done: set[str] = set()

        def visit(name: str) -> None:
            if name in done or name not in self.aliases:
                return
            done.add(name)
            a = self.aliases[name]
            for v in sorted(variables(a.expr)):
                visit(v)
            out.append(Let(name, a.expr, f"{name} (alias)  {_where(a.span)}"))

        for n in names:
            visit(n)
        return out


def _block_comment(kind: str, names: Sequence[str], spans: Sequence[Span]) -> str:
    shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
    where = ", ".join(sorted({_where(s) for s in spans})[:4])
    return f"{kind} {shown}  {where}"


# ------------------------------------------------------------------ parameters


def structural_parameters(system: ode.ODE, flat_model: flat.FlatModel | None) -> list[str]:
    """Parameters that generated code cannot change: Integer and Boolean ones (they may
    size arrays or pick equations) and those the flattener already evaluated away."""
    used: set[str] = set()
    for step in system.steps:
        for e in _step_exprs(step):
            used |= variables(e)
    for a in system.observed:
        used |= variables(a.expr)
    for s in system.states:
        if s.start is not None:
            used |= variables(s.start)
    for u in system.dae.unknowns:
        if u.start is not None:
            used |= variables(u.start)
    by_name = {q.name: q for q in system.parameters}
    for q in reversed(topological(system.parameters)):
        if q.name in used:
            used |= variables(parameter_value(q))
    types = {v.name: v.type for v in flat_model.variables} if flat_model else {}
    return [q.name for q in system.parameters
            if q.name not in used or types.get(q.name, "Real") != "Real"
            or q.name not in by_name]


def _step_exprs(step: ode.Step) -> list[Expr]:
    if isinstance(step, ode.Assign):
        return [step.expr]
    if isinstance(step, ode.LinearBlock):
        return [e for _, _, e in step.matrix] + list(step.rhs)
    return ([a.expr for a in step.inner] + list(step.residuals)
            + [a.expr for a in step.sensitivities] + [e for _, _, e in step.jacobian])


# ------------------------------------------------------------------ module


def generate(system: ode.ODE, flat_model: flat.FlatModel | None = None,
             options: CodegenOptions = CodegenOptions()) -> GeneratedModel:
    """The Python module of ``system`` for ``options.backend``."""
    if options.backend not in BACKENDS:
        raise CodegenError(f"unknown backend '{options.backend}'",
                           hint=f"choose one of {', '.join(BACKENDS)}")
    m = _Model(system, flat_model)
    computed = system.step_names()
    available = [n for n in system.observed_names()]
    outputs = list(available if options.outputs is None else options.outputs)
    available_set = set(available)
    missing = [n for n in outputs if n not in available_set]
    if missing:
        raise CodegenError(f"'{missing[0]}' is not an observed variable of {system.name}")
    _check_defined(m, computed)

    namer = Namer()
    helpers: set[str] = set()
    numba = options.backend == "numba"
    vector = options.vector
    if vector is None:
        vector = _vector_suits(system)
    elif vector and not _vector_suits(system, 0):
        raise CodegenError("the vector layout needs a system of explicit assignments only")
    if vector:
        layout = VectorLayout(m, _vector_statements(m, outputs), numba)
        jac_lines, pattern = layout.jacobian_body(helpers)
        bodies = [
            ("rhs", "Time derivatives of the states at time t.",
             layout.body(m.derivatives, helpers), "dx"),
            ("jacobian_values", _JAC_DOC, jac_lines, "jv"),
            ("observed", "The OBSERVED variables at time t.",
             layout.body(outputs, helpers) + layout.gather(outputs), "out"),
        ]
        table: list[int] | None = layout.table
    else:
        bodies, pattern = _scalar_bodies(m, outputs, namer, helpers, numba)
        table = None
    structural = structural_parameters(system, flat_model)
    source = module_text(m, options, bodies, helpers, pattern, outputs, structural, namer,
                          table)
    return GeneratedModel(system.name, source, options.backend, tuple(m.states),
                          tuple(outputs), tuple(m.params), tuple(structural))


_JAC_DOC = "Non-zeros of d(rhs)/dx in CSC order (JAC_INDICES, JAC_INDPTR)."


def _vector_suits(system: ode.ODE, threshold: int = VECTOR_THRESHOLD) -> bool:
    return (len(system.steps) >= threshold
            and all(isinstance(s, ode.Assign) for s in system.steps))


def _vector_statements(m: _Model, outputs: Sequence[str]) -> list[tuple[str, Expr, Span]]:
    statements = [(s.name, s.expr, s.span) for s in m.ode.steps if isinstance(s, ode.Assign)]
    computed = {s[0] for s in statements}
    wanted = [d for d in m.derivatives if d not in computed] + list(outputs)
    for let in m.alias_stmts(wanted):
        assert isinstance(let, Let)
        statements.append((let.name, let.expr, m.aliases[let.name].span))
    return statements


def _scalar_bodies(m: _Model, outputs: Sequence[str], namer: Namer, helpers: set[str],
                   numba: bool) -> tuple[list[tuple[str, str, list[str], str]],
                                         list[tuple[int, int]]]:
    """Straight-line bodies: one statement per assignment, named locals."""
    computed = m.ode.step_names()
    steps, described = m.step_stmts()
    loads = m.loads()
    n = len(m.states)

    rhs = loads + steps + m.alias_stmts([d for d in m.derivatives if d not in computed])
    rhs.append(Raw(f"dx = np.empty({n})"))
    rhs += [Store(f"dx[{i}]", Var(d), f"der({s})") for i, (s, d)
            in enumerate(zip(m.states, m.derivatives))]

    jac_body, pattern = jacobian_statements(
        m.states, m.derivatives, described,
        {a.name: a.expr for a in m.ode.observed if a.name in m.derivative_set})
    jac = loads + steps + jac_body

    obs = loads + steps + m.alias_stmts(outputs) + [Raw(f"out = np.empty({len(outputs)})")]
    obs += [Store(f"out[{i}]", Var(name), name) for i, name in enumerate(outputs)]

    functions = [
        ("rhs", "Time derivatives of the states at time t.", rhs, "dx"),
        ("jacobian_values", _JAC_DOC, jac, "jv"),
        ("observed", "The OBSERVED variables at time t.", obs, "out"),
    ]
    # Plain Python computes fastest on Python floats, which also raise
    # ZeroDivisionError or ValueError where they happen (springc names the line).
    prologue = [] if numba else [Raw("x = x.tolist()\np = p.tolist()")]
    bodies = [(fn, doc, function_lines(namer, helpers, prologue + stmts), ret)
              for fn, doc, stmts, ret in functions]
    return bodies, pattern


def _check_defined(m: _Model, computed: Sequence[str]) -> None:
    known = set(m.states) | set(m.params) | set(computed) | set(m.aliases)
    for step in m.ode.steps:
        inner = set()
        if isinstance(step, ode.NonlinearBlock):
            inner = {*step.tearing, *(s.name for s in step.sensitivities)}
        for e in _step_exprs(step):
            unknown = variables(e) - known - inner
            if unknown:
                name = sorted(unknown)[0]
                raise CodegenError(f"the simplified system reads '{name}' but nothing "
                                   "computes it", hint="this is a bug in springc")
    computed_set = set(computed)
    for d in m.derivatives:
        if d not in computed_set and d not in m.aliases:
            raise CodegenError(f"nothing computes {d}", hint="this is a bug in springc")


