"""Writing files safely: one writer for every file springc produces.

The policy, for every output (``-o``, ``--plot``, ``--save-reference``, the cache):

- **What may be replaced.** Only a regular file, or a name that does not exist yet.
  Folders, devices, FIFOs and sockets are refused, and so are the run's input files
  (``protected``) and files without any write permission bit (read-only files are
  honoured even when springc runs as root).
- **Symbolic links are followed**, as ``cp`` and a shell's ``>`` follow them: the file
  the link points to is replaced (the same checks apply to it) and the link itself
  stays a link. Replacing the link by a plain file would silently cut it. A link
  to nothing is refused: the file it would create elsewhere is one the user never named.
- **Nothing half-written.** Data goes to a temporary file (``.NAME.XXXX.part``) in the
  target's folder, created exclusively (never through a link) with the permissions
  ``open()`` would give (0666 less the umask; a replaced file keeps its mode). Only a
  complete file is renamed over the target. On any error, ``KeyboardInterrupt`` or
  ``SystemExit`` (the command line turns SIGTERM into one) the temporary file is
  removed.
- **All or nothing.** :class:`OutputSet` renders several outputs to their temporary
  files and renames them only once every one is complete, so a failing plot never
  leaves a fresh CSV next to a stale PNG.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from .errors import OutputError

PathLike = str | os.PathLike[str]


def real_target(path: PathLike) -> Path:
    """The file that writing ``path`` would replace (symbolic links followed)."""
    return Path(os.path.realpath(os.fspath(path)))


def _writable(mode: int) -> bool:
    return bool(mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))


def _same_file(a: Path, b: PathLike) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_target(path: PathLike, protected: Iterable[PathLike] = ()) -> Path:
    """The real path that writing ``path`` would replace, after the checks of the module
    text; :class:`~springc.errors.OutputError` names ``path`` and the reason."""
    shown = os.fspath(path)
    if not shown:
        raise OutputError("the output file name is empty")
    real = real_target(path)
    folder = real.parent
    try:
        folder_mode = folder.stat().st_mode
    except OSError:
        raise OutputError(f"cannot write '{shown}': the folder '{folder}' does not exist",
                          hint="create the folder first, or choose another path") from None
    if not stat.S_ISDIR(folder_mode):
        raise OutputError(f"cannot write '{shown}': '{folder}' is not a folder")
    if not (_writable(folder_mode) and os.access(folder, os.W_OK | os.X_OK)):
        raise OutputError(f"cannot write '{shown}': the folder '{folder}' is read-only")
    try:
        st = real.stat()
    except FileNotFoundError:
        if os.path.islink(path):
            raise OutputError(f"refusing to write '{shown}': it is a symbolic link to "
                              f"'{real}', which does not exist",
                              hint="springc replaces the file a link points to, and "
                              "creates no file where a link points: remove the link or "
                              "choose another path") from None
        return real
    except OSError as err:
        raise OutputError(f"cannot write '{shown}': {err.strerror}") from None
    if stat.S_ISDIR(st.st_mode):
        raise OutputError(f"cannot write '{shown}': it is a folder")
    if not stat.S_ISREG(st.st_mode):
        raise OutputError(f"refusing to write '{shown}': it is not a regular file (a "
                          "device, FIFO or socket)",
                          hint="springc writes its outputs to regular files only")
    if not (_writable(st.st_mode) and os.access(real, os.W_OK)):
        raise OutputError(f"cannot write '{shown}': the file is read-only",
                          hint="make it writable (chmod u+w) or choose another path")
    for source in protected:
        if _same_file(real, source):
            raise OutputError(f"refusing to write '{shown}': it is an input of this run "
                              f"('{os.fspath(source)}')",
                              hint="choose another output path")
    return real


def check_distinct(paths: Iterable[tuple[str, PathLike]]) -> None:
    """Refuse two outputs of one run that name the same file: ``(option, path)`` pairs
    (links followed, hard links caught once the file exists)."""
    seen: list[tuple[str, Path]] = []
    for option, path in paths:
        real = real_target(path)
        for other, other_real in seen:
            if real == other_real or _same_file(real, other_real):
                raise OutputError(f"{other} and {option} name the same file "
                                  f"'{os.fspath(path)}'",
                                  hint="give each output its own file")
        seen.append((option, real))


@dataclass
class _Staged:
    target: Path
    temporary: Path
    mode: int


class OutputSet:
    """Outputs written together (see the module text): open each with :meth:`open`;
    leaving the ``with`` block renames them all, or, on an error, removes them all."""

    def __init__(self, protected: Iterable[PathLike] = ()) -> None:
        self.protected = tuple(protected)
        self.staged: list[_Staged] = []

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, kind: type[BaseException] | None, *rest: object) -> None:
        if kind is not None:
            self.discard()
            return
        try:
            for item in self.staged:
                # the target may have changed since it was checked: check again
                check_target(item.target, self.protected)
                try:
                    os.chmod(item.temporary, item.mode)
                    os.replace(item.temporary, item.target)
                except OSError as err:
                    raise OutputError(f"cannot write '{item.target}': {err.strerror}") \
                        from None
        except BaseException:
            self.discard()
            raise
        self.staged.clear()

    def discard(self) -> None:
        """Remove every temporary file not renamed yet."""
        for item in self.staged:
            with contextlib.suppress(OSError):
                os.unlink(item.temporary)
        self.staged.clear()

    @contextlib.contextmanager
    def open(self, path: PathLike, mode: str) -> Iterator[IO[Any]]:
        """A file to write ``path``'s content to (``"w"``: UTF-8 text, ``"wb"``: bytes)."""
        target = check_target(path, self.protected)
        try:
            old_mode = stat.S_IMODE(target.stat().st_mode)
        except FileNotFoundError:
            old_mode = None
        temporary = target.parent / f".{target.name}.{secrets.token_hex(4)}.part"
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
        try:
            fd = os.open(temporary, flags, 0o666)  # the umask applies, as for open()
        except OSError as err:
            raise OutputError(f"cannot write '{os.fspath(path)}': {err.strerror}") from None
        mode_now = old_mode if old_mode is not None else stat.S_IMODE(os.fstat(fd).st_mode)
        item = _Staged(target, temporary, mode_now)
        self.staged.append(item)
        binary = "b" in mode
        try:
            with (os.fdopen(fd, "wb") if binary else
                  os.fdopen(fd, "w", encoding="utf-8", newline="")) as f:
                yield f
        except OSError as err:
            raise OutputError(f"cannot write '{os.fspath(path)}': {err.strerror}") from None


@contextlib.contextmanager
def atomic_write(path: PathLike, mode: str, protected: Iterable[PathLike] = ()
                 ) -> Iterator[IO[Any]]:
    """Write ``path`` through a temporary file next to it; rename only on success."""
    with OutputSet(protected) as outputs, outputs.open(path, mode) as f:
        yield f


def replace_private(target: PathLike, data: bytes) -> None:
    """Write ``data`` as ``target``, a file of one of springc's private cache folders:
    through a temporary file beside it (``.NAME.XXXXXXXX.part``, created exclusively,
    never through a link, mode 0600) renamed over ``target`` once complete, so that a
    reader sees the old file or the new one; on any error, ``KeyboardInterrupt`` or
    ``SystemExit`` the temporary file is removed and the error raised (``OSError``
    where writing failed). The one temp-and-rename writer of the cache's entries and
    run records (outputs the user names go through :class:`OutputSet`, which checks
    the target)."""
    path = Path(target)
    temporary = path.parent / f".{path.name}.{secrets.token_hex(4)}.part"
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    fd = os.open(temporary, flags, 0o600)
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def keep_newest(folder: Path, suffix: str, name_length: int, keep: int) -> None:
    """Remove the least recently written files of ``folder`` beyond ``keep``, counting
    only springc's own: names ending in ``suffix`` and ``name_length`` characters long
    (a hash and the suffix). An entry that vanishes or cannot be removed is left."""
    found = []
    with contextlib.suppress(OSError), os.scandir(folder) as entries:
        for entry in entries:
            if entry.name.endswith(suffix) and len(entry.name) == name_length:
                with contextlib.suppress(OSError):
                    found.append((entry.stat().st_mtime_ns, entry.path))
    found.sort(reverse=True)
    for _, path in found[keep:]:
        with contextlib.suppress(OSError):
            os.unlink(path)
