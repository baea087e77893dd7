"""The cyclic garbage collector while a model compiles (one owner of the policy).

Compiling a model makes millions of objects that live to its end and few cycles. While
Python's collector runs, each of its young-generation collections walks every object
made since the last one, and each middle-generation collection every object that
survived the young ones: on the 10,000-mass chain about 4 s of its 33 s of CPU went to
walks that found nothing (a pause restored in between, as flatten and simplify each
did, makes the next collection walk all that the pause allocated). So the whole compile
(derive, generate, import, and a second backend's generation) runs with the collector
paused; the first collection after it (``springc simulate`` runs one at once, to free
the compile's memory) walks the heap once.
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector; restore its state on exit (nests: an inner
    pause leaves it paused). Reference counting still frees acyclic garbage."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
