"""Which bundled models get dynamic state selection (states that switch during a run).

Every non-partial ``model`` of ``models/*.mdl`` (and of the files given as arguments) is
flattened and simplified as ``springc compile`` does; one line per model: its states and
whether their choice is static or switches during the run (``dynamic``). Classes that
are not complete models by themselves (components) are counted, not listed.

    PYTHONPATH=src python benchmarks/state_selection.py [more.mo ...]
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from springc.errors import SpringcError
from springc.ir.expr import recursion_room
from springc.pipeline import CompileOptions, derive_system

MODELS = Path(__file__).resolve().parents[1] / "models"
_CLASS = re.compile(r"^(\s*)(partial\s+)?(package|model)\s+(\w+)", re.M)


def model_names(path: Path) -> list[str]:
    """The dotted names of the non-partial models of ``path`` (one package level)."""
    names, package = [], ""
    for indent, partial, kind, name in _CLASS.findall(path.read_text(encoding="utf-8")):
        if kind == "package" and not indent:
            package = name + "."
        elif kind == "model" and not partial:
            names.append((package if indent else "") + name)
    return names


@recursion_room()
def main(extra: list[str]) -> None:
    files = sorted(MODELS.glob("*.mdl"))
    skipped = 0
    for path in files + [Path(p) for p in extra]:
        for name in model_names(path):
            options = CompileOptions(tuple(str(f) for f in [*files, path]), name)
            try:
                derived = derive_system(options)
            except SpringcError:
                skipped += 1
                continue
            states = [s.name for s in derived.system.states]
            kind = "dynamic" if derived.switchable else "static"
            shown = ", ".join(states[:6]) + (", ..." if len(states) > 6 else "")
            print(f"{kind:8} {name} ({len(states)} states: {shown})")
    print(f"({skipped} classes are components, not complete models)")


if __name__ == "__main__":
    main(sys.argv[1:])
