"""The command line: exit codes, where diagnostics go, and internal errors."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

import springc.pipeline
from springc.cli import main

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")


def run(*args: str, env: dict[str, str] | None = None) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args), prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": "", **(env or {})})
    return result.exit_code, result.stdout, result.stderr


def _crash(*args: object, **kwargs: object) -> None:
    raise ZeroDivisionError("boom")


def test_success_prints_on_stdout_only() -> None:
    code, out, err = run("check", SEED)
    assert (code, err) == (0, "")
    assert out == "SpringMass: 7 unknowns, 7 equations, 3 parameters, 4 parameter arrays: " \
        "balanced\n"


def test_model_error_goes_to_stderr_with_exit_1(tmp_path: Path) -> None:
    bad = tmp_path / "bad.mdl"
    bad.write_text("model M\n  Real x;\nequation\n  x = y;\nend M;\n")
    code, out, err = run("flatten", str(bad))
    assert (code, out) == (1, "")
    assert err.splitlines()[0] == f"{bad}:4:7: error: undefined name 'y'"


def test_internal_error_exit_3_without_traceback(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(springc.pipeline, "flatten_files", _crash)
    code, out, err = run("check", SEED)
    assert (code, out) == (3, "")
    assert err == ("internal error: ZeroDivisionError: boom\n"
                   "this is a bug in springc; rerun with -vv for the traceback and "
                   "report it\n")


def test_internal_error_traceback_with_debug(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(springc.pipeline, "flatten_files", _crash)
    code, _, err = run("--debug", "flatten", SEED)
    assert code == 3
    assert err.startswith("Traceback (most recent call last):\n")
    assert err.endswith("ZeroDivisionError: boom\n")
    assert "in _crash" in err


def test_usage_errors_exit_2(tmp_path: Path) -> None:
    assert run("check", str(tmp_path / "missing.mdl"))[0] == 2
    assert run("check")[0] == 2
    assert run("frobnicate", SEED)[0] == 2
    assert run("check", SEED, "-L", str(tmp_path / "nowhere"))[0] == 2


def test_library_option_and_environment(tmp_path: Path) -> None:
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "parts.mdl").write_text("package Parts\n  model Bob\n    Real x(start = 1);\n"
                                   "  equation\n    der(x) = -x;\n  end Bob;\nend Parts;\n")
    user = tmp_path / "m.mdl"
    user.write_text("model M\n  Parts.Bob b;\nend M;\n")
    expected = "M: 1 unknown, 1 equation, 0 parameters: balanced\n"
    assert run("check", str(user), "-L", str(lib))[:2] == (0, expected)
    assert run("check", str(user), env={"SPRINGC_PATH": str(lib)})[:2] == (0, expected)
    code, _, err = run("check", str(user))
    assert code == 1
    assert err.splitlines()[0] == f"{user}:2:3: error: unknown class 'Parts.Bob'"


def test_dotted_model_option() -> None:
    code, out, _ = run("check", str(ROOT / "models" / "Scenes.mdl"), "--model",
                       "Scenes.Pendulum")
    assert (code, out) == (0, "Scenes.Pendulum: 5 unknowns, 5 equations, 4 parameters: "
                              "balanced\n")
