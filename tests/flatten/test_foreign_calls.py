"""External C functions compiled from the C sources a library ships (Modelica 12.9):
the test library ``foreign/ForeignLib`` (its own Resources/C-Sources/ForeignLib.c and
Resources/Include/foreignlib.h), built with the system C compiler or zig cc, called
while flattening; exact values from its C code, exact located errors."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import pytest

import springc
from springc.errors import CodegenError, SpringcError, errors_of
from springc.ir.flat import format_flat
from springc.pipeline import c_source
from springc.pipeline.files import flatten_files

LIBRARY = Path(__file__).parent / "foreign"
PACKAGE = LIBRARY / "ForeignLib" / "package.mo"


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _equations(model: str) -> list[str]:
    text = format_flat(flatten_files([], model, [LIBRARY]))
    return text.split("equation\n")[1].splitlines()[:-1]


def _error(model: str, libraries: list[Path] | None = None) -> SpringcError:
    with pytest.raises(SpringcError) as info:
        flatten_files([], model, libraries or [LIBRARY])
    (err,) = errors_of(info.value)
    return err


def _line(needle: str) -> int:
    lines = PACKAGE.read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if needle in line)


def test_scalar_and_array_arguments_and_outputs() -> None:
    # stats({1.5, -2, 4}, 3, true): sum 3.5, -3*u, 2 positive entries; the transpose of
    # [1, 2, 3; 4, 5, 6] (row-major both ways); sqrt(6.25) = 2.5; (-1.5)^3 = -3.375
    # through the default call of the library's 'cube'
    assert _equations("ForeignLib.M") == [
        "  'T[1,1]' = 1.0;", "  'T[1,2]' = 4.0;", "  'T[2,1]' = 2.0;", "  'T[2,2]' = 5.0;",
        "  'T[3,1]' = 3.0;", "  'T[3,2]' = 6.0;", "  r = 2.5;", "  c = -3.375;",
        "  total = 3.5;", "  'scaled[1]' = -4.5;", "  'scaled[2]' = 6.0;",
        "  'scaled[3]' = -12.0;", "  count = 2;"]


def test_the_parameters_a_call_reads_become_structural() -> None:
    model = flatten_files([], "ForeignLib.M", [LIBRARY])
    assert {"u[1]", "u[2]", "u[3]", "k"} <= set(model.evaluated)


def test_modelica_error_is_a_located_error() -> None:
    err = _error("ForeignLib.Fails")
    assert err.message == ("the external function 'ForeignLib.root' ('foreignlib_root') "
                           "failed: foreignlib_root: x = -4 is negative")
    assert err.span is not None and (err.span.line, err.span.column) == (
        _line("Real y = root(x);"), 14)
    assert [n.message for n in err.notes] == ["its external clause"]


def test_an_argument_known_only_during_the_simulation_is_called_then() -> None:
    # y = root(time): the C function at each evaluation of the model, sqrt(t)
    rows = _simulated("ForeignLib.RunTime", backend="python")
    assert rows["y"] == pytest.approx([t ** 0.5 for t in rows["time"]], rel=1e-12)


def test_an_output_the_call_does_not_set_is_an_error() -> None:
    err = _error("ForeignLib.Unset")
    assert err.message == ("the external call of 'ForeignLib.unset' does not set its "
                           "output 'z'")
    assert err.span is not None and err.span.line == _line("(y, z) = unset(4);")


def test_a_library_without_its_sources_keeps_the_located_error() -> None:
    err = _error("ForeignLib.Missing")
    assert err.message == ("the external function 'ForeignLib.missing' (C function "
                           "'other_function') is not supported: its library does not "
                           "ship its C sources")
    assert err.span is not None and err.span.line == _line("Real y = missing(1);")
    include = LIBRARY / "ForeignLib" / "Resources" / "Include"
    assert [n.message for n in err.notes] == [
        "its external clause", "it links the library 'OtherLib'",
        "the C sources of 'OtherLib' are not in this copy of the library (looked for in "
        "its include directory and Resources/C-Sources)",
        f"its include directory modelica://ForeignLib/Resources/Include ({include}) "
        "holds no C source"]


def test_the_library_is_built_once_and_verified(_cache: Path) -> None:
    expected = _equations("ForeignLib.M")
    built = sorted((_cache / "foreign").glob("*.so"))
    assert len(built) == 4  # one per function: stats, transposed, root, cube
    for library in built:
        record = library.with_name(library.name + ".sha256").read_text().strip()
        assert hashlib.sha256(library.read_bytes()).hexdigest() == record
    built[0].write_bytes(b"not a library")  # damaged: never loaded, built again
    assert _equations("ForeignLib.M") == expected
    record = built[0].with_name(built[0].name + ".sha256").read_text().strip()
    assert hashlib.sha256(built[0].read_bytes()).hexdigest() == record


LIB = '''package Lib
  function f
    input Real x;
    output Real y;
  external "C" y = evil(x) annotation(IncludeDirectory="modelica://Lib/../outside",
                                      Library="Evil");
  end f;
  function remove
    input String name;
  external "C" ModelicaInternal_removeFile(name) annotation(Library="ModelicaExternalC");
  end remove;
  function g
    input Real x;
    output Real y;
  algorithm
    remove("data.txt");
    y := x;
  end g;
  model M
    Real y = f(1);
  end M;
  model R
    Real y = g(1);
  end R;
end Lib;
'''


def test_annotation_paths_stay_inside_the_library(tmp_path: Path) -> None:
    libs = tmp_path / "libs"
    (libs / "Lib").mkdir(parents=True)
    (libs / "Lib" / "package.mo").write_text(LIB)
    (libs / "outside").mkdir()
    (libs / "outside" / "Evil.c").write_text("double evil(double x) { return x; }\n")
    err = _error("Lib.M", [libs])
    assert [n.message for n in err.notes][1:] == [
        "it links the library 'Evil'",
        "the C sources of 'Evil' are not in this copy of the library (looked for in its "
        "include directory and Resources/C-Sources)"]


def test_functions_that_write_files_are_not_called(tmp_path: Path) -> None:
    libs = tmp_path / "libs"
    (libs / "Lib" / "Resources" / "C-Sources").mkdir(parents=True)
    (libs / "Lib" / "package.mo").write_text(LIB)
    kept = tmp_path / "data.txt"
    kept.write_text("kept")
    err = _error("Lib.R", [libs])
    assert err.message == ("springc does not call the external function 'Lib.remove' "
                           "('ModelicaInternal_removeFile'): it writes or removes files, "
                           "folders or the environment")
    assert kept.read_text() == "kept"


def test_a_compiler_error_is_located(tmp_path: Path) -> None:
    libs = tmp_path / "libs"
    shutil.copytree(LIBRARY / "ForeignLib", libs / "ForeignLib")
    source = libs / "ForeignLib" / "Resources" / "C-Sources" / "ForeignLib.c"
    source.write_text(source.read_text() + "\nthis is not C;\n")
    err = _error("ForeignLib.Fails", [libs])
    assert err.message.startswith("the external function 'ForeignLib.root' "
                                  "('foreignlib_root') could not be built: the C compiler "
                                  "refused the library's C sources (")
    assert err.span is not None and err.span.line == _line("Real y = root(x);")


def test_a_symbol_no_source_defines_is_a_located_error(tmp_path: Path) -> None:
    libs = tmp_path / "libs"
    (libs / "Lib").mkdir(parents=True)
    (libs / "Lib" / "package.mo").write_text(
        'package Lib\n  function f\n    input Real x;\n    output Real y;\n'
        '  external "C" y = nowhere(x) annotation(Include="double nowhere(double x);");\n'
        '  end f;\n  model M\n    Real y = f(2);\n  end M;\nend Lib;\n')
    err = _error("Lib.M", [libs])
    assert err.message == ("the external function 'Lib.f' ('nowhere') could not be "
                           "built: it does not load: the library: undefined symbol: "
                           "nowhere")


def test_c_code_in_the_include_annotation_is_not_compiled(tmp_path: Path) -> None:
    libs = tmp_path / "libs"
    (libs / "Lib").mkdir(parents=True)
    for code in ('static double f(double x) { return x; }', '#define f(x) (x)',
                 '#include \\"../outside.h\\"', 'double f(double x) <% return x; %>',
                 '%:define f(x) (x)', '??=define f(x) (x)', '__asm__(\\".text\\");'):
        (libs / "Lib" / "package.mo").write_text(
            'package Lib\n  function f\n    input Real x;\n    output Real y;\n'
            f'  external "C" annotation(Include="{code}");\n'
            '  end f;\n  model M\n    Real y = f(2);\n  end M;\nend Lib;\n')
        err = _error("Lib.M", [libs])
        shown = code.replace('\\"', '"')
        assert err.message == ("the Include annotation of the external function 'Lib.f' "
                               f"holds C code ('{shown}'); springc compiles only the C "
                               "source files a library ships, never code written in model "
                               "text")
        assert err.span is not None and err.span.line == 5


def _library(libs: Path, include_folder: str, header: str | None) -> Path:
    """Lib, whose f(x) = x * H, H from h.h in its include directory ``include_folder``
    (a link to ``header`` where given)."""
    folder = libs / "Lib" / "Resources"
    (folder / "C-Sources").mkdir(parents=True)
    (folder / include_folder).mkdir()
    (folder / "C-Sources" / "Lib.c").write_text(
        '#include "h.h"\ndouble lib_f(double x) { return x * H; }\n')
    target = folder / include_folder / "h.h"
    if header is None:
        target.write_text("#define H 3\ndouble lib_f(double x);\n")
    else:
        target.symlink_to(header)
    (libs / "Lib" / "package.mo").write_text(
        'package Lib\n  function f\n    input Real x;\n    output Real y;\n'
        '  external "C" y = lib_f(x) annotation(Library="Lib", Include="#include \\"h.h\\"",'
        f' IncludeDirectory="modelica://Lib/Resources/{include_folder}");\n'
        '  end f;\n  model M\n    Real y = f(2);\n  end M;\nend Lib;\n')
    return libs


def test_an_include_directory_of_any_name_is_built(tmp_path: Path) -> None:
    # 'My Include' is no plain name: it is built as springc's 'include'; 2 * 3 = 6
    libs = _library(tmp_path / "libs", "My Include", None)
    text = format_flat(flatten_files([], "Lib.M", [libs]))
    assert text.split("equation\n")[1].splitlines()[:-1] == ["  y = 6.0;"]


def test_a_header_linked_out_of_the_library_is_not_read(tmp_path: Path) -> None:
    outside = tmp_path / "outside.h"
    outside.write_text("#define H 3\ndouble lib_f(double x);\n")
    err = _error("Lib.M", [_library(tmp_path / "libs", "Include", str(outside))])
    assert err.message.startswith("the external function 'Lib.f' ('lib_f') could not be "
                                  "built: the C compiler refused the library's C sources (")
    assert err.message.endswith("h.h: No such file or directory")


def test_a_function_called_without_its_declaration_is_an_error(tmp_path: Path) -> None:
    # C would take lib_f to return an int and springc would read a wrong value
    libs = _library(tmp_path / "libs", "Include", None)
    (libs / "Lib" / "Resources" / "Include" / "h.h").write_text("#define H 3\n")
    err = _error("Lib.M", [libs])
    assert err.message.startswith("the external function 'Lib.f' ('lib_f') could not be "
                                  "built: the C compiler refused the library's C sources (")
    assert "implicit" in err.message and "lib_f" in err.message


def test_springc_gives_modelica_utilities_h_to_a_library_without_it(tmp_path: Path) -> None:
    libs = _library(tmp_path / "libs", "Include", None)
    (libs / "Lib" / "Resources" / "C-Sources" / "Lib.c").write_text(
        '#include "ModelicaUtilities.h"\n#include "h.h"\n'
        'double lib_f(double x) { ModelicaFormatError("x = %g, H = %d", x, H); return x; }\n')
    err = _error("Lib.M", [libs])
    assert err.message == "the external function 'Lib.f' ('lib_f') failed: x = 2, H = 3"


def test_a_crash_in_the_c_code_is_a_located_error(tmp_path: Path) -> None:
    # an invalid memory access ends the call, not springc (it died of SIGSEGV, silently)
    libs = _library(tmp_path / "libs", "Include", None)
    (libs / "Lib" / "Resources" / "C-Sources" / "Lib.c").write_text(
        '#include "h.h"\n'
        "double lib_f(double x) { volatile double *p = (volatile double *)(long)(x - 2);"
        " return *p; }\n")
    err = _error("Lib.M", [libs])
    assert err.message == ("the external function 'Lib.f' ('lib_f') failed: the C code "
                           "crashed: an invalid memory access (segmentation fault)")
    assert err.span is not None and err.span.line == 8
    # the handlers are restored and the library's next call runs
    (libs / "Lib" / "Resources" / "C-Sources" / "Lib.c").write_text(
        '#include "h.h"\ndouble lib_f(double x) { return x * H; }\n')
    text = format_flat(flatten_files([], "Lib.M", [libs]))
    assert text.split("equation\n")[1].splitlines()[:-1] == ["  y = 6.0;"]


def _simulated(model: str, **options: object) -> dict[str, list[float]]:
    compiled = springc.compile_model([], model, libraries=[LIBRARY], **options)
    result = springc.simulate(compiled, stop=0.95, interval=0.05)
    return {"time": list(result.time), **{name: list(result[name]) for name in result.names}}


def test_a_call_at_events_takes_values_of_the_simulation() -> None:
    # at each sample t = 0.1 k, stats of the four samples before it: after t = 0.2 the
    # buffer held {0, 0, 0, 0.1}; after t = 0.9 it held {0.5, 0.6, 0.7, 0.8}
    rows = _simulated("ForeignLib.Sampled", backend="python")
    at = rows["time"].index(0.25)
    assert rows["total"][at] == pytest.approx(0.1, rel=1e-12)
    assert rows["count"][at] == 1
    assert rows["scaled[4]"][at] == pytest.approx(0.2, rel=1e-12)
    assert rows["total"][-1] == pytest.approx(2.6, rel=1e-12)
    assert rows["count"][-1] == 4
    assert [rows[f"scaled[{k}]"][-1] for k in range(1, 5)] == pytest.approx(
        [1.0, 1.2, 1.4, 1.6], rel=1e-12)


def test_springc_chooses_the_python_backend_for_a_call_at_run_time() -> None:
    compiled = springc.compile_model([], "ForeignLib.Sampled", libraries=[LIBRARY])
    assert compiled.options.backend == "python"
    assert springc.simulate(compiled, stop=0.95)["total"][-1] == pytest.approx(2.6)


def test_numba_refuses_a_call_at_run_time() -> None:
    with pytest.raises(CodegenError) as info:
        springc.compile_model([], "ForeignLib.Sampled", libraries=[LIBRARY],
                              backend="numba")
    assert info.value.message == (
        "the numba backend cannot call the external C function 'ForeignLib.stats' during "
        "the simulation; the python backend does")


def test_the_c_model_refuses_a_call_at_run_time() -> None:
    compiled = springc.compile_model([], "ForeignLib.Sampled", libraries=[LIBRARY],
                                     backend="python")
    with pytest.raises(CodegenError) as info:
        c_source(compiled)
    assert info.value.message.startswith(
        "the C model cannot call the external C function 'ForeignLib.stats' during the "
        "simulation; the python backend does")


WRITES = '''model W
  Real x(start = 1, fixed = true);
algorithm
  when time > 0.5 then
    ForeignLib.writeText("x", "{file}");
  end when;
equation
  der(x) = -x;
end W;
'''


def test_a_model_writes_no_file(tmp_path: Path) -> None:
    target = tmp_path / "written.txt"
    source = tmp_path / "W.mo"
    source.write_text(WRITES.format(file=target))
    model = flatten_files([source], "W", [LIBRARY])
    assert model.notes == (
        f"{source}:5:5: warning: springc does not write or read files named by a model "
        "nor call impure functions; the call of 'ForeignLib.writeText' is skipped (it "
        f"calls 'ForeignLib.writeText' on the file '{target}')",)
    assert not target.exists()


def test_a_header_that_never_finishes_compiling_is_stopped(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A header that includes itself twice (2^200 inclusions) would keep the compiler
    busy for ever: each of its processes has a CPU-time limit (1 s here)."""
    monkeypatch.setenv("SPRINGC_COMPILE_CPU_SECONDS", "1")
    libs = _library(tmp_path / "libs", "Include", None)
    (libs / "Lib" / "Resources" / "Include" / "h.h").write_text(
        '#include "h.h"\n#include "h.h"\ndouble lib_f(double x);\n')
    err = _error("Lib.M", [libs])
    assert err.message == ("the external function 'Lib.f' ('lib_f') could not be built: "
                           "the C compiler did not finish the library's C sources within "
                           "its limit of 1 CPU seconds")
    assert err.hint == ("a header or source that never finishes compiling (one that "
                        "includes itself?); if the code really needs longer, set "
                        "SPRINGC_COMPILE_CPU_SECONDS=N")
