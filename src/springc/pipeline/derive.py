"""Compile options -> the flat model and simplified system of a model (``Derived``):
the first half of the compile path, imported only on a cache miss (or for the equations
of a model whose run captured no flat model).

Loads the files (and libraries), flattens the selected class (with structural
parameter values applied by a wrapper class ``extends M(N = 100)``, in the same class
tree as the user's files), and simplifies it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

from ..collector import collector_paused
from ..flatten import flatten, select_model
from ..ir import flat, syntax
from ..parse import ClassEntry, ClassTree, load, parse_text
from ..simplify import simplify
from ..units import check_units
from .options import CompileOptions, Derived

WRAPPER_FILE = "<springc: structural parameters>"
"""The file name of the class that applies ``--set`` values of structural parameters."""


@collector_paused()
def derive_system(options: CompileOptions,
                  parsed: Callable[[], None] | None = None) -> Derived:
    """Flatten and simplify the model of ``options`` (structural values applied);
    ``parsed()`` is called once the given files parsed and hold the model (the status
    line: never before a syntax error)."""
    tree = load(list(options.files), options.libraries, options.texts)
    model = options.model
    entry = select_model(tree, model)
    if parsed is not None:
        parsed()
    base = None
    if options.modifications:
        base = flatten(tree, model)
        model = _add_wrapper(tree, entry, options.modifications)
    flat_model = flatten(tree, model)
    warnings = check_units(flat_model)
    simplified = simplify(flat_model)
    system = simplified.ode
    switchable = any(b.switchable for b in simplified.blocks)
    if base is not None:
        # Keep the simulated model's name, location and experiment (annotations are
        # not inherited).
        system = dataclasses.replace(
            system, name=base.name,
            dae=dataclasses.replace(system.dae, experiment=base.experiment, span=base.span))
    return Derived(system, flat_model, switchable, warnings, lookups=tree.lookups.record())


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
