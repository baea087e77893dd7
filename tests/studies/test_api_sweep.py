"""``springc.sweep``: an xarray Dataset (run x time, parameters as coordinates, units
as attributes) or the study table as a pandas DataFrame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import UsageError

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")
UNITS = """
model Oscillator
  parameter Real k(unit = "N/m") = 4;
  parameter Real m(unit = "kg") = 1;
  Real x(unit = "m", start = 1);
  Real v(unit = "m/s", start = 0);
  Real E(unit = "J") = 0.5*m*v^2 + 0.5*k*x^2;
equation
  der(x) = v;
  m * der(v) = -k * x;
end Oscillator;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_sweep_returns_a_dataset_with_units_and_parameter_coordinates(tmp_path: Path
                                                                     ) -> None:
    path = tmp_path / "Oscillator.mdl"
    path.write_text(UNITS)
    data = springc.sweep(str(path), params={"k": [1.0, 4.0, 9.0]}, stop=1.0,
                         interval=0.25, workers=1, output=tmp_path / "osc.parquet")
    assert dict(data.sizes) == {"run": 3, "time": 5}
    assert data["k"].values.tolist() == [1.0, 4.0, 9.0]
    assert data["x"].attrs == {"units": "m"}
    x = data["x"].values
    t = np.linspace(0, 1, 5)
    for run, k in enumerate((1.0, 4.0, 9.0)):
        assert np.allclose(x[run], np.cos(np.sqrt(k) * t), atol=1e-5)
    import pandas as pd

    summary = pd.read_parquet(tmp_path / "osc.summary.parquet")
    assert summary.columns.tolist()[-4:] == ["E.final", "E.min", "E.max", "E.drift"]
    assert (summary["E.drift"] < 1e-5).all()


def test_sweep_as_dataframe_is_the_study_table() -> None:
    frame = springc.sweep(SEED, params={"spring.k": "1e3,1e4"}, stop=0.1, workers=1,
                          outputs=["spring.x"], parameters={"mass.m": 2.0},
                          as_="dataframe")
    assert frame.columns.tolist() == [
        "run", "time", "spring.k", "spring.x", "status", "error", "solver", "steps",
        "rhs_evaluations", "jacobian_evaluations", "rtol", "estimated_error",
        "warning"]
    single = springc.simulate(SEED, stop=0.1, outputs=["spring.x"],
                              parameters={"spring.k": 1e4, "mass.m": 2.0})
    last = frame[frame["run"] == 1]["spring.x"].to_numpy()
    assert np.array_equal(last, single["spring.x"])


def test_sweep_names_a_bad_argument() -> None:
    with pytest.raises(UsageError, match="as_ must be 'dataset' or 'dataframe'"):
        springc.sweep(SEED, params={"spring.k": [1.0]}, as_="table")


def test_a_variable_named_like_a_fixed_column_is_quoted(tmp_path: Path) -> None:
    path = tmp_path / "Control.mdl"
    path.write_text("model Control\n  parameter Real gain = 2;\n  Real x(start = 0);\n"
                    "  Real error = 1 - x;\nequation\n  der(x) = gain * error;\n"
                    "end Control;\n")
    frame = springc.sweep(str(path), params={"gain": [1.0, 2.0]}, stop=1.0,
                          interval=0.5, workers=1, as_="dataframe")
    assert frame.columns.tolist()[:5] == ["run", "time", "gain", "x", "'error'"]
    assert frame["error"].isna().all()
    assert np.allclose(frame["'error'"], np.exp(-frame["gain"] * frame["time"]),
                       atol=1e-5)


def test_a_structural_parameter_cannot_be_swept(tmp_path: Path) -> None:
    path = tmp_path / "Decay.mdl"
    path.write_text("model Decay\n  parameter Integer n = 2;\n  Real x(start = 1);\n"
                    "equation\n  der(x) = -n * x;\nend Decay;\n")
    with pytest.raises(UsageError) as caught:
        springc.sweep(str(path), params={"n": [1, 2]})
    assert caught.value.message == ("--param n: 'n' is a structural parameter (it changes "
                                    "the equations); a study varies the others")
    assert caught.value.hint == "run one study per value, with --set NAME=VALUE"
