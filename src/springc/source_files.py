"""Reading the bytes of a source file: regular files only, the one owner of that policy
(the parser's reads, the excerpts of error messages). A FIFO named as a model would
block springc until another process writes to it, and a device (``/dev/zero``) would
never end: both are refused, opened without blocking so that the check itself cannot
hang. Standard library only."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path


def read_regular(path: str | Path) -> bytes:
    """The bytes of the regular file ``path``; ``OSError`` where it cannot be read or
    is not a regular file (a folder, a FIFO, a device, a socket)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file")
        os.set_blocking(fd, True)
        with os.fdopen(fd, "rb", closefd=False) as f:
            return f.read()
    finally:
        os.close(fd)
