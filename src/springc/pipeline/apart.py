"""A model not in the cache compiled in a child process, the caller loading it from the
cache once the child is done (:func:`compiled_apart`).

Compiling a large scene leaves most of its memory behind: flattening's million
expression nodes, simplify's and the generators' objects are freed when the compile
returns, but their pages stay in Python's partly used arenas (the 50x50 cloth: about
400 MB more when its run starts than a warm run of the same model). A forked child
compiles and writes the cache entry, then exits, handing every page back; the caller
then takes the warm path (the cache entry's module), so a cold run starts from a warm
run's memory. The child shares the caller's pages (fork), so the machine holds about
the child's resident set while it compiles, not the two sets added up.

A numba module's functions compile (LLVM) at their first call, into numba's cache
beside the module: a run of a model whose functions numba has not cached would hold
that compile's memory on top of its own. :func:`functions_apart` compiles them in a
forked child from the loaded module (its pages shared), the child writing numba's cache
and exiting; the caller's run then loads them from numba's cache, as a warm run does.
The Jacobian's function, which only some runs call, is compiled so at its first use
(:func:`jacobian_apart`), not before every run.

Where the model is in the cache, nothing is forked: the caller's compile runs with
:func:`cached_only`, which makes the compile path's first step (deriving a system)
raise :class:`CacheMiss` before anything of the compile path is imported.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import sys
import weakref
from collections.abc import Callable, Iterator, Sequence
from contextvars import ContextVar
from pathlib import Path
from typing import TypeVar

from ..codegen import GeneratedModule
from ..errors import ErrorGroup, SpringcError
from ..status_line import say, silenced
from .closed import MODULE_PREFIX
from .notes import FUNCTIONS_NOTE, JACOBIAN_NOTE, functions_cached

T = TypeVar("T")

CACHED_ONLY: ContextVar[bool] = ContextVar("springc_cached_only", default=False)
"""Whether a compile in this context stops where it would derive a system."""


class CacheMiss(Exception):
    """A compile under :func:`cached_only` would derive a system (the model, or a part
    of its cache entry, is not in the cache)."""


@contextlib.contextmanager
def cached_only() -> Iterator[None]:
    """Inside the block, a compile that would derive raises :class:`CacheMiss`."""
    token = CACHED_ONLY.set(True)
    try:
        yield
    finally:
        CACHED_ONLY.reset(token)


def deriving() -> None:
    """Called where the compile path starts deriving a model whose result is cached:
    :class:`CacheMiss` under :func:`cached_only`."""
    if CACHED_ONLY.get():
        raise CacheMiss


def compiled_apart(compile: Callable[[], T]) -> T:
    """``compile()``'s result, where it misses the cache compiled first in a forked
    child that writes the cache entry and exits, then loaded here from the cache.

    Without ``os.fork`` (not POSIX), or where stderr is not a file the child can
    write to (an in-memory stream), ``compile()`` runs here. The error of a model
    (:class:`SpringcError`) that the child met is raised here as the child raised it
    (sent back pickled through a pipe: the model is not compiled twice); a child that
    failed otherwise (a bug, a signal) leaves the compile to this process, whose own
    run of ``compile()`` then meets it, its status lines silenced (the child said
    them)."""
    if not hasattr(os, "fork") or not _real_stream(sys.stderr):
        return compile()
    before = set(sys.modules)
    with cached_only():
        try:
            return compile()
        except CacheMiss:  # the modules this attempt imported from the cache let go
            for name in set(sys.modules) - before:
                if name.startswith(MODULE_PREFIX):
                    del sys.modules[name]
    status, error = _child_status(compile)
    if error is not None:
        raise error
    with silenced(True) if status == 1 else contextlib.nullcontext():
        return compile()


RUN_FUNCTIONS = ("rhs", "observed")
"""The functions of a numba module that every run hands to springc's compiled loops (the
model function's signature of :data:`springc.integrate.MODEL_FUNCTION_SIGNATURE`):
compiled by :func:`functions_apart` before the run (``observed`` where the module has
observed variables: a run calls it only then)."""

JACOBIAN_FUNCTIONS = ("jacobian_values",)
"""The functions only a run that needs the Jacobian calls (an implicit solver, ``auto``'s
stiffness estimate): compiled by :func:`jacobian_apart` at that run's first use, not
before every run (the 10,000-mass chain's ``dop853`` run never calls its
``jacobian_values``: 1.9 s of CPU to compile)."""

_DEFERRED: weakref.WeakKeyDictionary[object, Path] = weakref.WeakKeyDictionary()
"""The modules given to :func:`functions_apart`, whose :data:`JACOBIAN_FUNCTIONS` a
child compiles at the first use (:func:`jacobian_apart`), with their cache paths."""


def functions_apart(module: GeneratedModule, path: Path) -> bool:
    """Compile the :data:`RUN_FUNCTIONS` of the numba ``module`` imported from the cache
    entry ``path`` in a forked child, which writes them into numba's cache beside the
    module and exits, where numba has not cached them (:func:`functions_cached`);
    whether a child compiled them. The child says the status line of the compile; one
    that fails leaves the functions to this process's first call (numba compiles them
    there, as before). Nothing is forked without ``os.fork`` or a stderr with a file
    descriptor (as :func:`compiled_apart`).

    The module's :data:`JACOBIAN_FUNCTIONS` are left to :func:`jacobian_apart`, which
    the run calls where it needs them."""
    _DEFERRED[module] = path
    names = [name for name in RUN_FUNCTIONS if name != "observed" or module.OBSERVED]
    return _compiled_in_child(module, path, names, FUNCTIONS_NOTE)


def jacobian_apart(module: GeneratedModule) -> bool:
    """Called before a run's first call of ``module``'s :data:`JACOBIAN_FUNCTIONS`:
    where ``module`` was given to :func:`functions_apart` (``springc simulate``; once per
    module) and numba has not cached them, a forked child compiles them into numba's
    cache, as :func:`functions_apart` does the others; whether a child compiled them.
    A module that was not (the API's runs) compiles them at its first call."""
    path = _DEFERRED.pop(module, None)
    return path is not None and _compiled_in_child(module, path, JACOBIAN_FUNCTIONS,
                                                   JACOBIAN_NOTE)


def _compiled_in_child(module: GeneratedModule, path: Path, names: Sequence[str],
                       note: str) -> bool:
    """Whether a forked child compiled the numba functions ``names`` of ``module`` (not
    where numba has cached them, without ``os.fork`` or a real stderr)."""
    if (functions_cached(module, path, names) or not hasattr(os, "fork")
            or not _real_stream(sys.stderr)):
        return False

    def compile_functions() -> None:
        from numba.core.dispatcher import Dispatcher

        from ..integrate import MODEL_FUNCTION_SIGNATURE

        say(note.format(name=module.MODEL))
        for name in names:
            function = getattr(module, name, None)
            if isinstance(function, Dispatcher):  # by its arguments, as a run's first
                # call from Python compiles it (numba's cache is keyed by the signature)
                function.compile(MODEL_FUNCTION_SIGNATURE.args)

    status, _ = _child_status(compile_functions)
    return status == 0


def _child_status(compile: Callable[[], object]
                  ) -> tuple[int, SpringcError | ErrorGroup | None]:
    """The exit status of a forked child running ``compile()`` (0 when it returned, 1
    when it raised, -N when signal N ended it) and the model's error it raised."""
    sys.stdout.flush()
    sys.stderr.flush()
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child (measured by the tests' outcome)
        os.close(read_end)
        status = 1
        try:
            compile()
            status = 0
        except (SpringcError, ErrorGroup) as err:
            with contextlib.suppress(Exception), os.fdopen(write_end, "wb") as sent:
                sent.write(pickle.dumps(err))
        except BaseException:  # the caller's own compile meets it again
            pass
        finally:
            with contextlib.suppress(Exception):
                sys.stderr.flush()
            os._exit(status)
    os.close(write_end)
    try:
        with os.fdopen(read_end, "rb") as received:
            data = received.read()  # before waiting: the child may fill the pipe
    except BaseException:  # Ctrl-C, SIGTERM: the child's compile ends with this one
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        raise
    _, waited = os.waitpid(pid, 0)
    try:
        error = pickle.loads(data) if data else None
    except Exception:
        error = None
    if not isinstance(error, (SpringcError, ErrorGroup)):
        error = None
    return os.waitstatus_to_exitcode(waited), error


def _real_stream(stream: object) -> bool:
    try:
        return isinstance(stream.fileno(), int)  # type: ignore[attr-defined]
    except (AttributeError, OSError, ValueError):
        return False
