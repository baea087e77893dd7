"""What to compile: the options of one compilation (files, model, backend, outputs).

Its own module so that the light part of the pipeline (:mod:`.compiler`: the cache
lookup and :class:`~.compiler.CompiledModel`) and the compile path a cache miss takes
(:mod:`.generation`) share it without importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass


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

