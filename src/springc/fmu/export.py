"""Compile options -> an FMU file (FMI 3.0 or 2.0, Model Exchange and Co-Simulation).

Flattens and simplifies the model (:func:`springc.pipeline.derive_system`), prints its
C code (:func:`springc.codegen.generate_c`: a construct C cannot express, such as
``delay``, is refused there with a located error naming it), solves the initial
problem at the default parameters (:func:`springc.simplify.initial_state`), writes the
model description and packs sources and binary (:mod:`.package`).
"""

from __future__ import annotations

import hashlib
import math
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from importlib import metadata

from ..codegen import generate_c
from ..errors import UsageError
from ..fileio import check_target
from ..ir import expr as x
from ..ir import ode
from ..pipeline import CompileOptions, derive_system
from ..simplify import initial_state, parameter_values
from . import description as xml
from .glue import glue_source
from .package import NO_COMPILER_NOTE, assemble, compile_sources, compiler_or_none, write_fmu
from .variables import ModelTables, interface

FMI_VERSIONS = (3, 2)
"""The FMI versions springc writes (the first is the default)."""


@dataclass(frozen=True)
class FmuExport:
    """What :func:`export_fmu` wrote."""

    path: str
    model: str
    fmi_version: int
    binary: bool          # False: sources only (no C compiler)
    states: int
    variables: int
    event_indicators: int
    note: str | None      # why the FMU holds no binary
    warnings: tuple[str, ...] = ()  # what the FMU does differently from springc


STATIC_CHOICE_WARNING = (
    "springc switches the states of this model during a run where the choice made by "
    "index reduction turns singular; the FMU keeps the states chosen at export ({states})"
    " and fails where springc would switch")


def check_version(version: object) -> int:
    """``version`` as one of :data:`FMI_VERSIONS`; a UsageError naming ``--fmi``."""
    if isinstance(version, (int, str)) and str(version) in {str(v) for v in FMI_VERSIONS}:
        return int(version)
    raise UsageError(f"--fmi must be 3 or 2, not {version!r}", option="fmi")


def identifier_of(name: str) -> str:
    """The model identifier (the binary's name): ``name`` as a C identifier."""
    ident = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return ident if ident and not ident[0].isdigit() else "_" + ident


def _token(*parts: str) -> str:
    digest = hashlib.sha256("\0".join(parts).encode()).hexdigest()
    return "{" + "-".join((digest[:8], digest[8:12], digest[12:16], digest[16:20],
                           digest[20:32])) + "}"


def _version() -> str:
    try:
        return metadata.version("springc")
    except metadata.PackageNotFoundError:
        return "0"


def _value(e: x.Expr | None, env: dict[str, float], default: float) -> float:
    if e is None:
        return default
    try:
        value = float(x.evaluate(e, env))
    except Exception:
        return default
    return value if math.isfinite(value) else default


def relation_sides(system: ode.ODE, crossings: int) -> tuple[bool, ...]:
    """For each zero crossing of the C model (the event relations, then two bounds per
    ``floor`` on a state: ``u < k``, ``u >= k + 1``), whether it holds below zero;
    empty where the count differs from the C model's (no side known)."""
    events = system.events
    if events is None:
        return ()
    ops = [r.op for r in events.relations]
    rates = list(events.floor_rates) or [None] * len(events.floors)
    ops += [op for rate in rates if rate is None for op in ("<", ">=")]
    return tuple(op in ("<", "<=") for op in ops) if len(ops) == crossings else ()


def has_jacobian(text: str) -> bool:
    """Whether the C model computes its Jacobian (``SPRINGC_HAS_JACOBIAN`` 1): the FMU
    then provides directional derivatives of the state derivatives along the states."""
    return re.search(r"^#define SPRINGC_HAS_JACOBIAN 1\b", text, re.MULTILINE) is not None


def model_tables(system: ode.ODE, states: Iterable[str], parameters: Iterable[str],
                 observed: Iterable[str], crossings: Iterable[str], t0: float
                 ) -> tuple[ModelTables, tuple[float, ...] | None, tuple[float, ...]]:
    """The tables of the C model with values: parameters at their defaults, the states'
    initial values (consistent where an initial problem exists); the initial values
    the glue bakes in (None: the start values are initial) and the states' nominals."""
    values = parameter_values(system.parameters)
    x0, info = initial_state(system, values, t0)
    order = {s.name: i for i, s in enumerate(system.states)}
    states = tuple(states)
    initial = tuple(float(x0[order[n]]) for n in states)
    by_name = {s.name: s for s in system.states}
    nominals = tuple(abs(_value(by_name[n].nominal, values, 1.0)) or 1.0 for n in states)
    parameters = tuple(parameters)
    tables = ModelTables(states, parameters, tuple(observed),
                         tuple(values.get(n, 0.0) for n in parameters), initial,
                         tuple(crossings))
    return tables, (initial if info.conditions else None), nominals


def export_fmu(options: CompileOptions, output: str | os.PathLike[str],
               fmi_version: int = 3) -> FmuExport:
    """Write the FMU of ``options``' model to ``output``: with a binary where a C
    compiler is found (:func:`springc.pipeline.find_compiler`), else sources only."""
    version = check_version(fmi_version)
    check_target(output, options.files)
    derived = derive_system(options)
    system, flat_model = derived.system, derived.flat_model
    source = generate_c(system, flat_model)
    experiment = system.dae.experiment
    tables, initial, nominals = model_tables(
        system, source.states, source.parameters, source.observed, source.crossings,
        experiment.start or 0.0)
    face = interface(system, flat_model, tables)
    identifier = identifier_of(system.name)
    token = _token(source.text, repr(face), str(version), repr(experiment))
    header = xml.Header(system.name, identifier, token, "", experiment, _version(),
                        has_jacobian(source.text))
    text = (xml.model_description_3 if version == 3 else xml.model_description_2)(
        header, face)
    build = xml.build_description(identifier, compile_sources(3)) if version == 3 else None
    package = assemble(version, identifier, text, build, source.text,
                       glue_source(token, nominals, initial, experiment.tolerance,
                                   relation_sides(system, tables.crossings)),
                       compiler_or_none())
    write_fmu(output, package.entries, options.files)
    shown = ", ".join(tables.states[:4]) + (", ..." if len(tables.states) > 4 else "")
    warnings = (STATIC_CHOICE_WARNING.format(states=shown),) if derived.switchable else ()
    return FmuExport(os.fspath(output), system.name, version, package.binary,
                     len(tables.states), len(face.variables), tables.crossings,
                     None if package.binary else NO_COMPILER_NOTE, warnings)
