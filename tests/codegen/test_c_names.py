"""Model text is data in the C model too: names, units and descriptions holding ``*/``,
quotes, trigraphs (``??/``), backslashes, newlines, C keywords, <math.h> names and the C
file's own macro and function names reach C only as escaped string literals, comments
and fresh identifiers: the file compiles, its tables hold the exact text, and its
values are the Python module's."""

from __future__ import annotations

import ctypes
import re
import tempfile
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.codegen.c_printer import c_comment, c_string
from springc.pipeline import c_library
from springc.pipeline.c_build import build_library

DESCRIPTION = 'a */ "quoted" ??= ??/ \\ description\nwith a newline /* and é'
UNIT = 'm*/"??/'
NAMES = ['x*/ int evil; /*"', "v??/\n", "double", "SPRINGC_N_STATES", "springc_rhs",
         "sin", "NAN", "SPRINGC_FN"]


def quoted(name: str) -> str:
    body = name.replace("\\", "\\\\").replace("'", "\\'").replace("\n", "\\n")
    return "'" + body + "'"


def string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


MODEL = 'M*/"??/'
x, v, k, n_states, rhs_name, sin_name, nan_name, fn_name = (quoted(n) for n in NAMES)
SOURCE = f"""model {quoted(MODEL)} {string(DESCRIPTION)}
  parameter Real {k}(unit = {string(UNIT)}) = 4 {string(DESCRIPTION)};
  parameter Real {sin_name} = 2;
  Real {x}(start = 1, fixed = true, unit = {string(UNIT)}) {string(DESCRIPTION)};
  Real {v}(start = 0, fixed = true);
  Real {n_states};
  Real {rhs_name};
  Real {nan_name};
  Real {fn_name} {string(DESCRIPTION)};
equation
  der({x}) = {v};
  der({v}) = -{k} * {x} + sin({sin_name} * {x});
  {n_states} = 2 * {x};
  {rhs_name} = {n_states} + 1;
  {nan_name} = {rhs_name} * {v};
  {fn_name} = {nan_name} - {rhs_name};
end {quoted(MODEL)};
"""

HARNESS = """
const char *springc_test_string(int table, int i)
{
    switch (table) {
    case 0: return springc_model_name;
    case 1: return springc_state_names[i];
    case 2: return springc_state_descriptions[i];
    case 3: return springc_state_units[i];
    case 4: return springc_parameter_names[i];
    case 5: return springc_parameter_units[i];
    default: return springc_observed_names[i];
    }
}
"""


def test_c_string_and_comment_escape_everything_unsafe() -> None:
    assert c_string('a"b\\c??/d\n\u00e9') == '"a\\042b\\134c\\077\\077/d\\012\\303\\251"'
    assert c_comment("end */ ??/ 5%\\") == "end %2A/ %3F%3F/ 5%25%5C"


def test_hostile_names_compile_and_keep_their_text(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "hostile.mo"
    path.write_text(SOURCE, encoding="utf-8")
    model = springc.compile_model([str(path)], MODEL, backend="python")
    mod = model.module
    lib = c_library(model)
    source = lib.source
    assert "??" not in source and "\\\n" not in source
    code = re.sub(r'"(?:[^"\\\n]|\\.)*"', '""', source)  # string literals emptied
    # comments open and close in pairs, one per line, ending it
    assert code.count("/*") == code.count("*/") == sum(
        1 for line in code.splitlines() if "/*" in line and line.endswith("*/"))
    # the values are the Python module's
    p = mod.parameters({NAMES[2]: 3.0})
    index = {name: i for i, name in enumerate(mod.PARAMETERS)}
    np.testing.assert_allclose(lib.parameters({index[NAMES[2]]: 3.0}), p, rtol=1e-12)
    xs = np.array([0.7, -0.2])
    z = mod.guesses(p)
    np.testing.assert_allclose(lib.rhs(0.1, xs, p, z.copy())[1], mod.rhs(0.1, xs, p, z),
                               rtol=1e-12)
    np.testing.assert_allclose(lib.observed(0.1, xs, p, z.copy())[1],
                               mod.observed(0.1, xs, p, z), rtol=1e-12)
    # the tables hold the exact text
    with tempfile.TemporaryDirectory() as folder:
        data = build_library(source + HARNESS, Path(folder))
        so = Path(folder) / "harness.so"
        so.write_bytes(data)
        harness = ctypes.CDLL(str(so))
        read = harness.springc_test_string
        read.argtypes, read.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_char_p

        def table(number: int, size: int) -> list[str]:
            return [read(number, i).decode("utf-8") for i in range(size)]

        assert read(0, 0).decode("utf-8") == MODEL
        assert table(1, 2) == list(mod.STATES) == NAMES[:2]
        assert table(2, 2) == [DESCRIPTION, ""]
        assert table(3, 2) == [UNIT, ""]
        assert table(4, 2) == list(mod.PARAMETERS)
        assert set(table(4, 2)) == {NAMES[2], NAMES[5]}
        assert table(5, 2)[list(mod.PARAMETERS).index(NAMES[2])] == UNIT
        assert table(6, len(mod.OBSERVED)) == list(mod.OBSERVED)
