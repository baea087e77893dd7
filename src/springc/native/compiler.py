"""The C compiler springc runs, the one owner of its search: the C model, its kernels,
the FMU export (:mod:`springc.pipeline.c_build`) and the foreign functions of a library
(:mod:`.foreign`) all build with :func:`find_compiler`, and run it with
:func:`run_compiler` (its limits). Standard library only."""

from __future__ import annotations

import importlib.util
import os
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ..errors import SpringcError

COMPILERS = ("cc", "gcc", "clang")
ZIG_MODULE = "ziglang"
"""The PyPI package whose ``python -m ziglang cc`` is the C compiler of last resort (a
machine with Python and pip only: ``pip install ziglang``, in the ``test`` and ``c``
extras)."""


#: Each process of a compile may use this many CPU seconds (``SPRINGC_COMPILE_CPU_SECONDS``
#: sets another): a header that never finishes compiling (one that includes itself
#: twice: 2^200 inclusions) fails instead of hanging springc. A limit of the processes,
#: in CPU time (not the wall clock): the largest C models springc generates compile in
#: well under it.
COMPILE_CPU_SECONDS = 900
CPU_VARIABLE = "SPRINGC_COMPILE_CPU_SECONDS"
#: The largest file a compile may write (its library, its messages): 4 GiB.
COMPILE_FILE_BYTES = 4 << 30
#: What is read back of the compiler's messages.
MESSAGE_BYTES = 1 << 20


class CCompilerMissing(SpringcError):
    """No C compiler on this machine (the C library cannot be built)."""


class CompilerOutOfTime(SpringcError):
    """The C compiler used up its CPU time (:data:`COMPILE_CPU_SECONDS`)."""


def cpu_limit() -> int:
    """The CPU seconds each process of a compile may use."""
    text = os.environ.get(CPU_VARIABLE, "").strip()
    return int(text) if text.isdigit() and int(text) > 0 else COMPILE_CPU_SECONDS


def run_compiler(argv: Sequence[str], cwd: str | Path | None, what: str
                 ) -> tuple[int, str]:
    """Run the C compiler ``argv`` in ``cwd`` on ``what`` (for the message): its exit
    status and messages. Its stdin is closed, each of its processes may use
    :func:`cpu_limit` CPU seconds and write files of :data:`COMPILE_FILE_BYTES`; a
    compile that failed after using up its time raises :class:`CompilerOutOfTime`."""
    seconds = cpu_limit()

    def limited() -> None:  # in the child, before the compiler starts
        resource.setrlimit(resource.RLIMIT_CPU, (seconds, seconds + 5))
        resource.setrlimit(resource.RLIMIT_FSIZE, (COMPILE_FILE_BYTES, COMPILE_FILE_BYTES))

    before = _children_cpu()
    with tempfile.TemporaryFile() as messages:
        done = subprocess.run(list(argv), stdin=subprocess.DEVNULL, stdout=messages,
                              stderr=messages, cwd=cwd, check=False, preexec_fn=limited)
        messages.seek(0)
        text = messages.read(MESSAGE_BYTES).decode("utf-8", "replace")
    # 0.9: the kernel accounts CPU time in ticks (0.99 s used at a limit of 1 s)
    if done.returncode != 0 and _children_cpu() - before >= 0.9 * seconds:
        raise CompilerOutOfTime(
            f"the C compiler did not finish {what} within its limit of {seconds} CPU "
            "seconds", hint="a header or source that never finishes compiling (one "
            f"that includes itself?); if the code really needs longer, set {CPU_VARIABLE}=N")
    return done.returncode, text


def _children_cpu() -> float:
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


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
