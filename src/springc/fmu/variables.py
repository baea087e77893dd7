"""The simplified system and its C model -> the FMU's variables (``FmuVariable``) and
model structure, in the value-reference order of the C wrapper (``c/springc_fmu.h``):
0 time, then the states, their derivatives, the parameters, the observed variables.

Causality, variability and initial follow the FMI 3.0 rules (section 2.4.7): a
parameter bound to other parameters is a ``calculatedParameter``; a state with a fixed
start is ``initial="exact"``, one springc computes from the initial problem
``approx``; a top-level ``output`` of the model is an ``output``, every other
variable ``local``; the discrete variables of when-clauses are ``discrete``.
Dependencies come from the incidence graph of the evaluation order: each computed
variable depends on the states its expressions read, directly or through the
variables computed before it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from ..ir import dae, flat, ode
from ..ir import expr as x
from ..units import UnitSyntaxError, canonical, parse_unit

SECOND_UNIT = parse_unit("s")


@dataclass(frozen=True, slots=True)
class FmuVariable:
    """One scalar of modelDescription.xml."""

    name: str
    reference: int
    type: str              # Real, Integer or Boolean
    causality: str
    variability: str
    initial: str | None
    start: float | None
    unit: str | None
    description: str
    derivative_of: int | None = None  # the state's value reference, for a derivative


@dataclass(frozen=True)
class FmuInterface:
    """The variables and the model structure of an FMU."""

    variables: tuple[FmuVariable, ...]
    outputs: tuple[int, ...]
    derivatives: tuple[int, ...]
    initial_unknowns: tuple[int, ...]
    dependencies: Mapping[int, tuple[int, ...]]  # unknown -> states it depends on
    indicator_references: tuple[int, ...]  # the zero-crossing functions


def state_dependencies(system: ode.ODE) -> dict[str, frozenset[str]]:
    """Each computed variable -> the states it reads, transitively (the incidence graph
    of the evaluation order; parameters and time are not dependencies)."""
    states = {s.name for s in system.states}
    deps: dict[str, frozenset[str]] = {}

    def reads(expressions: Sequence[x.Expr]) -> frozenset[str]:
        found: set[str] = set()
        for e in expressions:
            for name in x.variables(e):
                if name in states:
                    found.add(name)
                else:
                    found |= deps.get(name, frozenset())
        return frozenset(found)

    for step in system.steps:
        if isinstance(step, ode.Assign):
            deps[step.name] = reads([step.expr])
            continue
        found = reads(ode.step_expressions(step))
        for name in ode.computed_names(step):
            deps[name] = found
    for alias in system.observed:
        deps[alias.name] = reads([alias.expr])
    return deps


@dataclass(frozen=True)
class ModelTables:
    """What the C model gives in order: names of states, parameters, observed; the
    parameter values and the states' initial values at the default parameters."""

    states: tuple[str, ...]
    parameters: tuple[str, ...]
    observed: tuple[str, ...]
    parameter_values: tuple[float, ...]
    initial_states: tuple[float, ...]
    crossing_texts: tuple[str, ...]

    @property
    def crossings(self) -> int:
        return len(self.crossing_texts)


def interface(system: ode.ODE, model: flat.FlatModel, tables: ModelTables) -> FmuInterface:
    """The FMU's variables, value references and model structure."""
    by_name = {v.name: v for v in model.variables}
    discrete = {d.name: d.type for d in system.events.discrete} if system.events else {}
    fixed = {s.name: s.fixed for s in system.states}
    parameters = {p.name: p for p in system.parameters}
    deps = state_dependencies(system)
    variables = [FmuVariable("time", 0, "Real", "independent", "continuous", None, None,
                             "s", "the simulation time")]

    def described(name: str) -> tuple[str | None, str]:
        variable = by_name.get(name)
        if variable is None:
            return None, ""
        return variable.attributes.unit or None, variable.description

    nx = len(tables.states)
    outputs: list[int] = []
    dependencies: dict[int, tuple[int, ...]] = {}
    for i, name in enumerate(tables.states):
        unit, text = described(name)
        if is_output(by_name.get(name)):
            outputs.append(1 + i)
            dependencies[1 + i] = (1 + i,)
        variables.append(FmuVariable(name, 1 + i, "Real",
                                     "output" if 1 + i in outputs else "local",
                                     "continuous",
                                     "exact" if fixed.get(name, True) else "approx",
                                     tables.initial_states[i], unit, text))
    for i, name in enumerate(tables.states):
        unit, _ = described(name)
        variables.append(FmuVariable(dae.derivative_name(name), 1 + nx + i, "Real", "local",
                                     "continuous", "calculated", None, per_second(unit),
                                     f"der({name})", derivative_of=1 + i))
    base = 1 + 2 * nx
    calculated: list[int] = []
    for i, name in enumerate(tables.parameters):
        unit, text = described(name)
        variable = by_name.get(name)
        kind = variable.type if variable else "Real"
        binding = parameters[name].binding if name in parameters else None
        bound = binding is not None and bool(x.variables(binding))
        if bound:
            calculated.append(base + i)
        variables.append(FmuVariable(
            name, base + i, kind if kind in ("Integer", "Boolean") else "Real",
            "calculatedParameter" if bound else "parameter", "fixed",
            "calculated" if bound else "exact",
            None if bound else tables.parameter_values[i], unit, text))
    base += len(tables.parameters)
    state_refs = {name: 1 + i for i, name in enumerate(tables.states)}
    for i, name in enumerate(tables.observed):
        unit, text = described(name)
        variable = by_name.get(name)
        kind = discrete.get(name, "Real")
        variables.append(FmuVariable(
            name, base + i, kind, "output" if is_output(variable) else "local",
            "discrete" if name in discrete else "continuous", "calculated", None, unit,
            text))
        if is_output(variable):
            outputs.append(base + i)
            dependencies[base + i] = tuple(sorted(state_refs[s]
                                                  for s in deps.get(name, ())))
    base += len(tables.observed)
    taken = {v.name for v in variables}
    stem = "crossing"
    while any(n == stem or n.startswith(stem + "[") for n in taken):
        stem = "_" + stem
    indicators = tuple(base + k for k in range(tables.crossings))
    variables += [FmuVariable(f"{stem}[{k + 1}]", base + k, "Real", "local", "continuous",
                              "calculated", None, None, f"event indicator: {text}")
                  for k, text in enumerate(tables.crossing_texts)]
    derivative_of = {s.name: s.derivative for s in system.states}
    derivatives = tuple(1 + nx + i for i in range(nx))
    for i, name in enumerate(tables.states):
        dependencies[1 + nx + i] = tuple(sorted(
            state_refs[s] for s in deps.get(derivative_of.get(name, ""), ())))
    computed = {v.reference for v in variables if v.initial in ("approx", "calculated")}
    unknowns = (set(outputs) & computed) | set(calculated) | set(derivatives) | {
        1 + i for i, name in enumerate(tables.states) if not fixed.get(name, True)}
    return FmuInterface(tuple(variables), tuple(outputs), derivatives,
                        tuple(sorted(unknowns)), dependencies, indicators)


def is_output(variable: flat.Variable | None) -> bool:
    """An ``output`` of the model itself (not one of its components' outputs)."""
    return variable is not None and variable.causality == "output" and \
        "." not in variable.name.split("[")[0]


def per_second(unit: str | None) -> str | None:
    """The unit of a derivative: ``unit`` per second (``m`` -> ``m/s``, ``m/s`` ->
    ``m/s2``), written canonically where springc reads ``unit``."""
    if not unit:
        return None
    try:
        parsed = parse_unit(unit)
    except UnitSyntaxError:
        parsed = None
    if parsed is None or SECOND_UNIT is None:
        return f"({unit})/s"
    return canonical(parsed / SECOND_UNIT)
