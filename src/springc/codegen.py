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
analytic (:mod:`springc.codegen_jac`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from . import dae, flat, ode
from .codegen_jac import jacobian_statements
from .codegen_print import (
    HELPERS,
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
from .codegen_vector import (
    VECTOR_THRESHOLD,
    VectorLayout,
    encode_floats,
    encode_ints,
    encode_strings,
)
from .errors import Span
from .expr import ZERO, BinOp, Call, Const, Expr, Var, add, mul, sub, variables

CODEGEN_VERSION = 1
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


def _where(span: Span) -> str:
    return f"{span.file}:{span.line}"


def _comment(name: str, span: Span) -> str:
    return f"{name}  {_where(span)}"


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


def _topological(params: Sequence[dae.Parameter]) -> list[dae.Parameter]:
    by_name = {q.name: q for q in params}
    order: list[dae.Parameter] = []
    state: dict[str, int] = {}

    def visit(q: dae.Parameter) -> None:
        mark = state.get(q.name)
        if mark == 2:
            return
        if mark == 1:
            raise CodegenError(f"the binding of parameter '{q.name}' depends on itself",
                               q.span)
        state[q.name] = 1
        for v in sorted(variables(_value(q))):
            if v in by_name:
                visit(by_name[v])
        state[q.name] = 2
        order.append(q)

    for q in params:
        visit(q)
    return order


def _value(q: dae.Parameter) -> Expr:
    if q.binding is not None:
        return q.binding
    return q.start if q.start is not None else ZERO


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
    for q in reversed(_topological(system.parameters)):
        if q.name in used:
            used |= variables(_value(q))
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
    source = _module_text(m, options, bodies, helpers, pattern, outputs, structural, namer,
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


def _module_text(m: _Model, options: CodegenOptions,
                 bodies: list[tuple[str, str, list[str], str]], helpers: set[str],
                 pattern: list[tuple[int, int]], outputs: list[str],
                 structural: list[str], namer: Namer, table: list[int] | None) -> str:
    numba = options.backend == "numba"
    n = len(m.states)
    files = sorted({_where(s.span).rsplit(":", 1)[0] for s in m.ode.states} or {"?"})
    exp = m.ode.dae.experiment
    experiment = {"start": exp.start, "stop": exp.stop, "interval": exp.interval,
                  "tolerance": exp.tolerance}
    lines = [
        f'"""springc-generated model {m.ode.name} ({options.backend} backend).',
        "",
        f"Generated by springc from {', '.join(files)}; runs with numpy and scipy"
        + (" and numba" if numba else "") + " only.",
        "x: the STATES, p: the PARAMETERS (see parameters()), z: warm starts of the",
        "Newton iterations of torn systems, then a failure flag (non-zero: the step",
        "number of a system that did not converge).",
        '"""',
        "",
        "import base64",
        "import math",
        "import zlib",
        "",
        "import numpy as np",
    ]
    if numba:
        lines += ["from numba import njit", "",
                  '_jit = njit(cache=True, error_model="numpy")']
    lines += [
        "",
        f"MODEL = {m.ode.name!r}",
        f"BACKEND = {options.backend!r}",
        f"CODEGEN_VERSION = {CODEGEN_VERSION}",
        f"STATES = {encode_strings(m.states)}",
        f"STATE_UNITS = {encode_strings([m.unit(s) for s in m.states])}",
        f"DERIVATIVES = {encode_strings(m.derivatives)}",
        f"PARAMETERS = {encode_strings(m.params)}",
        f"PARAMETER_UNITS = {encode_strings([m.unit(q) for q in m.params])}",
        f"PARAMETER_TYPES = {encode_strings([m.type(q) for q in m.params])}",
        f"STRUCTURAL = {encode_strings(structural)}",
        f"OBSERVED = {encode_strings(outputs)}",
        f"OBSERVED_UNITS = {encode_strings([m.unit(o) for o in outputs])}",
        f"GUESSES = {_tuple(list(m.guess_slots))}",
        f"NEWTON_SYSTEMS = {m.newton_systems()!r}",
        f"EXPERIMENT = {experiment!r}",
        f"JAC_ROWS = {encode_ints([r for r, _ in pattern])}",
        f"JAC_COLS = {encode_ints([c for _, c in pattern])}",
        "JAC_INDICES = JAC_ROWS",
        f"JAC_INDPTR = np.searchsorted(JAC_COLS, np.arange({n + 1}))",
    ]
    lines += _parameters_function(m, namer, helpers)
    for name in sorted(helpers):
        lines += ["", ""] + (["@_jit"] if numba else []) + HELPERS[name].splitlines()
    kernel = table is not None and numba  # numba kernels take the index table _I
    if table is not None:
        lines += ["", "# Indices of the vector layout (see springc.codegen_vector).",
                  f"_I = {encode_ints(table) if table else 'np.zeros(1, dtype=np.int64)'}"]
    for fn, doc, body, ret in bodies:
        lines += ["", ""] + (["@_jit"] if numba else [])
        if kernel:
            lines += [f"def _{fn}(t, x, p, z, _I):", f'    """{doc}"""', *body,
                      f"    return {ret}", "", "",
                      f"def {fn}(t, x, p, z):", f'    """{doc}"""',
                      f"    return _{fn}(t, x, p, z, _I)"]
        else:
            lines += [f"def {fn}(t, x, p, z):", f'    """{doc}"""', *body, f"    return {ret}"]
    grid_call = "_observed(ts[i], X[i], p, z, _I)" if kernel else "observed(ts[i], X[i], p, z)"
    lines += ["", ""] + (["@_jit"] if numba else []) + [
        "def _observed_grid(ts, X, p, z, _I):" if kernel else "def observed_grid(ts, X, p, z):",
        '    """OBSERVED at each time ts[i] with states X[i] (a row per time); rows from',
        '    a failed Newton iteration on are NaN (and z[-1] says which system)."""',
        f"    out = np.empty((ts.shape[0], {len(outputs)}))",
        "    for i in range(ts.shape[0]):",
        f"        out[i] = {grid_call}",
        "        if z[-1] != 0.0:",
        "            out[i:] = np.nan",
        "            break",
        "    return out",
    ]
    if kernel:
        lines += ["", "", "def observed_grid(ts, X, p, z):",
                  '    """OBSERVED at each time ts[i] with states X[i] (a row per time)."""',
                  "    return _observed_grid(ts, X, p, z, _I)"]
    lines += ["", "", *_FOOTER.splitlines()]
    return "\n".join(lines) + "\n"


_FOOTER = '''def jacobian(t, x, p, z):
    """d(rhs)/dx as a scipy.sparse.csc_matrix."""
    import scipy.sparse

    n = len(STATES)
    return scipy.sparse.csc_matrix((jacobian_values(t, x, p, z), JAC_INDICES, JAC_INDPTR),
                                   shape=(n, n))


def jacobian_dense(t, x, p, z):
    """d(rhs)/dx as a dense array."""
    n = len(STATES)
    out = np.zeros((n, n))
    out[JAC_ROWS, JAC_COLS] = jacobian_values(t, x, p, z)
    return out


def sparsity():
    """The sparsity pattern of d(rhs)/dx as a scipy.sparse.csc_matrix of ones."""
    import scipy.sparse

    n = len(STATES)
    return scipy.sparse.csc_matrix((np.ones(len(JAC_ROWS)), JAC_INDICES, JAC_INDPTR),
                                   shape=(n, n))'''


def _tuple(items: Sequence[str]) -> str:
    if not items:
        return "()"
    return "(" + ", ".join(repr(i) for i in items) + ("," if len(items) == 1 else "") + ")"


def _parameters_vector(m: _Model, helpers: set[str]) -> list[str]:
    """``parameters(values)`` and ``start(p)`` for many parameters: numpy, by level."""
    params = VectorLayout(m, [(q.name, _value(q), q.span)
                              for q in _topological(m.ode.parameters)],
                          numba=False, table_name="_IP", lift_constants=True)
    given = ["    for i, v in given:", "        p[i] = v"]
    body = params.body(m.params, helpers, given)
    starts = VectorLayout(m, [(s.name, _start_of(m, s.name, s.start), s.span)
                              for s in m.ode.states],
                          numba=False, table_name="_IS", lift_constants=True)
    start_body = starts.body(m.states, helpers)
    floats = params.floats + starts.floats
    offset = len(params.floats)
    start_body = [line.replace("_F[", "_FS[") for line in start_body]
    return [
        "",
        "# Tables of parameters() and start() (see springc.codegen_vector).",
        f"_IP = {encode_ints(params.table or [0])}",
        f"_IS = {encode_ints(starts.table or [0])}",
        f"_F = {encode_floats(floats or [0.0])}",
        f"_FS = _F[{offset}:]",
        "_PINDEX = {name: i for i, name in enumerate(PARAMETERS)}",
        "", "",
        "def parameters(values=None):",
        '    """The parameter vector p: the model\'s values, overridden by values (flat',
        "    name -> number); parameters bound to others follow them unless given too.",
        '    """',
        "    values = dict(values or {})",
        "    unknown = sorted(set(values) - set(PARAMETERS))",
        "    if unknown:",
        '        raise KeyError(f"unknown parameter {unknown[0]!r}")',
        "    given = [(_PINDEX[name], float(v)) for name, v in values.items()]",
        f"    p = np.empty({len(m.params)})",
        *body,
        "    return p",
        "", "",
        "def start(p):",
        '    """Start values of the states (initialization: see springc.simulate)."""',
        f"    x = np.zeros({len(m.states)})",
        *start_body,
        "    return x",
        "", "",
        "def guesses(p):",
        '    """Initial Newton guesses of the tearing variables, then the flag."""',
        "    return np.zeros(1)",
    ]


def _parameters_function(m: _Model, namer: Namer, helpers: set[str]) -> list[str]:
    """``parameters(values)``, ``start(p)`` and ``guesses(p)``: plain Python."""
    if m.guess_slots == {} and len(m.params) + len(m.states) >= VECTOR_THRESHOLD:
        return _parameters_vector(m, helpers)
    index = {name: i for i, name in enumerate(m.params)}
    stmts: list[Stmt] = []
    for q in _topological(m.ode.parameters):
        stmts.append(Let(q.name, _value(q), _comment(q.name, q.span)))
        stmts.append(Raw(f"if {q.name!r} in values:\n"
                         f"    {namer(q.name)} = float(values[{q.name!r}])"))
        stmts.append(Store(f"p[{index[q.name]}]", Var(q.name)))
    body = function_lines(namer, helpers, [Raw(f"p = np.empty({len(m.params)})"), *stmts])
    lines = [
        "", "",
        "def parameters(values=None):",
        '    """The parameter vector p: the model\'s values, overridden by values (flat',
        "    name -> number); parameters bound to others follow them unless given too.",
        '    """',
        "    values = dict(values or {})",
        "    unknown = sorted(set(values) - set(PARAMETERS))",
        "    if unknown:",
        '        raise KeyError(f"unknown parameter {unknown[0]!r}")',
        *body,
        "    return p",
    ]
    starts = [Raw(f"x0 = np.zeros({len(m.states)})")]
    for i, s in enumerate(m.ode.states):
        starts.append(Store(f"x0[{i}]", _start_of(m, s.name, s.start), f"{s.name}  "
                            + (_where(s.span))))
    lines += ["", "", "def start(p):",
              '    """Start values of the states (initialization: see springc.simulate)."""']
    lines += function_lines(namer, helpers, m.loads()[:len(m.params)] + starts)
    lines.append("    return x0")
    guesses = [Raw(f"z = np.zeros({len(m.guess_slots) + 1})")]
    for t, slot in m.guess_slots.items():
        u = m.unknowns.get(t)
        guesses.append(Store(f"z[{slot}]", _start_of(m, t, u.start if u else None), t))
    lines += ["", "", "def guesses(p):",
              '    """Initial Newton guesses of the tearing variables, then the flag."""']
    lines += function_lines(namer, helpers, m.loads()[:len(m.params)] + guesses)
    lines.append("    return z")
    return lines


def _start_of(m: _Model, name: str, start: Expr | None, depth: int = 0) -> Expr:
    """The start value of ``name`` as an expression of parameters (0 by default)."""
    if start is None:
        return Const(0.0)
    for v in variables(start) - m.param_set:
        u = m.unknowns.get(v)
        if depth > 8 or u is None:
            raise CodegenError(f"the start value of '{name}' reads '{v}', which is not a "
                               "parameter")
        from .expr import substitute
        start = substitute(start, {v: _start_of(m, v, u.start, depth + 1)})
    return start
