"""The README teaches what the code does: its test command, and its first model checked,
simulated and plotted as it says (the model against the closed form of its first swing)."""

from __future__ import annotations

import csv
import math
import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.optimize import brentq

import springc
from springc.cli import main

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    """The README's fenced code blocks of one language, in order."""
    return re.findall(rf"^```{language}\n(.*?)^```$", README, flags=re.M | re.S)


def run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args), prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    return result.exit_code, result.stdout, result.stderr


@pytest.fixture()
def first(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The README's first model, saved as it says, in a fresh working folder."""
    (model,) = blocks("modelica")
    path = tmp_path / "first.mdl"
    path.write_text(model, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    return path


def test_the_first_code_block_starts_with_the_two_set_up_commands() -> None:
    # .ci/run runs the second line of the first code block (its awk program)
    first_block = blocks("sh")[0].splitlines()
    assert README.index("```sh") == README.index("```")
    assert first_block == [
        "python -m pip install . && springc simulate models/SpringMass.mdl -o seed.csv "
        "--plot seed.png",
        'python -m pip install -e ".[test]" && python -m pytest -q']


def test_the_first_model_checks_as_the_readme_shows(first: Path) -> None:
    shown = re.search(r"^\$ springc check first\.mdl\n(.*)$", README, flags=re.M)
    assert shown is not None
    assert run("check", "first.mdl") == (0, shown.group(1) + "\n", "")


def swing(t: float) -> float:
    """mass.s before the first contact: m s'' = c (1 - s) - d s' - m g, s(0) = 1.6, v(0) = 0."""
    m, c, d, g = 1.0, 40.0, 0.4, 9.81
    rest = 1 - m * g / c
    decay, omega = d / (2 * m), math.sqrt(c / m - (d / (2 * m)) ** 2)
    return rest + (1.6 - rest) * math.exp(-decay * t) * (
        math.cos(omega * t) + decay / omega * math.sin(omega * t))


def test_the_first_model_simulates_as_the_readme_says(first: Path) -> None:
    (command,) = [line for line in blocks("sh")[1:] if line.startswith("springc simulate")]
    code, _, _ = run(*shlex.split(command.strip())[1:])
    assert code == 0
    assert (first.parent / "first.png").stat().st_size > 0
    with open(first.parent / "first.csv", newline="") as f:
        header, *rows = list(csv.reader(f))
    assert header == ["time", "mass.s", "mass.v", "stop.f"]
    table = np.array(rows, dtype=float)
    assert (table[0, 0], table[-1, 0], len(table)) == (0.0, 6.0, 3001)  # 0..6 s by 2 ms
    impact = brentq(lambda t: swing(t) - 0.5, 0.1, 0.5)  # the floor's flange at 0.5 m
    before = table[table[:, 0] < impact]
    assert np.max(np.abs(before[:, 1] - [swing(t) for t in before[:, 0]])) < 1e-6
    assert np.all(before[:, 3] == 0.0)
    # the README's "12 contact events": 6 contacts, each begun and ended by an event
    contacts = np.count_nonzero(np.diff((table[:, 3] != 0).astype(int)) == 1)
    stats = springc.simulate(str(first)).stats
    assert (contacts, stats.state_events, stats.time_events) == (6, 12, 0)
