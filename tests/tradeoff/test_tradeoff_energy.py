"""``springc tradeoff`` energy drift: the energy variable (by unit or ``--energy``), the
drift of velocity Verlet against its closed-form bound, and the errors."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import SimulationError
from springc.tradeoff import TradeoffOptions, compare_states, run_tradeoff

OSCILLATOR = """
model Oscillator "x'' = -x, energy E = (v^2 + x^2)/2 = 1/2"
  parameter Real k = 1;
  Real x(start = 1);
  Real v(start = 0);
  Real E(unit = "J") = 0.5 * v^2 + 0.5 * k * x^2;
  Real L = x * v "not an energy";
equation
  der(x) = v;
  der(v) = -k * x;
end Oscillator;
"""
PERIOD = 2 * math.pi
STEP = PERIOD / 40


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def oscillator(tmp_path: Path) -> str:
    path = tmp_path / "Oscillator.mdl"
    path.write_text(OSCILLATOR)
    return str(path)


def _study(path: str, energy: str | None = None):  # type: ignore[no-untyped-def]
    model = compare_states(springc.compile_model(path, "Oscillator"))
    options = TradeoffOptions(solvers=("verlet", "rk4", "dop853"), tolerances=(1e-3,),
                              steps=(STEP,), repeats=1, stop=50 * PERIOD,
                              interval=PERIOD / 10, energy=energy)
    return model, run_tradeoff(model, options)


def test_verlet_drift_is_bounded_by_the_closed_form(oscillator: str) -> None:
    model, study = _study(oscillator)
    assert study.energy == "E"  # the only variable in J
    runs = {r.solver: r for r in study.runs}
    # Velocity Verlet on x'' = -x conserves a modified energy: E itself oscillates by
    # at most (omega*h)^2/4 relative, with no drift over 50 periods.
    bound = STEP**2 / 4
    assert 0.5 * bound < runs["verlet"].energy_drift <= 1.05 * bound
    # The same drift, recomputed here from the run's states.
    result = springc.simulate(model, solver="verlet", step=STEP, stop=50 * PERIOD,
                              interval=PERIOD / 10)
    energy = 0.5 * result["v"] ** 2 + 0.5 * result["x"] ** 2
    assert runs["verlet"].energy_drift == pytest.approx(
        np.max(np.abs(energy - 0.5)) / 0.5, rel=1e-9)
    # rk4 loses energy steadily: E_n = |R(i h)|^(2n) E_0, R its stability polynomial.
    z = 1j * STEP
    decay = abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24) ** (2 * runs["rk4"].steps)
    assert runs["rk4"].energy_drift == pytest.approx(1 - decay, rel=1e-6)


def test_named_energy_and_the_table_column(oscillator: str, tmp_path: Path) -> None:
    out = tmp_path / "table.csv"
    result = CliRunner().invoke(main, [
        "tradeoff", oscillator, "--solvers", "verlet", "--steps", str(STEP), "--stop",
        str(10 * PERIOD), "--interval", str(PERIOD / 10), "--repeats", "1", "--energy", "L",
        "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    assert "L drift" in result.output
    rows = list(csv.DictReader(out.open()))
    verlet = next(r for r in rows if r["solver"] == "verlet")
    # L = x v = -sin(2t)/2 exactly: L(0) = 0 and |L| peaks at 1/2, so the "drift" of L
    # is about 1 (verlet's phase error adds a few percent), not E's 6e-3.
    assert 0.95 < float(verlet["energy_drift"]) < 1.1


def test_unknown_energy_variable(oscillator: str) -> None:
    with pytest.raises(SimulationError) as caught:
        _study(oscillator, energy="F")
    assert caught.value.message == "'F' is not a variable of Oscillator"
    # str() is the text the command line prints
    assert str(caught.value) == (
        "error: 'F' is not a variable of Oscillator\nhelp: name a state or observed "
        "variable of the model, e.g. one declared as Real E = 0.5*m*v^2 + 0.5*k*x^2")
