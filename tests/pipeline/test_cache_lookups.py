"""The cache key of a model is what its compile read (``parse.Lookups``): an edit of a
file the model read, or a new file that a lookup would now find first, compiles again;
an edit of a library file the model never read does not; the record is data, checked
and never trusted."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import springc
from springc.parse import still_hold
from springc.pipeline.cache import LOOKUPS_FILE

LIB = {
    "P/package.mo": "within;\npackage P\n  constant Real k = 2;\nend P;\n",
    "P/K.mo": "within P;\nmodel K\n  Real v = 3;\nend K;\n",
    "P/Sub/package.mo": "within P;\npackage Sub\nend Sub;\n",
    "P/Sub/M.mo": "within P.Sub;\nmodel M\n  K kk;\n  Real y = kk.v;\nend M;\n",
    "P/Unused.mo": "within P;\nmodel Unused\n  Real u = 1;\nend Unused;\n",
}


@pytest.fixture
def lib(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("MODELICAPATH", raising=False)
    root = tmp_path / "lib"
    for name, text in LIB.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root


def compiled(lib: Path) -> springc.CompiledModel:
    return springc.compile_model([], "P.Sub.M", libraries=[str(lib)], backend="python")


def y_of(model: springc.CompiledModel) -> float:
    return float(springc.simulate(model, stop=0.1, interval=0.1)["y"][-1])


def test_an_edit_of_a_file_the_model_read_compiles_again(lib: Path) -> None:
    first = compiled(lib)
    assert (first.cached, y_of(first)) == (False, 3.0)
    (lib / "P" / "K.mo").write_text("within P;\nmodel K\n  Real v = 5;\nend K;\n")
    edited = compiled(lib)
    assert (edited.cached, y_of(edited)) == (False, 5.0)
    assert compiled(lib).cached  # and then it is the cached one


def test_an_edit_of_a_library_file_the_model_never_read_keeps_the_entry(lib: Path) -> None:
    first = compiled(lib)
    (lib / "P" / "Unused.mo").write_text("within P;\nmodel Unused\n  Real u = 2;\nend Unused;\n")
    (lib / "P" / "Other.mo").write_text("within P;\nmodel Other\nend Other;\n")
    again = compiled(lib)
    assert (again.cached, again.path) == (True, first.path)


def test_a_new_file_that_lookup_finds_first_compiles_again(lib: Path) -> None:
    """``K`` in ``P.Sub.M`` was looked for in ``P/Sub`` (not found: recorded) before it
    was found in ``P``: a ``P/Sub/K.mo`` added later is the class lookup finds now."""
    assert y_of(compiled(lib)) == 3.0
    (lib / "P" / "Sub" / "K.mo").write_text("within P.Sub;\nmodel K\n  Real v = 7;\nend K;\n")
    shadowed = compiled(lib)
    assert (shadowed.cached, y_of(shadowed)) == (False, 7.0)


def test_a_lookups_record_is_checked_never_trusted(lib: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    first = compiled(lib)
    (record,) = (lib.parent / "cache").glob(f"*/{LOOKUPS_FILE}")
    data = json.loads(record.read_text())
    assert still_hold(data)
    asked = {item[0] for item in data["lookups"]}
    assert {"dir", "class", "file"} <= asked
    record.write_text(record.read_text().replace('"format":1', '"format":1 '))
    again = compiled(lib)  # a record that does not match its hash: derived again, the
    assert f"note: {record} does not match its recorded hash; building it again" in \
        capsys.readouterr().err
    assert json.loads(record.read_text()) == data  # same reads: the same (checked) module
    assert (again.cached, again.path, y_of(again)) == (True, first.path, 3.0)


@pytest.mark.parametrize("record", [
    None, [], {"format": 2, "lookups": []}, {"format": 1},
    {"format": 1, "lookups": [["rm", "-rf", True]]},
    {"format": 1, "lookups": [["class", "/", 3, None]]},
    {"format": 1, "lookups": [["file", "/nonexistent/springc/x.mo", [None, "0" * 64]]]},
])
def test_a_record_that_is_not_one_never_holds(record: object) -> None:
    assert still_hold(record) is False


def test_an_empty_record_holds() -> None:
    assert still_hold({"format": 1, "lookups": []}) is True
