"""The C compiler springc runs, the one owner of its search: the C model, its kernels,
the FMU export (:mod:`springc.pipeline.c_build`) and the foreign functions of a library
(:mod:`.foreign`) all build with :func:`find_compiler`. Standard library only."""

from __future__ import annotations

import importlib.util
import os
import shlex
import shutil
import sys

from ..errors import SpringcError

COMPILERS = ("cc", "gcc", "clang")
ZIG_MODULE = "ziglang"
"""The PyPI package whose ``python -m ziglang cc`` is the C compiler of last resort (a
machine with Python and pip only: ``pip install ziglang``, in the ``test`` and ``c``
extras)."""


class CCompilerMissing(SpringcError):
    """No C compiler on this machine (the C library cannot be built)."""


def find_compiler() -> list[str]:
    """The C compiler's command, the one owner of this search (the C model, its kernels,
    the FMU export and a library's foreign functions): ``$CC`` (split as a shell would,
    never run by one), else the first of :data:`COMPILERS` on the PATH, else ``zig cc``
    run by this Python where the ``ziglang`` package is installed (looked up, not
    imported)."""
    given = os.environ.get("CC", "").strip()
    if given:
        argv = shlex.split(given)
        if shutil.which(argv[0]) is not None:
            return argv
    for name in COMPILERS:
        found = shutil.which(name)
        if found is not None:
            return [found]
    if importlib.util.find_spec(ZIG_MODULE) is not None:
        return [sys.executable, "-m", ZIG_MODULE, "cc"]
    raise CCompilerMissing("no C compiler found (looked for $CC, cc, gcc and clang on "
                           "the PATH, and the ziglang package)",
                           hint="pip install ziglang (a C compiler from PyPI), or install "
                           "a system C compiler (for example gcc), to build the C model; "
                           "the Python module needs none")


def first_error(stderr: str, limit: int) -> str:
    """The compiler's first line that names an error (else its first line), at most
    ``limit`` characters: the one reading of a compiler's complaint."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    named = [line for line in lines if "error" in line]
    return (named or lines or ["no message"])[0][:limit]
