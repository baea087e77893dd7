"""Which conformance test models lie inside springc's subset (issue 15).

The subset is the whole language except external functions, operator records
(``operator`` classes, ``operator record``/``operator function``, overloading), stream
and expandable connectors, and clocked synchronous features. A test model is out of the
subset when the code of its file (comments and string literals removed, so a
``Documentation`` text mentioning "operator" does not count), or of a suite file it
names by a full path ``ModelicaCompliance.A.B``, uses one of these keywords or
built-ins:

- ``external`` (external functions and external objects);
- ``operator`` (operator records, operators, operator functions);
- ``stream``, ``inStream``, ``actualStream`` (stream connectors);
- ``expandable`` (expandable connectors);
- ``Clock`` and the clocked built-ins (``hold``, ``subSample``, ``superSample``,
  ``shiftSample``, ``backSample``, ``noClock``, ``previous``, ``interval``,
  ``firstTick``).

``reason(path, suite)`` names the first keyword found (and the file it is in when that
is another one), or returns ``""`` for a model inside the subset. The shared
``Icons`` and ``Util`` packages use none of them.
"""

from __future__ import annotations

import re
from pathlib import Path

MARKERS = {
    "external": "external function", "operator": "operator record/overloading",
    "stream": "stream connector", "inStream": "stream connector",
    "actualStream": "stream connector", "expandable": "expandable connector",
    **{name: "clocked synchronous" for name in (
        "Clock", "hold", "subSample", "superSample", "shiftSample", "backSample",
        "noClock", "previous", "interval", "firstTick")},
}
_NOISE = re.compile(r'"(?:[^"\\]|\\.)*"|//[^\n]*|/\*.*?\*/', re.DOTALL)
_MARKER = re.compile(r"\b(" + "|".join(MARKERS) + r")\b")
_SUITE_REF = re.compile(r"\bModelicaCompliance((?:\.\w+)+)")


def code_of(path: Path) -> str:
    """The text of a Modelica file without comments and string literals."""
    return _NOISE.sub('""', path.read_text(encoding="utf-8-sig", errors="replace"))


def _files_named(code: str, suite: Path) -> list[Path]:
    """The suite files a full path ``ModelicaCompliance.A.B.C`` in ``code`` names: the
    longest prefix of the path that is a file ``A/B.mo`` (or a package folder)."""
    found = []
    for match in _SUITE_REF.finditer(code):
        parts = match.group(1).lstrip(".").split(".")
        for n in range(len(parts), 0, -1):
            base = suite.joinpath("ModelicaCompliance", *parts[:n])
            candidate = base.with_suffix(".mo") if not base.is_dir() else base / "package.mo"
            if candidate.is_file():
                found.append(candidate)
                break
    return found


def reason(path: Path, suite: Path) -> str:
    """Why the test model in ``path`` is outside the subset, or ``""``."""
    seen: set[Path] = set()
    todo = [path]
    while todo:
        current = todo.pop()
        if current in seen:
            continue
        seen.add(current)
        code = code_of(current)
        marker = _MARKER.search(code)
        if marker:
            where = "" if current == path else f" (in {current.relative_to(suite)})"
            return f"{MARKERS[marker.group(1)]}: `{marker.group(1)}`{where}"
        # a package file names its whole folder: follow only the files it names
        todo += [f for f in _files_named(code, suite) if f.name != "package.mo"]
    return ""
