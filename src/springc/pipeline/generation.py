"""CompileOptions -> module text: flatten, simplify, generate (the compile path).

Loaded only on a cache miss (by :func:`springc.pipeline.compile_files`), or when a
model's equations are asked for: a cached model is simulated without importing the
parser, lark, the flattener, simplify or codegen's generator. Structural parameters
(Integer or Boolean ones, and those the flattener evaluated, such as array sizes) are
set by re-flattening the selected class with a modification (``extends M(N = 100)``),
in the same class tree as the user's files.
"""

from __future__ import annotations

import contextlib
import dataclasses
import gc
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from ..codegen import CodegenOptions, generate
from ..flatten import flatten, select_model
from ..ir import flat, ode, syntax
from ..parse import ClassEntry, ClassTree, load, parse_text
from ..simplify import simplify
from .cache import Names
from .options import CompileOptions
from .selection import select_names


def candidate_names(derived: Derived) -> Names:
    """The states and the observed variables of a derived model."""
    system = derived.system
    return tuple(s.name for s in system.states), tuple(system.observed_names())



@dataclass(frozen=True)
class Derived:
    """The simplified system of a model, its flat model, and whether index reduction
    left a choice of states that may turn singular during a run (``switchable``)."""

    system: ode.ODE
    flat_model: flat.FlatModel
    switchable: bool


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
    simplified = simplify(flat_model)
    system = simplified.ode
    switchable = any(len(b.candidates) > len(b.dummies) for b in simplified.blocks)
    if base is not None:
        # Keep the simulated model's name, location and experiment (annotations are
        # not inherited).
        system = dataclasses.replace(
            system, name=base.name,
            dae=dataclasses.replace(system.dae, experiment=base.experiment, span=base.span))
    return Derived(system, flat_model, switchable)


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
    codegen = CodegenOptions(options.backend, observed, switchable=derived.switchable)
    return generate(system, flat_model, codegen).source


