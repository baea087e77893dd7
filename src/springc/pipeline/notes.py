"""The status lines of the pipeline's long steps (:mod:`springc.status_line`).

Decided from the disk, never the clock: a model not in the cache is compiled now
(flattened, simplified, generated; :func:`compiling_note`, said by
:func:`~springc.pipeline.compile_files`); a cached numba module whose functions numba
has not cached compiles them at their first call (:func:`announce_functions`, said by
the simulation before it calls them: ``springc compile`` never calls them).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from ..codegen import GeneratedModule
from ..status_line import say
from .options import CompileOptions

FUNCTIONS_NOTE = "compiling the functions of {name} for this machine (once)"
"""The status line before a cached numba module's functions compile."""

JACOBIAN_NOTE = "compiling the Jacobian of {name} for this machine (once)"
"""The status line before a cached numba module's ``jacobian_values`` compiles, at the
first use of a run that needs it (:func:`springc.pipeline.apart.jacobian_apart`)."""

_ANNOUNCED: set[Path] = set()
"""The module paths whose functions this process announced (a run, its probe and its
companion run each build a problem of the same module: one line, not one each)."""


def compiling_note(options: CompileOptions, folder: Path | None) -> str:
    """The status line of a model that is not in the cache (``folder``: the cache
    folder, None where none is used), before it is compiled."""
    name = options.model or (Path(options.files[0]).stem if options.files else "the model")
    if folder is None:
        return f"compiling {name} (not cached: every run compiles it)"
    return f"compiling {name} for this machine (once; later runs load it from the cache)"


def functions_cached(module: GeneratedModule, path: Path,
                     names: Iterable[str] | None = None) -> bool:
    """Whether the numba functions of the module imported from ``path`` load from
    numba's cache (an index next to the module; assumed where ``NUMBA_CACHE_DIR`` moves
    numba's cache elsewhere); a python module's always do (nothing compiles).

    ``names``: whether each of these functions has its index (numba's
    ``model.<name>-<line>.pyXY.nbi``, or its body's ``model._<name>_indexed-...`` where
    the module passes its index table to the bodies); by default, whether any has."""
    if module.BACKEND != "numba" or os.environ.get("NUMBA_CACHE_DIR"):
        return True
    folder = path.parent / "__pycache__"
    if names is None:
        return any(folder.glob("model.*.nbi"))
    return all(any(folder.glob(f"model.{name}-*.nbi"))
               or any(folder.glob(f"model._{name}_indexed-*.nbi")) for name in names)


def announce_functions(module: GeneratedModule, path: Path, cached: bool) -> None:
    """Say that the functions of a module loaded from the cache (``cached``) compile at
    their first call, where numba has not cached them (a model compiled just now was
    announced by :func:`compiling_note` already)."""
    if cached and path not in _ANNOUNCED and not functions_cached(module, path):
        _ANNOUNCED.add(path)
        say(FUNCTIONS_NOTE.format(name=module.MODEL))
