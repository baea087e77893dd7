"""CompileOptions -> CompiledModel: the cache lookup, and the compiled model itself.

Generated modules are cached (see :mod:`.cache`: keyed by the options, springc's own
code and what the compile read, checked again on each use; verified by a recorded hash
before import). A warm hit imports the module without flattening
anything, and without importing the compile path (:mod:`.derive`: the parser, the
flattener, unit checks and simplify; :mod:`.generation`: codegen's generator), which
loads only on a miss. What a run needs beyond the module is captured at compile time
(:mod:`.closed`), so a compiled model never reads its files again.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..codegen import GeneratedModule, ModuleKind
from ..collector import collector_paused
from ..errors import (
    CodegenError,
    SimulationError,
    UnitError,
    UnknownParameterError,
    did_you_mean,
)
from ..ir.expr import recursion_room
from ..native.foreign_calls import RunTimeCallRefused
from ..parse import still_hold
from ..resources import CacheUnusable, private_folder
from ..status_line import say
from .apart import deriving
from .cache import (
    MODULE_FILE,
    SYSTEM_FILE,
    cache_dir,
    discard,
    import_module,
    model_key_for,
    note,
    prune_cache,
    read_entry,
    read_lookups,
    read_names,
    request_key,
    selection_key,
    touch,
    write_entry,
    write_lookups,
    write_names,
)
from .closed import (
    MODULE_PREFIX,
    RunSystem,
    dump,
    import_text,
    load_run_system,
    needs_run_system,
    run_system_of,
)
from .diagnostics import decode_warnings
from .equations import Equations
from .notes import compiling_note
from .options import CompileOptions, Derived
from .selection import ALL_OBSERVED, select_names, selected_observed

__all__ = ["CompileOptions", "CompiledModel", "ModuleKind", "check_parameter_names",
           "compile_files", "modification_value"]


@dataclass
class CompiledModel:
    """A generated module, imported, with the options that produced it; ``temporary``
    keeps the private folder of an uncached module alive as long as the model.

    A compiled model is closed: what its runs need beyond the module (``run_system``,
    see :mod:`.closed`) was captured when it was compiled, so it never reads its source
    files again. It pickles (the module as its text, imported again on unpickling), so
    that it runs in another process where those files do not exist."""

    module: GeneratedModule
    options: CompileOptions
    path: Path
    cached: bool
    compile_time: float
    outputs: tuple[str, ...] = field(default=())
    temporary: tempfile.TemporaryDirectory[str] | None = None
    text: str = ""  # the module's text as verified and imported (``source``)
    derived: Derived | None = field(default=None, repr=False)  # set by ``equations``
    run_system: RunSystem | None = field(default=None, repr=False)
    model_key: str = ""  # the cache key of the model when it was compiled
    # the system the module was generated from in this process (not pickled): the one
    # memory of a derivation. Another backend's module of the same model is generated
    # from it (api), and a python module's C model (c_build.c_source) is printed from
    # it rather than derived again; :meth:`settled` lets it go where neither follows.
    compiled_from: Derived | None = field(default=None, repr=False)
    # what loading read when it was compiled (``parse.Lookups.record``), checked again
    # before its files are read for it (:meth:`check_files`)
    lookups: dict[str, Any] | None = field(default=None, repr=False)

    def __getstate__(self) -> dict[str, object]:
        return {"text": self.source, "name": getattr(self.module, "__name__", ""),
                "options": self.options, "cached": self.cached,
                "compile_time": self.compile_time, "outputs": self.outputs,
                "run_system": self.run_system, "model_key": self.model_key,
                "lookups": self.lookups}

    def __setstate__(self, state: dict[str, Any]) -> None:
        imported = import_text(state["text"], state["name"])
        self.__init__(imported.module, state["options"], imported.path,  # type: ignore[misc]
                      state["cached"], state["compile_time"], state["outputs"],
                      imported.temporary, state["text"], None, state["run_system"],
                      state["model_key"], lookups=state.get("lookups"))

    def settled(self) -> CompiledModel:
        """This model, keeping the system it was generated from only where its C model
        may be printed from it (the python backend's, for the C loop): a large model's
        flat model and system are not kept alive through its runs."""
        if self.options.backend != "python":
            self.compiled_from = None
        return self

    def let_go(self) -> None:
        """Forget this model's module in ``sys.modules`` (where the import put it for
        numba's cache), so that its code and globals are freed with the model: api's
        module of the backend springc did not keep (the 50x50 cloth's python module,
        whose C loop is refused by size, holds about 100 MB)."""
        name = getattr(self.module, "__name__", "")
        if sys.modules.get(name) is self.module:
            del sys.modules[name]

    @property
    def name(self) -> str:
        return str(self.module.MODEL)

    @property
    def kind(self) -> str:
        """The driver that runs the model: one of :class:`ModuleKind` (the generated
        module declares it as ``KIND``)."""
        return str(self.module.KIND)

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
    def start_names(self) -> tuple[str, ...]:
        """The variables whose ``start`` value a run may set (``--set``, ``parameters=``):
        the states and, in a model with an initial problem, the other variables with a
        fixed start value (conditions of that problem)."""
        names = self.states
        run = self.run_system
        if run is None or not getattr(self.module, "INITIAL_CONDITIONS", 0):
            return names
        return names + tuple(u.name for u in run.system.dae.unknowns
                             if u.fixed and u.start is not None and u.name not in names)

    @property
    def units(self) -> dict[str, str]:
        """The unit of every state and observed variable, by flat name ("" for none)."""
        units = dict(zip(self.states, self.module.STATE_UNITS))
        units.update(zip(self.observed, self.module.OBSERVED_UNITS))
        return units

    @property
    def descriptions(self) -> dict[str, str]:
        """The description strings of the variables and parameters that have one."""
        flat_list = tuple(getattr(self.module, "DESCRIPTIONS", ()))
        return dict(zip(flat_list[::2], flat_list[1::2]))

    @property
    def warnings(self) -> tuple[UnitError, ...]:
        """The unit mismatches of the model (warnings; errors with ``--strict-units``)."""
        return decode_warnings(getattr(self.module, "WARNINGS", ()), dict(self.options.texts))

    @property
    def structural(self) -> tuple[str, ...]:
        return tuple(self.module.STRUCTURAL)

    @property
    def source(self) -> str:
        """The text of the imported module (not re-read from the cache file)."""
        return self.text or self.path.read_text(encoding="utf-8")

    def equations(self) -> Equations:
        """The simplified equations in evaluation order (LaTeX in Jupyter): those the
        model holds, else derived again from its files on first use (a module loaded
        from the cache keeps no equations), which must be unchanged since compiling."""
        return Equations(self.derive().system)

    def flat_equations(self) -> Equations:
        """The flat model's equations (LaTeX in Jupyter), as ``springc flatten`` shows."""
        return Equations(self.derive().flat_model)

    @recursion_room()
    def derive(self) -> Derived:
        """The flat model and simplified system of this model (derived once): those it
        holds, else derived from its files, refused when they changed since compiling."""
        if self.derived is None:
            run = self.run_system
            if run is not None and run.flat_model is not None:
                self.derived = Derived(run.system, run.flat_model, True)
            else:
                self.check_files("its equations are no longer those of the files",
                                 "compile the model again to see its equations")
                deriving()
                from . import generation  # the compile path (not loaded for a cached model)

                self.derived = generation.derive_system(self.options)
        return self.derived

    def check_files(self, consequence: str, hint: str) -> None:
        """Refuse to read this model's files again (for what a run never needs: its
        equations, a new structural value) when they changed since it was compiled
        (what its load read, :attr:`lookups`, is no longer what a load would read)."""
        if self.lookups is not None and not still_hold(self.lookups):
            raise SimulationError(f"the files of {self.name} changed since it was "
                                  f"compiled: {consequence}", hint=hint)

    def closed_system(self) -> RunSystem:
        """What runs of this model need beyond its module (see :mod:`.closed`),
        captured when it was compiled."""
        if self.run_system is None:
            raise RuntimeError(f"the compiled model {self.name} holds no system for its "
                               "initial problem or state selection (a bug in springc)")
        return self.run_system

    def parameters(self, values: Mapping[str, float] | None = None) -> Any:
        """The parameter vector with ``values`` (non-structural names) applied; start
        values among them are not parameters and leave it unchanged."""
        return self.module.parameters(split_values(self, values or {})[0])


def check_parameter_names(model: CompiledModel, values: Mapping[str, object]) -> None:
    """Reject names that are neither parameters nor start values a run may set
    (:attr:`CompiledModel.start_names`), suggesting close matches."""
    known = model.parameter_names
    starts = model.start_names
    for name in values:
        if name in known or name in starts:
            continue
        if name in model.observed:
            raise UnknownParameterError(
                f"'{name}' is not a parameter or a state of {model.name}: it is computed "
                "from the states, so its start value is not an initial value", name=name,
                hint=f"set a parameter or the start of a state ({_listed(starts)})")
        raise UnknownParameterError(
            f"'{name}' is not a parameter or a state of {model.name}", name=name,
            hint=did_you_mean(name, known + starts)
            or "parameters and states are named by their flat names, e.g. 'spring.k'")


def _listed(names: tuple[str, ...], limit: int = 4) -> str:
    shown = ", ".join(names[:limit])
    return shown + (", ..." if len(names) > limit else "") if names else "it has none"


def split_values(model: CompiledModel, values: Mapping[str, float]
                 ) -> tuple[dict[str, float], dict[str, float]]:
    """``values`` (checked by :func:`check_parameter_names`) as parameter values and
    start values; a name that is both (none in a flat model) is a parameter."""
    check_parameter_names(model, values)
    known = set(model.parameter_names)
    params = {k: v for k, v in values.items() if k in known}
    return params, {k: v for k, v in values.items() if k not in known}


# ------------------------------------------------------------------ compile


@collector_paused()
def compile_files(options: CompileOptions, derived: Derived | None = None) -> CompiledModel:
    """The compiled model for ``options``: from the cache, or generated now (from
    ``derived``, the system of the same files, model and modifications, where given).

    The module computes the observed variables ``options.outputs`` selects (every one
    without ``--vars``); its key is the model's key with that selection, so ``--vars``
    that change only the states selected, or select the same observed variables, load
    the same module, and the model's names record (written with the first module of a
    model) resolves the patterns without flattening."""
    began = time.perf_counter()
    folder = None
    if options.cache:
        try:
            folder = private_folder(cache_dir())
        except CacheUnusable as err:
            note(f"cannot use the cache folder: {err}; compiling in a temporary folder")
    request = request_key_of(options)
    lookups = derived.lookups if derived is not None else None
    if lookups is None:
        lookups = read_lookups(folder, request)  # checked again: still what it read
    if lookups is None:  # not compiled, or its files changed: derive (and record)
        derived = _derive_now(options, folder)
        lookups = derived.lookups or {}
    if derived is not None:
        write_lookups(folder, request, lookups)
    model_key = model_key_for(request, lookups)
    observed: tuple[str, ...] | str = ALL_OBSERVED  # the key's selection, the module's too
    if options.outputs is not None:
        names = read_names(folder, model_key)
        if names is None:
            from . import generation  # the compile path, loaded on a miss only

            if derived is None:
                derived = _derive_now(options, folder)
            names = generation.candidate_names(derived)
            write_names(folder, model_key, names)
        observed = selected_observed(names, options.outputs)
    key = selection_key(model_key, observed)
    module_name = MODULE_PREFIX + key
    if folder is not None:
        hit = _cached(folder / key, module_name, options, model_key)
        if hit is not None:
            hit.compile_time = time.perf_counter() - began
            hit.lookups = lookups
            return hit
    from . import generation  # the compile path, loaded on a miss only

    if derived is None:
        derived = _derive_now(options, folder)
    if folder is not None and options.outputs is None:  # (with outputs: read or written above)
        write_names(folder, model_key, generation.candidate_names(derived))
    try:
        generated = generation.generate_from(derived, options, observed)
    except RunTimeCallRefused as refused:  # api generates it for python instead
        refused.derived = derived
        raise
    run = run_system_of(derived.system, derived.flat_model, derived.switchable)
    temporary = None
    if folder is not None:
        try:
            path = write_entry(folder / key, generated,
                               extra={SYSTEM_FILE: dump(run)} if run is not None else None)
            prune_cache(folder, keep=key)
        except OSError as err:
            note(f"cannot write to the cache folder {folder} ({err.strerror or err}); "
                 "compiling in a temporary folder")
            folder = None
    if folder is None:
        temporary = tempfile.TemporaryDirectory(prefix="springc-")  # private (0700)
        path = Path(temporary.name) / "model.py"
        path.write_text(generated, encoding="utf-8")
    try:
        module = import_module(generated.encode("utf-8"), path, module_name)
    except (SyntaxError, RecursionError, MemoryError) as err:
        if folder is not None:  # never leave an entry that cannot be imported
            shutil.rmtree(path.parent, ignore_errors=True)
        raise too_deep_for_python(err) from None
    return CompiledModel(module, options, path, False, time.perf_counter() - began,
                         outputs_of(module, options), temporary, generated,
                         run_system=run, model_key=model_key, compiled_from=derived,
                         lookups=lookups)


def _derive_now(options: CompileOptions, folder: Path | None) -> Derived:
    """The flat model and simplified system of ``options``, derived now (the compile
    path: :class:`CacheMiss` under ``cached_only`` where the model is cached)."""
    if folder is not None:
        deriving()
    from . import generation  # the compile path, loaded on a miss only

    return generation.derive_system(options,
                                    parsed=lambda: say(compiling_note(options, folder)))


def request_key_of(options: CompileOptions) -> str:
    """What a compile of ``options`` is asked (the model, backend, structural values,
    files and library path as named; not the selected outputs): with what loading read
    (a lookups record), the model's cache key (:func:`.cache.model_key_for`)."""
    settings: tuple[object, ...] = (options.model, options.backend, options.modifications)
    if options.texts:
        settings += (options.texts,)
    return request_key(settings, options.files, options.libraries)


def _cached(entry: Path, module_name: str, options: CompileOptions, model_key: str
            ) -> CompiledModel | None:
    """The model of a verified cache entry (its module, and its :class:`RunSystem`
    when its runs need one); None when there is none, or it is damaged (removed)."""
    data = read_entry(entry)
    if data is None:
        return None
    path = entry / MODULE_FILE
    try:
        module = import_module(data, path, module_name)
    except Exception as err:  # a damaged entry: regenerate it
        discard(entry, f"does not import ({type(err).__name__}: {err})")
        return None
    run = None
    if needs_run_system(module):
        record = read_entry(entry, SYSTEM_FILE)  # a damaged one is removed with a note
        if record is None:
            if entry.exists():
                discard(entry, f"has no {SYSTEM_FILE}")
            return None
        try:
            run = load_run_system(record)
        except Exception as err:  # any damage: regenerate the entry
            discard(entry, f"has an unusable {SYSTEM_FILE} ({type(err).__name__}: {err})")
            return None
    touch(path)
    return CompiledModel(module, options, path, True, 0.0, outputs_of(module, options),
                         text=data.decode("utf-8"), run_system=run, model_key=model_key)


def too_deep_for_python(err: BaseException) -> BaseException:
    """The error for a generated module that Python's compiler refuses: a located
    :class:`CodegenError` when it nests too deeply (more than about 200 parentheses or
    calls inside one another), else ``err`` itself (a bug in springc)."""
    if isinstance(err, SyntaxError) and "too many nested parentheses" not in str(err):
        return err
    return CodegenError(
        "an expression of this model nests deeper than Python's compiler accepts "
        f"({err.__class__.__name__}: {err})",
        hint="split deeply nested calls or parentheses with intermediate variables "
             "(`Real s1 = sin(x); Real s2 = sin(s1);` ...); Python accepts about 200 levels")


def outputs_of(module: GeneratedModule, options: CompileOptions) -> tuple[str, ...]:
    """The names ``options.outputs`` selects among the module's states and observed."""
    return tuple(select_names(tuple(module.STATES) + tuple(module.OBSERVED),
                              options.outputs))


def modification_value(model: CompiledModel, name: str, value: float) -> str:
    """Modelica text for a structural parameter's new value (Integer/Boolean/Real)."""
    if "[" in name:
        raise SimulationError(
            f"'{name}' is a structural parameter (it was evaluated while flattening) and "
            "an array element cannot be modified on its own",
            hint="change the whole array in the model, or bind it to a scalar parameter")
    types = dict(zip(model.module.PARAMETERS, model.module.PARAMETER_TYPES))
    kind = types.get(name, "Real")
    if kind == "Boolean":
        return "true" if value else "false"
    if kind == "Integer":
        if float(value) != int(value):
            raise SimulationError(f"'{name}' is an Integer parameter; {value} is not an "
                                  "integer")
        return str(int(value))
    return repr(float(value))
