"""Fuzzing library trees (issue 22): package folders with mutated ``within`` clauses,
class names, nesting, ``package.order`` entries and stray files, loaded through ``-L``
by ``springc check``. Every run must end with exit code 0, 1 or 2 and print no traceback.

CI runs a fixed, derandomized set (``SPRINGC_FUZZ_LIBRARY_EXAMPLES``, default 40, a few
seconds).
"""

from __future__ import annotations

import os
import shutil

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzz.test_fuzz import RANDOM, SECONDS_PER_RUN, limits
from springc.cli import main

EXAMPLES = int(os.environ.get("SPRINGC_FUZZ_LIBRARY_EXAMPLES", "40"))

NAMES = st.sampled_from(["P", "Q", "A", "B", "Modelica", "'q r'", "x" * 300, "package",
                         "P.Q", "", "Real"])
WITHIN = st.sampled_from(["", "within;", "within P;", "within P.Q;", "within Q;",
                          "within Modelica;", "within 'P';", "within P.Q.R;", "within ;;"])


@st.composite
def trees(draw: st.DrawFn) -> dict[str, str]:
    """Relative path -> text of a library tree under one root."""
    files: dict[str, str] = {}
    for _ in range(draw(st.integers(1, 5))):
        depth = draw(st.lists(st.sampled_from(["P", "Q", "R", "junk", "P"]), max_size=3))
        folder = "/".join(depth)
        kind = draw(st.sampled_from(["package.mo", "package.mdl", "A.mo", "B.mdl",
                                     "package.order", "stray.mdl"]))
        name = draw(NAMES)
        within = draw(WITHIN)
        restricted = draw(st.sampled_from(["package", "model", "block", "connector"]))
        if kind == "package.order":
            text = "\n".join(draw(st.lists(NAMES, max_size=3)))
        else:
            body = draw(st.sampled_from(["", "  Real x = 1;\n", "  A a;\n",
                                         "  extends P.A;\n", "  Q.B b;\n"]))
            text = f"{within}\n{restricted} {name}\n{body}end {name};\n"
        files[f"{folder}/{kind}" if folder else kind] = text
    return files


@settings(max_examples=EXAMPLES, derandomize=not RANDOM, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(files=trees(), use=st.sampled_from(["P.A", "P.Q.B", "Q.B", "Modelica.Mine",
                                           "P", "A"]))
def test_check_of_library_trees_never_crashes(tmp_path_factory: pytest.TempPathFactory,
                                              files: dict[str, str], use: str) -> None:
    base = tmp_path_factory.getbasetemp() / "libfuzz"
    shutil.rmtree(base, ignore_errors=True)
    lib = base / "lib"
    for relative, text in files.items():
        path = lib / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    lib.mkdir(parents=True, exist_ok=True)
    user = base / "m.mo"
    user.write_text(f"model M\n  {use} c;\n  Real y = 1;\nend M;\n")
    with limits(SECONDS_PER_RUN, 3 << 30):
        result = CliRunner().invoke(main, ["check", str(user), "-L", str(lib)],
                                    prog_name="springc", catch_exceptions=False,
                                    env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    shown = "\n".join(f"--- {k}\n{v}" for k, v in files.items())
    assert result.exit_code in (0, 1, 2), f"exit {result.exit_code}:\n{result.output}\n{shown}"
    assert "Traceback" not in result.output and "internal error" not in result.output, (
        f"{result.output}\n{shown}")
