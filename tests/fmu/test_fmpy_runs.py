"""FMUs exported by springc, validated and run by another tool (FMPy): ``validate_fmu``
reports no problem, and Model Exchange (FMPy's CVode) and Co-Simulation (the FMU's
embedded Dormand-Prince solver) agree with springc's own results within 1e-4 of each
variable's largest magnitude, for FMI 3.0 and FMI 2.0, on the seed, the bundled
bouncing ball (state events), a Modelica.Mechanics.Translational example and the
100-mass chain, and a model with time events (``sample``, ``time >= 1``)."""

from __future__ import annotations

from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.validation import validate_fmu

import springc
from springc.simulation import SimulationResult

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
TEST_MODELS = Path(__file__).resolve().parent / "models.mo"
TOLERANCE = 1e-4

# name: (files, model, stop time, variables compared)
CASES = {
    "seed": ([MODELS / "SpringMass.mdl"], None, 2.0,
             ["mass.pos[1]", "mass.pos[2]", "mass.v[2]", "spring.x"]),
    "bouncing ball": ([MODELS / "EventScenes.mdl"], "EventScenes.BouncingBall", 3.5,
                      ["h", "v", "bounces"]),
    "translational": ([TEST_MODELS], "TranslationalOscillator", 3.0,
                      ["mass.s", "mass.v", "spring.f"]),
    "100-mass chain": ([MODELS / "Scenes.mdl", TEST_MODELS], "Chain100", 2.0,
                       ["m[1].s", "m[50].v", "m[100].s"]),
    "time events": ([TEST_MODELS], "Kicked", 2.0, ["x", "v", "kicks"]),
}
POINTS = 199  # no output point falls on an event before the stop time (0.4 k, 1 s)


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def references() -> dict[str, SimulationResult]:
    """springc's own results of each case on the grid the FMUs report."""
    out = {}
    for name, (files, model, stop, variables) in CASES.items():
        out[name] = springc.simulate([str(f) for f in files], model_name=model, stop=stop,
                                     interval=stop / POINTS, rtol=1e-9, atol=1e-9,
                                     outputs=variables, engine="scipy", backend="python")
    return out


def _deviation(result: np.ndarray, reference: SimulationResult,
               variables: list[str]) -> float:
    """The largest difference of the FMU's rows at the reference's times (the rows FMPy
    adds at events are skipped), relative to each variable's largest magnitude."""
    rows = np.searchsorted(result["time"], reference.time + 1e-9) - 1
    assert np.allclose(result["time"][rows], reference.time, rtol=0, atol=1e-9)
    worst = 0.0
    for name in variables:
        expected = np.asarray(reference[name], dtype=float)
        scale = max(float(np.max(np.abs(expected))), 1e-12)
        worst = max(worst, float(np.max(np.abs(result[name][rows] - expected))) / scale)
    return worst


@pytest.mark.parametrize("version", [3, 2])
@pytest.mark.parametrize("case", list(CASES))
def test_fmpy_validates_and_runs_the_fmu_as_springc_does(
        case: str, version: int, tmp_path: Path,
        references: dict[str, SimulationResult]) -> None:
    files, model, stop, variables = CASES[case]
    path = tmp_path / "model.fmu"
    done = springc.export_fmu([str(f) for f in files], path, model, fmi_version=version)
    assert (done.binary, done.fmi_version, done.note) == (True, version, None)
    assert validate_fmu(str(path)) == []
    description = fmpy.read_model_description(str(path))
    assert description.fmiVersion == f"{version}.0"
    assert description.modelExchange is not None and description.coSimulation is not None
    for kind in ("ModelExchange", "CoSimulation"):
        result = fmpy.simulate_fmu(str(path), fmi_type=kind, stop_time=stop,
                                   relative_tolerance=1e-9, output=variables,
                                   output_interval=stop / POINTS)
        assert _deviation(result, references[case], variables) < TOLERANCE, kind


@pytest.mark.parametrize("version", [3, 2])
def test_parameters_set_by_the_importer_move_the_bound_ones_and_the_starts(
        version: int, tmp_path: Path) -> None:
    """The chain's spring constant ``k`` binds every ``s[i].c`` (calculated parameters)
    and ``ds`` the start of ``m[1].s``: set through FMPy, they change the run as
    ``springc.simulate(parameters=...)`` does."""
    path = tmp_path / "chain.fmu"
    springc.export_fmu(str(MODELS / "Scenes.mdl"), path, "Scenes.Chain", fmi_version=version)
    causality = {v.name: v.causality for v in fmpy.read_model_description(str(path))
                 .modelVariables}
    assert (causality["k"], causality["s[3].c"]) == ("parameter", "calculatedParameter")
    values = {"k": 200.0, "ds": 0.3}
    reference = springc.simulate(str(MODELS / "Scenes.mdl"), model_name="Scenes.Chain",
                                 stop=2.0, interval=0.01, rtol=1e-9, atol=1e-9,
                                 parameters=values, engine="scipy", backend="python")
    for kind in ("ModelExchange", "CoSimulation"):
        result = fmpy.simulate_fmu(str(path), fmi_type=kind, stop_time=2.0,
                                   relative_tolerance=1e-9, output=["m[1].s", "m[5].v"],
                                   output_interval=0.01, start_values=values)
        assert result["m[1].s"][0] == pytest.approx(1.3, abs=1e-12)
        assert _deviation(result, reference, ["m[1].s", "m[5].v"]) < TOLERANCE, kind


def test_a_co_simulation_step_handles_every_event_inside_it(tmp_path: Path) -> None:
    """Communication steps of 0.5 s over the bouncing ball: each doStep locates and
    handles the impacts inside it (9 by 3.5 s) with its own solver."""
    files, model, stop, variables = CASES["bouncing ball"]
    path = tmp_path / "ball.fmu"
    springc.export_fmu([str(f) for f in files], path, model)
    reference = springc.simulate([str(f) for f in files], model_name=model, stop=stop,
                                 interval=0.5, rtol=1e-9, atol=1e-9, outputs=variables,
                                 engine="scipy", backend="python")
    result = fmpy.simulate_fmu(str(path), fmi_type="CoSimulation", stop_time=stop,
                               relative_tolerance=1e-9, output=variables,
                               output_interval=0.5)
    assert list(result["bounces"]) == [0, 1, 1, 2, 3, 4, 6, 9]  # as springc counts them
    assert _deviation(result, reference, variables) < TOLERANCE


@pytest.mark.parametrize("version", [3, 2])
def test_a_contact_closing_exactly_at_an_output_point_is_not_missed(
        version: int, tmp_path: Path) -> None:
    """Newton's cradle: the first ball closes its gap at t = 1 ms, an output point, where
    the contact's indicator is exactly 0 and then turns negative; the FMU reads a zero
    on the side of the relation's held value, so both CVode and the embedded solver see
    the sign change (before, the balls passed through each other)."""
    files, model = [MODELS / "EventScenes.mdl"], "EventScenes.NewtonsCradle"
    variables, stop = ["ball[1].s", "ball[5].v"], 0.02
    path = tmp_path / "cradle.fmu"
    springc.export_fmu([str(f) for f in files], path, model, fmi_version=version)
    reference = springc.simulate([str(f) for f in files], model_name=model, stop=stop,
                                 interval=1e-4, rtol=1e-9, atol=1e-9, outputs=variables,
                                 engine="scipy", backend="python")
    for kind in ("ModelExchange", "CoSimulation"):
        result = fmpy.simulate_fmu(str(path), fmi_type=kind, stop_time=stop,
                                   relative_tolerance=1e-9, output=variables,
                                   output_interval=1e-4)
        assert result["ball[5].v"][-1] == pytest.approx(1.0, abs=1e-3), kind
        assert _deviation(result, reference, variables) < TOLERANCE, kind
