"""CompileOptions -> module text: the compile path's entry (derive, then generate).

Loaded only on a cache miss (by :func:`springc.pipeline.compile_files`), or when a
model's equations are asked for and its run captured no flat model: a cached model is
simulated without importing the parser, lark, the flattener, the unit checks,
simplify or codegen's generator. Flattening and simplifying is :mod:`.derive`; this
module generates the text of a derived model's module.
"""

from __future__ import annotations

from ..codegen import CodegenOptions, generate
from ..collector import collector_paused
from .cache import Names
from .derive import derive_system
from .diagnostics import encode_warnings
from .options import CompileOptions, Derived
from .selection import ALL_OBSERVED, selected_observed

__all__ = ["candidate_names", "derive_system", "generate_from", "generate_source"]


def candidate_names(derived: Derived) -> Names:
    """The states and the observed variables of a derived model."""
    system = derived.system
    return tuple(s.name for s in system.states), tuple(system.observed_names())


def generate_source(options: CompileOptions) -> str:
    """Flatten, simplify and generate the module text for ``options``."""
    return generate_from(derive_system(options), options)


@collector_paused()
def generate_from(derived: Derived, options: CompileOptions,
                  selection: tuple[str, ...] | str | None = None) -> str:
    """The module text of a derived model with the outputs ``options`` selects;
    ``selection``: that choice where the caller made it already (the cache key's,
    :func:`~springc.pipeline.selection.selected_observed`; matching the 10,000-mass
    chain's 220,000 names a second time cost 0.3 s), else made here."""
    system, flat_model = derived.system, derived.flat_model
    if selection is None:
        selection = ALL_OBSERVED if options.outputs is None else \
            selected_observed(candidate_names(derived), options.outputs)
    observed = selection if isinstance(selection, tuple) else tuple(system.observed_names())
    codegen = CodegenOptions(options.backend, observed, switchable=derived.switchable,
                             warnings=encode_warnings(derived.warnings),
                             shared=derived.parts)
    return generate(system, flat_model, codegen).source
