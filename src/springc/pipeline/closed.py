"""A closed compiled model: what a run needs beyond the generated module, captured at
compile time (simplified system -> :class:`RunSystem` -> bytes in the cache entry), and
a generated module imported again from its text (a model unpickled in another process).

The generated module holds the ODE's functions. Two things a run may need are not in it:

- the *initial problem* of a model with ``initial equation``s, or with fixed start
  values of variables that are not states: :func:`springc.simplify.initial_state`
  solves it on the simplified system, once per run;
- the *flat model* of a model with dynamic state selection: the switching driver
  (:mod:`springc.simulation.switching`) simplifies it again at the values where the
  states must change.

Both are kept as the symbolic IR (frozen dataclasses of :mod:`springc.ir`) in the
:class:`~springc.pipeline.CompiledModel`, and pickled into its cache entry
(:data:`~springc.pipeline.cache.SYSTEM_FILE`, verified by its hash before it is read,
as the module is). Why not generated code: the initial problem is solved once per run
(a Newton solve of a few conditions), so the reference evaluator costs little there;
keeping the one tested solver gives the same start values as before, and the
switching driver needs the flat model anyway, which no generated code can replace.
So a compiled model never reads its source files again: editing or deleting them
after compiling changes nothing in its runs, and a pickled model runs in a process
where they do not exist.
"""

from __future__ import annotations

import functools
import pickle
import tempfile
from dataclasses import dataclass
from pathlib import Path

from ..codegen import GeneratedModule
from ..ir import flat, ode
from ..ir.expr import recursion_room
from ..resources import CacheUnusable, private_folder
from .cache import MODULE_FILE, cache_dir, import_module, read_entry

MODULE_PREFIX = "springc_model_"
"""A generated module is imported as this prefix and its cache key."""


@dataclass(frozen=True)
class RunSystem:
    """The simplified ``system`` (its initial problem) and, for a model with dynamic
    state selection, the ``flat_model`` the switching driver simplifies again."""

    system: ode.ODE
    flat_model: flat.FlatModel | None = None


def run_system_of(system: ode.ODE, flat_model: flat.FlatModel, switchable: bool
                  ) -> RunSystem | None:
    """What runs of this model need beyond its module; None when nothing. (Called on
    the compile path only: simplify is not imported to load a cached model.)"""
    from ..simplify import conditions

    if switchable:
        return RunSystem(system, flat_model)
    if conditions(system):
        return RunSystem(system)
    return None


def needs_run_system(module: GeneratedModule) -> bool:
    """Do runs of ``module``'s model need a :class:`RunSystem`? (The module says so:
    an initial problem, or dynamic state selection.)"""
    return bool(getattr(module, "INITIAL_CONDITIONS", 0) or
                getattr(module, "SWITCHABLE", False))


@recursion_room()
def dump(run: RunSystem) -> bytes:
    """The bytes of ``run`` for the cache entry (pickle; deep expressions included)."""
    return pickle.dumps(run, protocol=pickle.HIGHEST_PROTOCOL)


@recursion_room()
def load_run_system(data: bytes) -> RunSystem:
    """The :class:`RunSystem` of verified bytes; ``ValueError`` if they hold another
    object."""
    run = pickle.loads(data)  # hash-verified bytes of a private folder
    if not isinstance(run, RunSystem):
        raise ValueError(f"holds a {type(run).__name__}, not a RunSystem")
    return run


@dataclass(frozen=True)
class Imported:
    """A module imported from its text, the file it was imported from, and the private
    folder that holds that file when it is not the cache entry."""

    module: GeneratedModule
    path: Path
    temporary: tempfile.TemporaryDirectory[str] | None


@functools.lru_cache(maxsize=8)
def import_text(text: str, name: str) -> Imported:
    """The module ``name`` with source ``text``, imported once per process: from its
    cache entry when that holds the same verified text (numba's cache of the entry then
    serves its functions), else from a file written in a private temporary folder
    (numba's caching needs the file)."""
    data = text.encode("utf-8")
    key = name.removeprefix(MODULE_PREFIX)
    try:
        entry = private_folder(cache_dir()) / key
    except CacheUnusable:
        entry = None
    if entry is not None and (entry / MODULE_FILE).exists() and read_entry(entry) == data:
        return Imported(import_module(data, entry / MODULE_FILE, name), entry / MODULE_FILE,
                        None)
    temporary = tempfile.TemporaryDirectory(prefix="springc-")  # private (0700)
    path = Path(temporary.name) / MODULE_FILE
    path.write_bytes(data)
    return Imported(import_module(data, path, name), path, temporary)

