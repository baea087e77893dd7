"""Libraries stored the Modelica way: package folders (``package.mo``, ``package.order``,
one file per class), single-file packages, ``within``, the library path (``-L``,
``SPRINGC_PATH``, ``MODELICAPATH``), lazy loading, and the loader's located errors."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SpringcError, render
from springc.ir.flat import format_equation, format_flat
from springc.parse import load
from springc.pipeline import flatten_files


@pytest.fixture(autouse=True)
def _no_environment_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("MODELICAPATH", raising=False)


def write(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


MECH = {
    "Mech/package.mo": "within;\npackage Mech\n  constant Real g = 9.81;\nend Mech;\n",
    "Mech/package.order": "Parts\nOscillator\n",
    "Mech/Parts/package.mo": "within Mech;\npackage Parts\nend Parts;\n",
    "Mech/Parts/Mass.mo": ("within Mech.Parts;\nmodel Mass\n  parameter Real m = 1;\n"
                           "  Real x(start = 1, fixed = true);\n"
                           "  Real v(start = 0, fixed = true);\n  Real f;\nequation\n"
                           "  der(x) = v;\n  m * der(v) = f;\nend Mass;\n"),
    "Mech/Parts/Spring.mo": ("within Mech.Parts;\nmodel Spring\n  parameter Real k = 1;\n"
                             "  Real s;\n  Real f;\nequation\n  f = -k * s;\nend Spring;\n"),
    "Mech/Oscillator.mo": ("within Mech;\nmodel Oscillator\n  Parts.Mass mass(m = 4);\n"
                           "  Parts.Spring spring(k = 9);\nequation\n  spring.s = mass.x;\n"
                           "  mass.f = spring.f;\nend Oscillator;\n"),
}


def error_text(exc: pytest.ExceptionInfo[SpringcError]) -> str:
    return render(exc.value)


def test_package_folder_tree_flattens(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", MECH)
    user = write(tmp_path, {"m.mo": "model M\n  Mech.Oscillator osc;\nend M;\n"}) / "m.mo"
    assert format_flat(flatten_files([user], None, [lib])) == (
        "model M\n"
        "  parameter Real 'osc.mass.m' = 4;\n"
        "  Real 'osc.mass.x'(start = 1, fixed = true);\n"
        "  Real 'osc.mass.v'(start = 0, fixed = true);\n"
        "  Real 'osc.mass.f';\n"
        "  parameter Real 'osc.spring.k' = 9;\n"
        "  Real 'osc.spring.s';\n"
        "  Real 'osc.spring.f';\n"
        "equation\n"
        "  der('osc.mass.x') = 'osc.mass.v';\n"
        "  'osc.mass.m' * der('osc.mass.v') = 'osc.mass.f';\n"
        "  'osc.spring.f' = -'osc.spring.k' * 'osc.spring.s';\n"
        "  'osc.spring.s' = 'osc.mass.x';\n"
        "  'osc.mass.f' = 'osc.spring.f';\n"
        "end M;\n")


def test_a_library_model_simulates_to_the_closed_form(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", MECH)
    user = write(tmp_path, {"m.mo": "model M\n  Mech.Oscillator osc;\nend M;\n"}) / "m.mo"
    result = springc.simulate([user], libraries=[lib], stop=3.0, interval=0.01, rtol=1e-10,
                              atol=1e-12, cache=False)
    # m x'' = -k x, x(0) = 1, v(0) = 0: x(t) = cos(sqrt(k/m) t) with k/m = 9/4.
    expected = np.cos(math.sqrt(9 / 4) * result.time)
    assert np.max(np.abs(result["osc.mass.x"] - expected)) < 1e-7


def test_only_the_files_lookup_needs_are_parsed(tmp_path: Path) -> None:
    files = dict(MECH)
    for i in range(20):
        files[f"Mech/Unused{i}.mo"] = f"within Mech;\nmodel Unused{i}\n  syntax error here\n"
    lib = write(tmp_path / "lib", files)
    user = write(tmp_path, {"m.mo": "model M\n  Mech.Parts.Mass mass;\nend M;\n"}) / "m.mo"
    tree = load([user], [lib])
    springc.flatten.flatten(tree, None)
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tree.parsed_paths) == [
        "lib/Mech/Parts/Mass.mo", "lib/Mech/Parts/package.mo", "lib/Mech/package.mo",
        "m.mo"]


def test_single_file_package_and_mdl_files(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", {
        "Tools.mo": "package Tools\n  model Decay\n    Real y(start = 2, fixed = true);\n"
                    "  equation\n    der(y) = -y;\n  end Decay;\nend Tools;\n",
        "Other/package.mdl": "within;\npackage Other\nend Other;\n",
        "Other/Gain.mdl": "within Other;\nmodel Gain\n  Real u = 3;\nend Gain;\n"})
    user = write(tmp_path, {"m.mdl": "model M\n  Tools.Decay d;\n  Other.Gain g;\nend M;\n"})
    flat = flatten_files([user / "m.mdl"], None, [lib])
    assert [format_equation(e) for e in flat.equations] == ["'g.u' = 3;", "der('d.y') = -'d.y';"]


def test_library_path_order(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def lib(name: str, value: int) -> Path:
        return write(tmp_path / name, {
            "Lib/package.mo": f"within;\npackage Lib\n  constant Real c = {value};\nend Lib;\n"})
    first, second, third = lib("first", 1), lib("second", 2), lib("third", 3)
    user = write(tmp_path, {"m.mo": "model M\n  Real x = Lib.c;\nend M;\n"}) / "m.mo"

    def value(libraries: list[Path]) -> str:
        return format_equation(flatten_files([user], None, libraries).equations[0])

    monkeypatch.setenv("MODELICAPATH", os.pathsep.join([str(third), str(second)]))
    assert value([]) == "x = 3;"
    monkeypatch.setenv("SPRINGC_PATH", str(second))
    assert value([]) == "x = 2;"  # SPRINGC_PATH before MODELICAPATH
    assert value([first]) == "x = 1;"  # -L first


def test_user_file_takes_precedence_and_named_package_is_not_the_default_model(
        tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", MECH)
    user = write(tmp_path, {"m.mo": "model M\n  Real y = 5;\nend M;\n"}) / "m.mo"
    package = lib / "Mech" / "package.mo"
    assert flatten_files([user, package]).name == "M"
    assert flatten_files([package, user]).name == "M"
    # The named package's folder is loaded lazily like a library's.
    assert flatten_files([package], "Mech.Oscillator").name == "Mech.Oscillator"
    with pytest.raises(SpringcError) as exc:
        flatten_files([package])
    # package.order lists Parts before Oscillator: the first model is Parts.Mass.
    assert error_text(exc) == (
        "error: no model at the top level of the given files: their models sit in packages "
        "(Mech.Parts.Mass, Mech.Parts.Spring, Mech.Oscillator)\n"
        "help: choose one by its dotted name, e.g. --model Mech.Parts.Mass")
    write(lib, {"Mech/package.order": "Oscillator\nParts\n"})
    with pytest.raises(SpringcError) as exc:
        flatten_files([package])
    assert error_text(exc).endswith("e.g. --model Mech.Oscillator")


def test_within_must_match_the_folder(tmp_path: Path) -> None:
    files = dict(MECH)
    files["Mech/Parts/Spring.mo"] = "within Mech;\nmodel Spring\n  Real s;\nend Spring;\n"
    lib = write(tmp_path / "lib", files)
    user = write(tmp_path, {"m.mo": "model M\n  Mech.Parts.Spring s;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    path = lib / "Mech/Parts/Spring.mo"
    assert error_text(exc) == (
        f"{path}:2:1: error: '{path}' is stored in package 'Mech.Parts' but says "
        "within Mech;\n"
        "    2 | model Spring\n"
        "      | ^^^^^^^^^^^^\n"
        "help: start the file with `within Mech.Parts;` or move it to the folder of the "
        "package it names")


def test_file_must_hold_the_class_it_is_named_after(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", {"Pkg/package.mo": "within;\npackage Pkg\nend Pkg;\n",
                                   "Pkg/A.mo": "within Pkg;\nmodel B\nend B;\n"})
    user = write(tmp_path, {"m.mo": "model M\n  Pkg.A a;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    path = lib / "Pkg/A.mo"
    assert error_text(exc).splitlines()[0] == (
        f"{path}:2:1: error: '{path}' must hold exactly the class 'A' (its file name), "
        "found 'B'")


def test_import_of_a_missing_package_is_an_error_at_the_import(tmp_path: Path) -> None:
    # SpringMass exists in the bundled models: it must not be picked instead.
    user = write(tmp_path, {"m.mo": "model M\n  import Missing.SpringMass;\n"
                                    "  SpringMass s;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user])
    assert error_text(exc) == (
        f"{user}:2:3: error: the imported package 'Missing' is not loaded\n"
        "    2 |   import Missing.SpringMass;\n"
        "      |   ^^^^^^^^^^^^^^^^^^^^^^^^^\n"
        "help: load the library that defines it (name its file, or pass its folder with -L "
        "or in MODELICAPATH); searched the files named, then the bundled models")


def test_import_of_a_missing_class_of_a_loaded_package(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", MECH)
    user = write(tmp_path, {"m.mo": "model M\n  import Mech.Parts.Damper;\n"
                                    "  Damper d;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    assert error_text(exc).splitlines()[0] == (
        f"{user}:2:3: error: the imported class 'Mech.Parts.Damper' is not loaded: "
        "'Mech.Parts' has no class 'Damper'")


def test_package_extending_its_own_missing_subpackage(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", {
        "Loop/package.mo": "within;\npackage Loop\n  extends Loop.Icons.Base;\n"
                           "  model A\n    Real x = 1;\n  end A;\nend Loop;\n"})
    user = write(tmp_path, {"m.mo": "model M\n  Loop.Icons.Other a;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    path = lib / "Loop/package.mo"
    assert error_text(exc) == (
        f"{path}:3:3: error: class 'Loop' extends 'Loop.Icons.Base', whose lookup needs "
        "the class 'Icons' of 'Loop' itself, and 'Loop' has no class 'Icons'\n"
        "    3 |   extends Loop.Icons.Base;\n"
        "      |   ^^^^^^^^^^^^^^^^^^^^^^^\n"
        "help: define 'Icons' in 'Loop' (in the package or, for a package folder, as "
        "Icons.mo or Icons/package.mo), or correct the extends clause")


def test_unknown_class_names_the_library_path(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    lib = write(tmp_path / "lib", MECH)
    other = tmp_path / "other"
    other.mkdir()
    monkeypatch.setenv("MODELICAPATH", str(other))
    user = write(tmp_path, {"m.mo": "model M\n  Nowhere.Part p;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    assert error_text(exc).splitlines()[-1] == (
        "help: no class 'Nowhere' is visible here: check the spelling, add an `import`, or "
        "load the file that defines it (name it on the command line or pass its folder "
        f"with -L); searched the files named, then {lib} (-L), then {other} (MODELICAPATH), "
        "then the bundled models")


def test_quoted_names_never_name_files(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", {"Pkg/package.mo": "within;\npackage Pkg\nend Pkg;\n"})
    write(tmp_path, {"Secret.mo": "model Secret\n  Real s = 1;\nend Secret;\n"})
    user = write(tmp_path, {"m.mo": "model M\n  Pkg.'../Secret' a;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    assert error_text(exc).splitlines()[0] == (
        f"{user}:2:3: error: class 'Pkg' has no member class '../Secret'")


def test_an_older_style_mdl_file_may_hold_several_classes(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", {
        "Parts.mdl": "package Parts\n  model A\n    Real a = 1;\n  end A;\nend Parts;\n"
                     "model Helper\n  Real h = 2;\nend Helper;\n"})
    user = write(tmp_path, {"m.mo": "model M\n  Parts.A a;\n  Helper h;\nend M;\n"}) / "m.mo"
    flat = flatten_files([user], None, [lib])
    assert [format_equation(e) for e in flat.equations] == ["'a.a' = 1;", "'h.h' = 2;"]


def test_a_symbolic_link_back_to_a_parent_folder_is_walked_once(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", {"Parts/package.mo": "package Parts\n  model A\n"
                                   "    Real a = 1;\n  end A;\nend Parts;\n"})
    (lib / "Parts" / "Loop").symlink_to(lib / "Parts")
    user = write(tmp_path, {"m.mo": "model M\n  Parts.A a;\nend M;\n"}) / "m.mo"
    assert [format_equation(e) for e in flatten_files([user], None, [lib]).equations] == [
        "'a.a' = 1;"]


def test_an_mdl_file_in_a_folder_that_is_not_a_package_is_not_read(tmp_path: Path) -> None:
    """Only the top of a root may hold older-style .mdl files: a stray one further down
    is not part of the library (it could define package Modelica)."""
    lib = write(tmp_path / "lib", {"junk/deeper/evil.mdl": "package Evil\n  "
                                   "constant Real k = 4;\nend Evil;\n",
                                   "Parts.mdl": "package Parts\n  model A\n"
                                   "    Real a = 1;\n  end A;\nend Parts;\n"})
    user = write(tmp_path, {"m.mo": "model M\n  Parts.A a;\n  Real b = Evil.k;\n"
                                    "end M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    assert error_text(exc).splitlines()[0] == f"{user}:3:12: error: undefined name 'Evil'"


def test_a_library_tree_deeper_than_a_path_may_be_is_cached_by_what_was_read(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A package tree deeper than the longest path the system accepts: loading never
    reaches its bottom, and the cache key (what the load read) never walks it."""
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    lib = tmp_path / "lib"
    lib.mkdir()
    name = "P" * 100
    fds = [os.open(lib, os.O_RDONLY)]
    for _ in range(45):  # 45 levels of 101 characters: past PATH_MAX (4096)
        os.mkdir(name, dir_fd=fds[-1])
        fd = os.open(name, os.O_RDONLY, dir_fd=fds[-1])
        with os.fdopen(os.open("package.mo", os.O_WRONLY | os.O_CREAT, dir_fd=fd),
                       "w") as file:
            file.write(f"package {name}\nend {name};\n")
        fds.append(fd)
    try:
        user = write(tmp_path, {"m.mo": "model M\n  Real x = 1;\nend M;\n"}) / "m.mo"
        first = springc.compile_model(str(user), libraries=[str(lib)], backend="python")
        again = springc.compile_model(str(user), libraries=[str(lib)], backend="python")
        assert (first.cached, again.cached, again.path) == (False, True, first.path)
    finally:
        for fd, parent in zip(fds[:0:-1], fds[-2::-1], strict=True):
            os.unlink("package.mo", dir_fd=fd)
            os.close(fd)
            os.rmdir(name, dir_fd=parent)
        os.close(fds[0])


def test_a_type_name_too_long_for_a_file_name_is_an_unknown_class(tmp_path: Path) -> None:
    name = "A" * 300
    user = write(tmp_path, {"m.mo": f"model M\n  {name} a;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [tmp_path])
    assert error_text(exc).splitlines()[0] == (
        f"{user}:2:3: error: unknown class '{name}'")


def test_a_missing_member_of_a_package_folder_names_the_folder(tmp_path: Path) -> None:
    lib = write(tmp_path / "lib", MECH)
    user = write(tmp_path, {"m.mo": "model M\n  Mech.Parts.Damper d;\nend M;\n"}) / "m.mo"
    with pytest.raises(SpringcError) as exc:
        flatten_files([user], None, [lib])
    assert error_text(exc).splitlines()[0] == (
        f"{user}:2:3: error: class 'Mech.Parts' has no member class 'Damper'")
    assert error_text(exc).splitlines()[-1] == (
        f"note: searched the package folder {lib / 'Mech' / 'Parts'} for Damper.mo, "
        "Damper.mdl and Damper/package.mo")


def test_the_command_line_simulates_the_users_model_not_the_librarys(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from springc.cli import main
    lib = write(tmp_path / "lib", MECH)
    user = write(tmp_path, {"m.mo": "model M\n  Mech.Parts.Mass mass(m = 2);\n"
                                    "equation\n  mass.f = -8 * mass.x;\nend M;\n"}) / "m.mo"
    package = lib / "Mech" / "package.mo"
    for files in ([str(user), str(package)], [str(package), str(user)]):
        result = CliRunner().invoke(main, ["check", *files], prog_name="springc",
                                    env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
        assert (result.exit_code, result.output) == (
            0, "M: 3 unknowns, 3 equations, 1 parameter: balanced\n")


def test_a_top_level_class_hiding_another_gets_a_note(tmp_path: Path) -> None:
    """An older-style .mdl at the top of a -L root defines package Modelica: it is used
    (the library path's order), with a note naming both files."""
    from springc.resources import models_dir

    lib = write(tmp_path / "lib", {"mine.mdl": "package Modelica\n  package Mine\n"
                                   "    constant Real k = 4;\n  end Mine;\n"
                                   "end Modelica;\n"})
    user = write(tmp_path, {"m.mo": "model M\n  Real a = Modelica.Mine.k;\nend M;\n"})
    flat = flatten_files([user / "m.mo"], None, [lib])
    assert [format_equation(e) for e in flat.equations] == ["a = 4;"]
    assert flat.notes == (
        f"note: the top-level class 'Modelica' is taken from {lib / 'mine.mdl'}; it hides "
        f"{models_dir() / 'Modelica' / 'package.mo'} (the bundled models)",)


MSL_LIKE = {
    # the layout of the Modelica Standard Library as distributed: a package folder
    "Modelica/package.mo": "within;\npackage Modelica\n  extends Modelica.Icons.Package;\n"
                           "end Modelica;\n",
    "Modelica/package.order": "Icons\nBlocks\nMechanics\n",
    "Modelica/Icons.mo": "within Modelica;\npackage Icons\n  partial package Package\n"
                         "  end Package;\nend Icons;\n",
    "Modelica/Blocks/package.mo": "within Modelica;\npackage Blocks\n"
                                  "  this is not Modelica;\nend Blocks;\n",
    "Modelica/Mechanics/package.mo": "within Modelica;\npackage Mechanics\n"
                                     "  constant Real k = 7;\nend Mechanics;\n",
}


@pytest.mark.parametrize("how", ["-L", "MODELICAPATH"])
def test_the_real_library_on_the_path_takes_precedence_over_the_bundled_one(
        tmp_path: Path, how: str) -> None:
    """The MSL (a ``Modelica`` folder) on ``-L`` or ``MODELICAPATH`` is used instead of
    the bundled ``Modelica``, with a note naming both; read lazily: the file of a
    package the model does not use (here one that does not even parse) is not read."""
    from click.testing import CliRunner

    from springc.cli import main
    from springc.resources import models_dir

    lib = write(tmp_path / "lib", MSL_LIKE)
    user = write(tmp_path, {"m.mo": "model M\n  Real a = Modelica.Mechanics.k;\nend M;\n"})
    options = ["-L", str(lib)] if how == "-L" else []
    result = CliRunner().invoke(
        main, ["check", *options, str(user / "m.mo")], prog_name="springc",
        env={"SPRINGC_PATH": "", "MODELICAPATH": str(lib) if how != "-L" else ""})
    assert (result.exit_code, result.output) == (0, (
        f"note: the top-level class 'Modelica' is taken from "
        f"{lib / 'Modelica' / 'package.mo'}; it hides "
        f"{models_dir() / 'Modelica' / 'package.mo'} (the bundled models)\n"
        "M: 1 unknown, 1 equation, 0 parameters: balanced\n"))
