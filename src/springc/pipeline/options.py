"""What to compile (:class:`CompileOptions`: files, model, backend, outputs) and what
deriving a model gives (:class:`Derived`: its flat model and simplified system).

Their own module so that the light part of the pipeline (:mod:`.compiler`: the cache
lookup and :class:`~.compiler.CompiledModel`, which makes a ``Derived`` of the system
a cached model captured) and the compile path a cache miss takes (:mod:`.derive`,
:mod:`.generation`) share them without importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import UnitError
from ..ir import flat, ode


@dataclass(frozen=True)
class CompileOptions:
    """What to compile: files, model, libraries, backend, outputs, structural values.

    ``outputs`` are ``--vars`` patterns (``*`` and ``?`` wildcards, otherwise exact
    flat names); ``None`` selects every state and observed variable.
    ``modifications`` are structural parameter values as Modelica text.
    """

    files: tuple[str, ...]
    model: str | None = None
    libraries: tuple[str, ...] = ()
    backend: str = "python"
    outputs: tuple[str, ...] | None = None
    modifications: tuple[tuple[str, str], ...] = ()
    cache: bool = True
    texts: tuple[tuple[str, str], ...] = ()  # models given as text: (pseudo file, text)



@dataclass(frozen=True)
class Derived:
    """The simplified system of a model, its flat model, whether index reduction
    left a choice of states that may turn singular during a run (``switchable``), and
    the unit mismatches of the flat model; ``lookups``: what loading read; ``parts``:
    what its generations share (``codegen.CodegenOptions.shared``: a second backend's
    module reuses the first's backend-independent parts)."""

    system: ode.ODE
    flat_model: flat.FlatModel
    switchable: bool
    warnings: tuple[UnitError, ...] = ()
    parts: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)
    #: what loading asked the file system (``parse.Lookups.record``): the cache key's
    #: part that a cached compile checks again; None where it is not known
    lookups: dict[str, Any] | None = field(default=None, compare=False, repr=False)
