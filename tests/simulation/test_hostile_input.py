"""Hostile input to ``simulate`` (issue 10): unbalanced models, extreme parameters,
non-finite observed values, a step that does not fit the output grid. Each case ends
with a clear, located error (CLI exit 1, no traceback, no output file) or a stated
behaviour, never a hang, an internal error or a silent wrong answer."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import BalanceError, render

ROOT = Path(__file__).resolve().parents[2]
SEED_TEXT = (ROOT / "models" / "SpringMass.mdl").read_text()
SCENES = str(ROOT / "models" / "Scenes.mdl")


def simulate_cli(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(main, ["simulate", *args, "-q"])
    assert "Traceback" not in result.output and "internal error" not in result.output
    return result.exit_code, result.output


# ------------------------------------------------------------------ balance


def test_simulate_reports_a_missing_equation_as_check_does(tmp_path: Path) -> None:
    path = tmp_path / "missing.mdl"
    path.write_text(SEED_TEXT.replace("  spring.x = sqrt(spring.dir * spring.dir);\n", ""))
    with pytest.raises(BalanceError) as info:
        springc.simulate([path], cache=False)
    text = render(info.value)
    assert text.startswith(f"{path}:18:1: error: model 'SpringMass' is under-determined: "
                           "7 unknowns, 6 equations\n")
    assert f"{path}:14:8: note: 'spring.x' (in spring) is left undetermined" in text
    out = tmp_path / "out.csv"
    code, output = simulate_cli(str(path), "-o", str(out), "--no-cache")
    assert code == 1 and not out.exists()
    check = CliRunner().invoke(main, ["check", str(path)])
    assert output == check.output  # the same diagnostic as `springc check`


def test_simulate_names_a_surplus_equation(tmp_path: Path) -> None:
    path = tmp_path / "extra.mdl"
    path.write_text(SEED_TEXT.replace("  der(pos) = v;\n", "  der(pos) = v;\n  v[1] = 0;\n"))
    code, output = simulate_cli(str(path), "--no-cache")
    assert code == 1
    assert output.startswith(f"{path}:19:1: error: model 'SpringMass' is over-determined: "
                             "7 unknowns, 8 equations\n")
    assert (f"{path}:9:3: note: equation in mass `mass.v[1] = 0` is one of 8 equations "
            "for only 7 unknowns") in output
