"""``springc simulate`` honours initial equations (solved by springc.simplify.initialize)."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from springc.cli import main

SETTLE = """model Settle "A mass on a spring, started at equilibrium by an initial equation"
  parameter Real k = 100, m = 2, g = 9.81;
  Real x(start = 0), v(start = 0);
initial equation
  der(v) = 0;
  v = 0;
equation
  der(x) = v;
  m*der(v) = -k*x - m*g;
end Settle;
"""


def test_initial_equation_sets_the_equilibrium(tmp_path: Path) -> None:
    model = tmp_path / "settle.mdl"
    model.write_text(SETTLE)
    result = CliRunner().invoke(main, ["simulate", str(model), "--stop", "1", "--interval",
                                       "0.5", "--quiet", "--no-cache", "--set", "k=200"])
    assert result.exit_code == 0, result.output
    rows = [line.split(",") for line in result.stdout.strip().splitlines()]
    assert rows[0] == ["time", "x", "v"]
    # At rest: k x = -m g, so x = -2 * 9.81 / 200 for all times (with --set k=200).
    for row in rows[1:]:
        assert abs(float(row[1]) + 2 * 9.81 / 200) < 1e-9
        assert abs(float(row[2])) < 1e-9
