"""Source files -> CompiledModel: flatten, simplify, generate, cache on disk, import.

Generated modules are cached (the 200 most recently used) in ``$SPRINGC_CACHE_DIR``, else
``$XDG_CACHE_HOME/springc``, else ``~/.cache/springc``, keyed by the text of every
file that could be loaded (the named files and all ``.mdl`` files of the library
folders), the model name, the options, and the installed springc's own files. A warm
hit imports the module without flattening anything. Structural parameters (Integer or
Boolean ones, and those the flattener evaluated, such as array sizes) are set by
re-flattening the model with a modification (``extends M(N = 100)``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import difflib
import hashlib
import importlib.util
import os
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ..errors import SimulationError
from ..fileio import atomic_write
from ..resources import PACKAGE_ROOT

if TYPE_CHECKING:
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


@dataclass
class CompiledModel:
    """A generated module, imported, with the options that produced it."""

    module: ModuleType
    options: CompileOptions
    path: Path
    cached: bool
    compile_time: float
    outputs: tuple[str, ...] = field(default=())
    _tmp: Any = None

    @property
    def name(self) -> str:
        return str(self.module.MODEL)

    @property
    def states(self) -> tuple[str, ...]:
        return tuple(self.module.STATES)

    @property
    def observed(self) -> tuple[str, ...]:
        return tuple(self.module.OBSERVED)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(self.module.PARAMETERS)

    @property
    def structural(self) -> tuple[str, ...]:
        return tuple(self.module.STRUCTURAL)

    @property
    def source(self) -> str:
        return self.path.read_text(encoding="utf-8")

    def parameters(self, values: Mapping[str, float] | None = None) -> Any:
        """The parameter vector with ``values`` (non-structural names) applied."""
        check_parameter_names(self, values or {})
        return self.module.parameters(dict(values or {}))


# ------------------------------------------------------------------ selection

def _pattern(text: str) -> re.Pattern[str]:
    parts = (".*" if c == "*" else "." if c == "?" else re.escape(c) for c in text)
    return re.compile("".join(parts) + r"\Z")


def select_names(candidates: Sequence[str], patterns: Sequence[str] | None) -> list[str]:
    """``candidates`` matching any of ``patterns`` (all when ``None``), in model order."""
    if patterns is None:
        return list(candidates)
    compiled = [(p, _pattern(p)) for p in patterns]
    for text, rx in compiled:
        if not any(rx.match(c) for c in candidates):
            close = difflib.get_close_matches(text, candidates, 3)
            raise SimulationError(
                f"--vars '{text}' matches no state or observed variable",
                hint=(f"did you mean {', '.join(repr(c) for c in close)}?" if close else
                      "use flat names such as 'mass.pos[1]', with * and ? as wildcards"))
    return [c for c in candidates if any(rx.match(c) for _, rx in compiled)]


def check_parameter_names(model: CompiledModel, values: Mapping[str, object]) -> None:
    """Reject names that are not parameters, suggesting close matches."""
    known = model.parameter_names
    for name in values:
        if name not in known:
            close = difflib.get_close_matches(name, known, 3)
            raise SimulationError(
                f"'{name}' is not a parameter of {model.name}",
                hint=(f"did you mean {', '.join(repr(c) for c in close)}?" if close else
                      "parameters are named by their flat names, e.g. 'spring.k'"))


# ------------------------------------------------------------------ cache

def cache_dir() -> Path:
    """Where generated modules are kept."""
    if os.environ.get("SPRINGC_CACHE_DIR"):
        return Path(os.environ["SPRINGC_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "springc"


CACHE_ENTRIES = 200
"""Generated modules kept in the cache; the least recently used beyond this are removed."""


def _touch(path: Path) -> None:
    """Mark a cache entry as used (its modification time orders the pruning)."""
    with contextlib.suppress(OSError):  # a read-only cache still works
        os.utime(path)


def prune_cache(folder: Path, keep: str, limit: int | None = None) -> list[Path]:
    """Remove the least recently used entries beyond ``limit`` (never ``keep``)."""
    limit = CACHE_ENTRIES if limit is None else limit
    entries = []
    for entry in folder.iterdir() if folder.is_dir() else ():
        module = entry / "model.py"
        try:
            entries.append((module.stat().st_mtime, entry))
        except OSError:  # not an entry (the "modified" folder) or being written
            continue
    entries.sort(reverse=True)
    removed = [e for _, e in entries[limit:] if e.name != keep]
    for entry in removed:
        shutil.rmtree(entry, ignore_errors=True)
    return removed


def _library_folders(libraries: Sequence[str]) -> list[Path]:
    from ..resources import models_dir

    folders = [Path(p) for p in libraries]
    env = os.environ.get("SPRINGC_PATH", "")
    folders += [Path(p) for p in env.split(os.pathsep) if p]
    folders.append(models_dir())
    return folders


def cache_key(options: CompileOptions) -> str:
    """A digest of everything the generated module depends on."""
    from ..codegen import CODEGEN_VERSION

    h = hashlib.sha256()
    h.update(repr((CODEGEN_VERSION, options.model, options.backend, options.outputs,
                   options.modifications)).encode())
    for f in sorted(PACKAGE_ROOT.glob("**/*.py")):
        st = f.stat()
        h.update(f"{f.relative_to(PACKAGE_ROOT)}:{st.st_size}:{st.st_mtime_ns}".encode())
    sources = [Path(f) for f in options.files]
    for folder in _library_folders(options.libraries):
        if folder.is_dir():
            sources += sorted(folder.glob("**/*.mdl"))
    for path in sources:
        h.update(str(path.resolve()).encode() + b"\0")
        try:
            h.update(hashlib.sha256(path.read_bytes()).digest())
        except OSError:
            h.update(b"missing")
    return h.hexdigest()[:24]


def _import(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    # numba's on-disk cache finds the module again by name when loading.
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


# ------------------------------------------------------------------ compile

def compile_files(options: CompileOptions) -> CompiledModel:
    """The compiled model for ``options``: from the cache, or generated now."""
    began = time.perf_counter()
    key = cache_key(options)
    module_name = f"springc_model_{key}"
    tmp = None
    if options.cache:
        path = cache_dir() / key / "model.py"
        if path.exists():
            _touch(path)
            module = _import(path, module_name)
            return CompiledModel(module, options, path, True, time.perf_counter() - began,
                                 _outputs(module, options))
    else:
        tmp = tempfile.TemporaryDirectory(prefix="springc-")
        path = Path(tmp.name) / "model.py"
    generated = generate_source(options)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path, "w") as f:
        f.write(generated)
    if options.cache:
        prune_cache(cache_dir(), keep=key)
    module = _import(path, module_name)
    return CompiledModel(module, options, path, False, time.perf_counter() - began,
                         _outputs(module, options), tmp)


def _outputs(module: ModuleType, options: CompileOptions) -> tuple[str, ...]:
    return tuple(select_names(tuple(module.STATES) + tuple(module.OBSERVED),
                              options.outputs))


@dataclass(frozen=True)
class Derived:
    """The simplified system of a model, its flat model, and whether index reduction
    left a choice of states that may turn singular during a run (``switchable``)."""

    system: ode.ODE
    flat_model: flat.FlatModel
    switchable: bool


def derive_system(options: CompileOptions) -> Derived:
    """Flatten and simplify the model of ``options`` (structural values applied)."""
    from ..simplify import simplify
    from .files import flatten_files

    files = list(options.files)
    model = options.model
    base = None
    if options.modifications:
        base = flatten_files(files, model, options.libraries)
        files.append(str(_wrapper_file(base.name, options.modifications)))
        model = "SpringcModified"
    flat_model = flatten_files(files, model, options.libraries)
    simplified = simplify(flat_model)
    system = simplified.ode
    switchable = any(len(b.candidates) > len(b.dummies) for b in simplified.blocks)
    if base is not None:
        # Keep the simulated model's name and experiment (annotations are not inherited).
        system = dataclasses.replace(
            system, name=base.name,
            dae=dataclasses.replace(system.dae, experiment=base.experiment))
    return Derived(system, flat_model, switchable)


def generate_source(options: CompileOptions) -> str:
    """Flatten, simplify and generate the module text for ``options``."""
    from ..codegen import CodegenOptions, generate

    derived = derive_system(options)
    system, flat_model = derived.system, derived.flat_model
    candidates = [s.name for s in system.states] + system.observed_names()
    selected = set(select_names(candidates, options.outputs))
    observed = tuple(n for n in system.observed_names() if n in selected)
    source = generate(system, flat_model, CodegenOptions(options.backend, observed)).source
    # Index reduction left a choice of states that may turn singular during the run:
    # the simulator then switches states (springc.simulation_switching).
    return source + f"\nSWITCHABLE = {derived.switchable}\n"


def _wrapper_file(model: str, modifications: Sequence[tuple[str, str]]) -> Path:
    mods = ", ".join(f"{name} = {value}" for name, value in modifications)
    text = (f'model SpringcModified "{model} with structural parameters set by springc"\n'
            f"  extends {model}({mods});\n"
            "end SpringcModified;\n")
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    path = cache_dir() / "modified" / f"{digest}.mdl"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path, "w") as f:
            f.write(text)
    return path


def modification_value(model: CompiledModel, name: str, value: float) -> str:
    """Modelica text for a structural parameter's new value (Integer/Boolean/Real)."""
    if "[" in name:
        raise SimulationError(
            f"'{name}' is a structural parameter (it was evaluated while flattening) and "
            "an array element cannot be modified on its own",
            hint="change the whole array in the model, or bind it to a scalar parameter")
    types = dict(zip(model.module.PARAMETERS, getattr(model.module, "PARAMETER_TYPES", ())))
    kind = types.get(name, "Real")
    if kind == "Boolean":
        return "true" if value else "false"
    if kind == "Integer":
        if float(value) != int(value):
            raise SimulationError(f"'{name}' is an Integer parameter; {value} is not an "
                                  "integer")
        return str(int(value))
    return repr(float(value))
