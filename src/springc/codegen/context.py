"""The shared vocabulary of code generation: options, the generated model, and the
context (names and lookups of one ``ir.ode.ODE``) that the generator hands to the
Jacobian, vector-layout and module-text writers.

Order of the codegen modules: ``statements <- printer``, ``statements <- context <-
{jacobian, vector, module_text} <- generator`` (``vector`` and ``module_text`` print
with ``printer``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar, cast

from ..errors import Span
from ..ir import flat, ode
from ..ir.expr import ZERO, BinOp, Call, Const, Expr, If, Var, add, mul, variables
from .delays import DelayLayout
from .event_layout import EventLayout
from .linear_cache import held_linear, solved_linear, varying_names
from .newton_search import (
    guarded,
    residual_norm,
    search_accept,
    search_control,
    search_end,
    search_start,
    search_step,
    search_trial,
)
from .newton_step import newton_solve
from .statements import Block, Let, Load, Loop, Raw, Stmt, Store

T = TypeVar("T")


class CodegenBug(RuntimeError):
    """An internal invariant of the code generator failed: a bug in springc, not in the
    model (the CLI reports it as an internal error, exit code 3)."""


def source_location(span: Span) -> str:
    """``file:line`` of ``span``, for comments (escaped when printed)."""
    return f"{span.file}:{span.line}"


def source_comment(name: str, span: Span) -> str:
    """The comment of an assignment: its flat name and where it comes from."""
    return f"{name}  {source_location(span)}"


BACKENDS = ("python", "numba")
NEWTON_ITERATIONS = 200
"""Newton steps of a torn system before its failure flag is set. Newton on an exponential
(a diode) from a warm start on the other side of its knee moves about one thermal voltage
per step: the Zener clamp of tests/simulation/models/ZenerClamp.mo needs about 100 from
vm = 3 V to its solution -0.03 V (the rhs starts from the last call's solution, which a
stage of a large step can leave far away); with 50 its run with ``--stop 0.36`` stopped
("did not converge at time 0.338", 0.036 on scipy's loop)."""


@dataclass(frozen=True)
class CodegenOptions:
    """``outputs``: observed variables to generate (``None``: all of them);
    ``vector``: loops over groups of same-shaped assignments (large systems);
    ``switchable``: index reduction left a choice of states that may turn singular
    during a run (the module says so; the simulator then switches states);
    ``warnings``: diagnostics of the model that are not errors, as text the module keeps
    (``WARNINGS``) for whoever loads it from the cache;
    ``shared``: the parts of a module that do not depend on the backend (the structural
    parameters, the vector layout's ``parameters`` and ``start``), kept for another
    generation of the same system (the pipeline's ``Derived.parts``: a model over the
    C loop's size rule is generated for python, then for numba; :func:`shared_part`)."""

    backend: str = "python"
    outputs: tuple[str, ...] | None = None
    vector: bool | None = None  # None: by size (vector.VECTOR_THRESHOLD)
    switchable: bool = False
    warnings: tuple[str, ...] = ()
    shared: dict[str, Any] | None = field(default=None, compare=False, repr=False)


def shared_part(options: CodegenOptions, name: str, make: Callable[[], T]) -> T:
    """The part ``name`` of the module: made by ``make``, once per ``options.shared``
    (whose generations are of one system: :func:`.generator.generate` checks)."""
    if options.shared is None:
        return make()
    if name not in options.shared:
        options.shared[name] = make()
    return cast(T, options.shared[name])


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



class CodegenContext:
    """The system being generated: names and lookups shared by the generated functions
    and the module text (the parts of codegen below the generator take it)."""

    guard_errors = False
    """Whether a Newton trial's arithmetic errors are caught (the Python backend, whose
    ``math`` functions raise where numba's and C's return inf or NaN)."""

    def __init__(self, system: ode.ODE, flat_model: flat.FlatModel | None) -> None:
        self.delays = DelayLayout(system)  # delay(...) calls read z slots (delays.py)
        system = self.delays.system
        self.ode = system
        self.states = [s.name for s in system.states]
        self.derivatives = [s.derivative for s in system.states]
        self.params = [q.name for q in system.parameters]
        self.param_set = set(self.params)
        self.derivative_set = set(self.derivatives)
        self.aliases = {a.name: a for a in system.observed}
        self.variables = {v.name: v for v in flat_model.variables} if flat_model else {}
        self.unknowns = {u.name: u for u in system.dae.unknowns}
        # Every name the model defines: the namer sanitizes them all (see printer.Namer).
        self.model_names = {*self.states, *self.derivatives, *self.params,
                            *system.step_names(), *self.aliases, *self.unknowns,
                            *self.variables}
        self.guess_slots: dict[str, int] = {}
        for step in system.steps:
            if isinstance(step, ode.NonlinearBlock):
                for t in step.tearing:
                    self.guess_slots[t] = len(self.guess_slots)
        # the event slots of z (codegen/event_layout.py), between the warm starts and
        # the failure flag
        self.events = EventLayout(system.events, len(self.guess_slots)) \
            if system.events is not None else None
        self.flag_slot = len(self.guess_slots) + (self.events.size if self.events else 0)
        self.delays.base = self.flag_slot
        self.flag_slot += len(self.delays)
        if self.events:
            self.model_names |= set(self.events.discrete)
        # the python backend keeps the matrices of linear blocks that hold still between
        # events (codegen/linear_cache.py): the names that may move, else None
        self.varying: set[str] | None = None

    def keep_linear_matrices(self) -> None:
        """Linear blocks whose matrix reads no varying name keep it and its inverse
        (:mod:`.linear_cache`; generated Python only)."""
        self.varying = varying_names(self.ode)

    def source_files(self) -> list[str]:
        """The model's own file, then the other files its variables come from."""
        model_file = self.ode.dae.span.file
        others = {s.span.file for s in self.ode.states} | {
            q.span.file for q in self.ode.parameters}
        return [model_file, *sorted(others - {model_file})]

    def loads(self) -> list[Stmt]:
        out: list[Stmt] = [Load(n, f"p[{i}]", n) for i, n in enumerate(self.params)]
        out += [Load(n, f"x[{i}]", n) for i, n in enumerate(self.states)]
        return out + (self.events.loads() if self.events else []) + self.delays.loads()

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
                comment = source_comment(step.name, step.span)
                stmts.append(Let(step.name, step.expr, comment))
            elif isinstance(step, ode.LinearBlock):
                comment = block_comment("linear system for", step.names, step.spans)
                stmts.append(self._linear(step, index, comment))
            else:
                comment = block_comment("nonlinear system, tearing", step.tearing,
                                        step.spans)
                stmts.append(self._nonlinear(step, index, comment))
            described.append((step, index, comment))
        return stmts, described

    def _linear(self, block: ode.LinearBlock, index: int, comment: str) -> Stmt:
        held = None if self.varying is None else held_linear(block, index, self.varying)
        body = held if held is not None else solved_linear(block, index)
        body += [Load(name, f"_y{index}[{k}]", name) for k, name in enumerate(block.names)]
        return Block(body, comment, {*block.names, f"_A{index}"})

    def _nonlinear(self, block: ode.NonlinearBlock, index: int, comment: str) -> Stmt:
        k = len(block.tearing)
        slots = [self.guess_slots[t] for t in block.tearing]
        body: list[Stmt] = [Load(t, f"float(z[{s}])", f"{t} (warm start)")
                            for t, s in zip(block.tearing, slots)]
        body += search_start(block.tearing, index)
        body.append(Raw(f"_ok{index} = False\n_done{index} = False"))
        loop = newton_trial(block, index, self.guard_errors)
        loop.append(search_control(index, c=False))
        loop += search_accept(block.tearing, index)
        loop += [Let(s.name, s.expr, "sensitivity") for s in block.sensitivities]
        entries = {(i, j): e for i, j, e in block.jacobian}
        if k == 1:
            loop += scalar_newton_step(block.tearing[0], entries.get((0, 0), ZERO), index)
        else:
            loop.append(Raw(f"_J{index} = np.zeros(({k}, {k}))"))
            loop += [Store(f"_J{index}[{i}, {j}]", e) for (i, j), e in entries.items()]
            loop.append(Raw(f"_R{index} = np.empty({k})"))
            loop += [Store(f"_R{index}[{i}]", Var(f"_r{index}_{i}")) for i in range(k)]
            loop.append(Raw(f"_T{index} = np.empty({k})"))
            loop += [Store(f"_T{index}[{i}]", Var(t)) for i, t in enumerate(block.tearing)]
            loop.append(Raw(newton_solve(f"_D{index}", f"_J{index}", f"_R{index}",
                                         f"_T{index}", k)))
            loop += [Load(f"_d{index}_{i}", f"_D{index}[{i}]") for i in range(k)]
        loop += search_step(block.tearing, index)
        body.append(Loop(f"for _it in range({NEWTON_ITERATIONS}):", loop))
        body += search_end(block.tearing, index)
        body.append(Raw(f"if not _ok{index}:\n    z[{self.flag_slot}] = "
                        f"{float(index + 1)}"))
        body += [Store(f"z[{s}]", Var(t)) for t, s in zip(block.tearing, slots)]
        return Block(body, comment, block_names(block))

    def alias_stmts(self, names: Sequence[str]) -> list[Stmt]:
        """Lets for the aliases among ``names`` and the aliases they read, in order."""
        out: list[Stmt] = []
        done: set[str] = set()
        for n in names:
            self._alias_stmts(n, done, out)
        return out

    def _alias_stmts(self, name: str, done: set[str], out: list[Stmt]) -> None:
        # A method, not a recursive closure: that would be a reference cycle (closure
        # -> its cell -> closure) holding the context and its system, left to the
        # collector, paused while a model compiles (springc.collector).
        if name in done or name not in self.aliases:
            return
        done.add(name)
        a = self.aliases[name]
        for v in sorted(variables(a.expr)):
            self._alias_stmts(v, done, out)
        out.append(Let(name, a.expr, f"{name} (alias)  {source_location(a.span)}"))


NEWTON_NUDGE = 1e-6
"""Where a scalar block's derivative is exactly 0 at an iterate that is no solution
(``P = v*i`` at ``v = i = 0``), the next iterate is this far from it, relative to
``1 + |t|``: the tangent there has no root, a point beside it has one."""


def scalar_newton_step(tearing: str, pivot: Expr, index: int) -> list[Stmt]:
    """``_d{index}_0``, the Newton correction of a block with one tearing variable:
    ``r / pivot``; 0 at a zero pivot where ``r`` is 0, else a step of
    :data:`NEWTON_NUDGE` off the point (no division by zero)."""
    r, d = Var(f"_r{index}_0"), Var(f"_p{index}_0")
    nudge = mul(Const(-NEWTON_NUDGE), add(Const(1.0), Call("abs", (Var(tearing),))))
    zero = BinOp("==", d, ZERO)
    return [Let(f"_p{index}_0", pivot),
            Let(f"_d{index}_0", If(zero, If(BinOp("==", r, ZERO), ZERO, nudge),
                                   BinOp("/", r, d)))]


def newton_trial(block: ode.NonlinearBlock, index: int, guard: bool) -> list[Stmt]:
    """The start of a Newton iteration's body: the trial point, the block's inner
    assignments and residuals at it, and their squared norm (in Python's ``try`` where
    ``guard``: :func:`.newton_search.guarded`)."""
    part = search_trial(block.tearing, index)
    part += [Let(a.name, a.expr, source_comment(a.name, a.span)) for a in block.inner]
    part += [Let(f"_r{index}_{i}", r, "residual") for i, r in enumerate(block.residuals)]
    part.append(residual_norm(index, len(block.residuals)))
    return guarded(part, index, guard)


def block_names(block: ode.NonlinearBlock) -> set[str]:
    """The names a torn block's statements define for the statements after it (its
    tearing variables, inner assignments and sensitivities)."""
    return {*block.tearing, *(a.name for a in block.inner),
            *(s.name for s in block.sensitivities)}


def block_comment(kind: str, names: Sequence[str], spans: Sequence[Span]) -> str:
    shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
    where = ", ".join(sorted({source_location(s) for s in spans})[:4])
    return f"{kind} {shown}  {where}"
