"""Source files -> CompiledModel: flatten, simplify, generate, cache on disk, import.

Generated modules are cached (see :mod:`.cache`: keyed by the text of every file that
could be loaded, the model name, the options and springc's own code; verified by a
recorded hash before import). A warm hit imports the module without flattening
anything. Structural parameters (Integer or Boolean ones, and those the flattener
evaluated, such as array sizes) are set by re-flattening the selected class with a
modification (``extends M(N = 100)``), in the same class tree as the user's files.
"""

from __future__ import annotations

import contextlib
import dataclasses
import gc
import shutil
import tempfile
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..codegen import CodegenOptions, GeneratedModule, generate
from ..errors import CodegenError, SimulationError, UnitError, did_you_mean
from ..flatten import flatten, select_model
from ..ir import flat, ode, syntax
from ..ir.expr import recursion_room
from ..parse import ClassEntry, ClassTree, load, parse_text
from ..simplify import simplify
from ..units import check_units
from .cache import (
    CacheUnusable,
    Names,
    cache_dir,
    cache_key,
    discard,
    import_module,
    note,
    private_folder,
    prune_cache,
    read_entry,
    read_names,
    selection_key,
    touch,
    write_entry,
    write_names,
)
from .diagnostics import decode_warnings, encode_warnings
from .equations import Equations
from .selection import ALL_OBSERVED, select_names, selected_observed


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


@dataclass
class CompiledModel:
    """A generated module, imported, with the options that produced it; ``temporary``
    keeps the private folder of an uncached module alive as long as the model."""

    module: GeneratedModule
    options: CompileOptions
    path: Path
    cached: bool
    compile_time: float
    outputs: tuple[str, ...] = field(default=())
    temporary: tempfile.TemporaryDirectory[str] | None = None
    text: str = ""  # the module's text as verified and imported (``source``)
    derived: Derived | None = field(default=None, repr=False)  # set by ``equations``

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
        return decode_warnings(getattr(self.module, "WARNINGS", ()))

    @property
    def structural(self) -> tuple[str, ...]:
        return tuple(self.module.STRUCTURAL)

    @property
    def source(self) -> str:
        """The text of the imported module (not re-read from the cache file)."""
        return self.text or self.path.read_text(encoding="utf-8")

    def equations(self) -> Equations:
        """The simplified equations in evaluation order (LaTeX in Jupyter); derived
        again from the options (the files as they are now) on first use: a module
        loaded from the cache keeps no equations."""
        return Equations(self.derive().system)

    def flat_equations(self) -> Equations:
        """The flat model's equations (LaTeX in Jupyter), as ``springc flatten`` shows."""
        return Equations(self.derive().flat_model)

    @recursion_room()
    def derive(self) -> Derived:
        """The flat model and simplified system of this model (derived once)."""
        if self.derived is None:
            self.derived = derive_system(self.options)
        return self.derived

    def parameters(self, values: Mapping[str, float] | None = None) -> Any:
        """The parameter vector with ``values`` (non-structural names) applied."""
        check_parameter_names(self, values or {})
        return self.module.parameters(dict(values or {}))


def check_parameter_names(model: CompiledModel, values: Mapping[str, object]) -> None:
    """Reject names that are not parameters, suggesting close matches."""
    known = model.parameter_names
    for name in values:
        if name not in known:
            raise SimulationError(
                f"'{name}' is not a parameter of {model.name}",
                hint=did_you_mean(name, known)
                or "parameters are named by their flat names, e.g. 'spring.k'")


# ------------------------------------------------------------------ compile


def compile_files(options: CompileOptions) -> CompiledModel:
    """The compiled model for ``options``: from the cache, or generated now.

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
    settings: tuple[object, ...] = (options.model, options.backend, options.modifications)
    if options.texts:  # (the keys of file-only models are unchanged)
        settings += (options.texts,)
    model_key = cache_key(settings, options.files, options.libraries)
    derived = None
    observed: object = ALL_OBSERVED
    if options.outputs is not None:
        names = read_names(folder, model_key)
        if names is None:
            derived = derive_system(options)
            names = candidate_names(derived)
            write_names(folder, model_key, names)
        observed = selected_observed(names, options.outputs)
    key = selection_key(model_key, observed)
    module_name = f"springc_model_{key}"
    if folder is not None:
        entry = folder / key
        data = read_entry(entry)
        if data is not None:
            path = entry / "model.py"
            try:
                module = import_module(data, path, module_name)
            except Exception as err:  # a damaged entry: regenerate it
                discard(entry, f"does not import ({type(err).__name__}: {err})")
            else:
                touch(path)
                return CompiledModel(module, options, path, True,
                                     time.perf_counter() - began, outputs_of(module, options),
                                     text=data.decode("utf-8"))
    if derived is None:
        derived = derive_system(options)
        write_names(folder, model_key, candidate_names(derived))
    generated = generate_from(derived, options)
    temporary = None
    if folder is not None:
        try:
            path = write_entry(folder / key, generated)
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
                         outputs_of(module, options), temporary, generated)


def candidate_names(derived: Derived) -> Names:
    """The states and the observed variables of a derived model."""
    system = derived.system
    return tuple(s.name for s in system.states), tuple(system.observed_names())


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


@dataclass(frozen=True)
class Derived:
    """The simplified system of a model, its flat model, whether index reduction
    left a choice of states that may turn singular during a run (``switchable``), and
    the unit mismatches of the flat model."""

    system: ode.ODE
    flat_model: flat.FlatModel
    switchable: bool
    warnings: tuple[UnitError, ...] = ()


WRAPPER_FILE = "<springc: structural parameters>"
"""The file name of the class that applies ``--set`` values of structural parameters."""


@contextlib.contextmanager
def fewer_collections() -> Iterator[None]:
    """Python's cyclic garbage collector run less often, restored on exit: compiling a
    model makes millions of objects that live to its end, which the collector walked
    every 700 allocations (a third of compile_model's CPU time on the 1,000-mass chain:
    1.44 s instead of 2.07 s; compiling makes few cycles)."""
    threshold = gc.get_threshold()
    gc.set_threshold(100_000, 50, 100)
    try:
        yield
    finally:
        gc.set_threshold(*threshold)


@fewer_collections()
def derive_system(options: CompileOptions) -> Derived:
    """Flatten and simplify the model of ``options`` (structural values applied)."""
    tree = load(list(options.files), options.libraries, options.texts)
    model = options.model
    base = None
    if options.modifications:
        entry = select_model(tree, model)
        base = flatten(tree, model)
        model = _add_wrapper(tree, entry, options.modifications)
    flat_model = flatten(tree, model)
    warnings = check_units(flat_model)
    simplified = simplify(flat_model)
    system = simplified.ode
    switchable = any(len(b.candidates) > len(b.dummies) for b in simplified.blocks)
    if base is not None:
        # Keep the simulated model's name, location and experiment (annotations are
        # not inherited).
        system = dataclasses.replace(
            system, name=base.name,
            dae=dataclasses.replace(system.dae, experiment=base.experiment, span=base.span))
    return Derived(system, flat_model, switchable, warnings)


def _add_wrapper(tree: ClassTree, entry: ClassEntry,
                 modifications: Sequence[tuple[str, str]]) -> str:
    """Add to ``tree`` a model extending the class ``entry`` with ``modifications``;
    its name. The base is named by its path from the root, each part quoted, so the
    class of the user's file is used even where a library class has the same dotted
    name (a flattened file's ``model 'Scenes.Chain'``)."""
    path = []
    scope: ClassEntry | None = entry
    while scope is not None and scope.parent is not None:
        path.append(flat.quote(scope.name))
        scope = scope.parent
    declared = {e.name for e in entry.defn.elements if isinstance(e, syntax.Component)}
    targets = {name: flat.quote(name) if name in declared
               else ".".join(map(flat.quote, name.split("."))) for name, _ in modifications}
    mods = ", ".join(f"{targets[name]} = {value}" for name, value in modifications)
    wrapper = "SpringcModified"
    while wrapper in tree.root.classes:
        wrapper += "_"
    text = (f"model {wrapper}\n  extends {'.'.join(reversed(path))}({mods});\n"
            f"end {wrapper};\n")
    errors = tree.add(parse_text(text, WRAPPER_FILE), override=True)
    if errors:
        raise errors[0]
    return wrapper


def generate_source(options: CompileOptions) -> str:
    """Flatten, simplify and generate the module text for ``options``."""
    return generate_from(derive_system(options), options)


@fewer_collections()
def generate_from(derived: Derived, options: CompileOptions) -> str:
    """The module text of a derived model with the outputs ``options`` selects."""
    system, flat_model = derived.system, derived.flat_model
    candidates = [s.name for s in system.states] + system.observed_names()
    selected = set(select_names(candidates, options.outputs))
    observed = tuple(n for n in system.observed_names() if n in selected)
    codegen = CodegenOptions(options.backend, observed, switchable=derived.switchable,
                             warnings=encode_warnings(derived.warnings))
    return generate(system, flat_model, codegen).source


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
