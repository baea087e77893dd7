"""Locate files shipped with springc (the grammar and the bundled model library) and
springc's per-user cache folder.

In a built wheel they sit inside the package (``springc/grammar``, ``springc/models``);
in a source checkout or editable install they are the repository's top-level folders.
"""

from __future__ import annotations

import os
import stat
import sys
from pathlib import Path

#: The installed ``springc`` package folder (every subpackage lies below it).
PACKAGE_ROOT = Path(__file__).resolve().parent


def resource_dir(name: str) -> Path:
    """The folder ``name`` (``grammar`` or ``models``), wherever this install keeps it."""
    for candidate in (PACKAGE_ROOT / name, PACKAGE_ROOT.parents[1] / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"springc installation is missing its '{name}' folder")


def grammar_path() -> Path:
    return resource_dir("grammar") / "modelica.lark"


def models_dir() -> Path:
    return resource_dir("models")


def user_cache_dir() -> Path | None:
    """springc's per-user cache folder: ``$SPRINGC_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/springc``, else ``~/.cache/springc``; None when there is no home
    folder to put it in (no ``HOME`` and no password entry)."""
    if os.environ.get("SPRINGC_CACHE_DIR"):
        return Path(os.environ["SPRINGC_CACHE_DIR"])
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"]) / "springc"
    try:
        return Path.home() / ".cache" / "springc"
    except RuntimeError:
        return None


class CacheUnusable(Exception):
    """The cache folder cannot hold entries (the reason is the message)."""


def private_folder(folder: Path, quiet: bool = False) -> Path:
    """The folder to keep springc's files in, given the cache folder ``folder``: the
    folder itself, created 0700 (missing parents too) when it does not exist, if it is a
    folder of this user that no one else may write. springc never changes the mode of,
    or removes anything from, a folder it finds: a shared sticky folder (such as
    ``/tmp``) is used through a private subfolder ``springc-<uid>`` created inside it,
    with a note (none when ``quiet``). Raises :class:`CacheUnusable` otherwise."""
    info = _existing_folder(folder)
    if info.st_mode & 0o022 and info.st_mode & stat.S_ISVTX:
        inner = folder / f"springc-{os.getuid()}"
        inner_info = _existing_folder(inner)
        _check_own(inner, inner_info)
        if not quiet:
            print(f"note: the cache folder {_shown(folder)} is shared with other users: "
                  f"springc keeps its files in {_shown(inner)}", file=sys.stderr)
        return inner
    _check_own(folder, info)
    return folder


def _shown(path: Path) -> str:
    return " ".join(str(path).splitlines())


def _existing_folder(folder: Path) -> os.stat_result:
    """``folder``'s status after creating it (and missing parents) 0700 if absent."""
    missing = []
    parent = folder
    while not os.path.lexists(parent) and parent != parent.parent:
        missing.append(parent)
        parent = parent.parent
    try:
        for path in reversed(missing):
            path.mkdir(mode=0o700)  # the umask only removes bits: 0700 stays 0700
        info = folder.stat()
    except OSError as err:
        raise CacheUnusable(f"cannot create {folder}: {err.strerror or err}") from err
    if not stat.S_ISDIR(info.st_mode):
        raise CacheUnusable(f"{folder} is not a folder")
    return info


def _check_own(folder: Path, info: os.stat_result) -> None:
    """Refuse ``folder`` unless it is this user's and no one else may write it."""
    if info.st_uid != os.getuid():
        raise CacheUnusable(f"{folder} belongs to another user")
    if info.st_mode & 0o022:
        raise CacheUnusable(f"{folder} is writable by others (make it private: "
                            f"chmod 700)")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise CacheUnusable(f"{folder} is not writable")
