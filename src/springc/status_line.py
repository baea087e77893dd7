"""Never silent: one status line on stderr before a step that may take over a second.

Compiling a model's numba functions or an integrator's kernel for this machine takes
seconds to minutes, once; a user (or a log file: stderr need not be a terminal) sees
what springc is doing instead of a silent process. Whether a step may be long is
decided from what is on disk (a model not in the cache, a kernel without numba's
cache), never from the clock. ``--quiet`` silences the lines (:func:`silenced`), as does
a non-empty ``SPRINGC_QUIET`` in the environment (the test suite sets it, so that
outputs compared exactly do not depend on which test compiled a kernel first).
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from contextvars import ContextVar

SILENT: ContextVar[bool] = ContextVar("springc_status_silent", default=False)
"""Whether status lines are silenced in this context (see :func:`silenced`)."""

PREFIX = "springc: "


def say(text: str) -> None:
    """Write ``springc: text`` on stderr, terminal or not, unless silenced."""
    if SILENT.get() or os.environ.get("SPRINGC_QUIET"):
        return
    print(PREFIX + text, file=sys.stderr, flush=True)


@contextlib.contextmanager
def silenced(on: bool = True) -> Iterator[None]:
    """Status lines off (``on``) inside the block, as they were after it."""
    token = SILENT.set(on)
    try:
        yield
    finally:
        SILENT.reset(token)
