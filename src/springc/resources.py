"""Locate files shipped with springc (the grammar and the bundled model library) and
springc's per-user cache folder.

In a built wheel they sit inside the package (``springc/grammar``, ``springc/models``);
in a source checkout or editable install they are the repository's top-level folders.
"""

from __future__ import annotations

import os
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
