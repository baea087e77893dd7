"""``springc fmu`` and ``springc.export_fmu``: what modelDescription.xml says of a model
(causality, variability, initial, units, descriptions, dependencies, the default
experiment), the FMU's files, a sources-only FMU where no C compiler is found (its
build description is complete: the sources it lists compile into a working binary),
refused constructs and the file-safety rules of ``-o``."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from click.testing import CliRunner
from fmpy.model_description import read_build_description
from fmpy.validation import validate_fmu

import springc
from springc.cli import main
from springc.errors import UsageError
from springc.pipeline import find_compiler

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
EVENTS = str(ROOT / "models" / "EventScenes.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def _description(path: Path) -> ET.Element:
    with zipfile.ZipFile(path) as archive:
        return ET.fromstring(archive.read("modelDescription.xml"))


def _variables(root: ET.Element) -> dict[str, dict[str, str]]:
    found = {}
    for element in root.find("ModelVariables") or []:
        attributes = dict(element.attrib)
        attributes["type"] = element.tag
        found[attributes.pop("name")] = attributes
    return found


def test_the_bouncing_ball_fmi3_description(tmp_path: Path) -> None:
    path = tmp_path / "ball.fmu"
    springc.export_fmu(EVENTS, path, "EventScenes.BouncingBall")
    root = _description(path)
    assert root.get("fmiVersion") == "3.0"
    variables = _variables(root)
    assert variables["h"] == {
        "valueReference": "1", "description": "Height above the floor",
        "causality": "local", "variability": "continuous", "initial": "exact",
        "start": "1.0", "unit": "m", "type": "Float64"}
    assert variables["der(v)"]["derivative"] == "2"
    assert variables["der(v)"]["unit"] == "m/s2"
    assert variables["e"] == {
        "valueReference": "5", "description": "Coefficient of restitution",
        "causality": "parameter", "variability": "fixed", "initial": "exact",
        "start": "0.8", "type": "Float64"}
    assert variables["bounces"]["type"] == "Int32"
    assert variables["bounces"]["variability"] == "discrete"
    assert variables["time"]["causality"] == "independent"
    units = {u.get("name"): u.find("BaseUnit").attrib  # type: ignore[union-attr]
             for u in root.iter("Unit")}
    assert units["m/s2"] == {"m": "1", "s": "-2"}
    assert root.find("DefaultExperiment").attrib == {  # type: ignore[union-attr]
        "startTime": "0.0", "stopTime": "3.5", "tolerance": "1e-08", "stepSize": "0.001"}
    structure = root.find("ModelStructure")
    assert structure is not None
    derivatives = {d.get("valueReference"): d.get("dependencies")
                   for d in structure.iter("ContinuousStateDerivative")}
    assert derivatives == {"3": "2", "4": ""}  # der(h) = v, der(v) = -g
    indicators = [e.get("valueReference") for e in structure.iter("EventIndicator")]
    assert variables["crossing[1]"]["valueReference"] == indicators[0]
    assert variables["crossing[1]"]["description"] == "event indicator: h <= 0"


def test_the_seed_fmi2_description_indexes_and_dependencies(tmp_path: Path) -> None:
    path = tmp_path / "seed.fmu"
    done = springc.export_fmu(SEED, path, fmi_version=2)
    root = _description(path)
    assert (root.get("fmiVersion"), root.get("numberOfEventIndicators")) == ("2.0", "0")
    assert done.states == 4
    names = [v.get("name") for v in root.iter("ScalarVariable")]
    index = {name: str(i + 1) for i, name in enumerate(names)}
    real = {v.get("name"): v.find("Real") for v in root.iter("ScalarVariable")}
    assert real["der(mass.v[1])"].get("derivative") == index["mass.v[1]"]  # type: ignore[union-attr]
    unknowns = {u.get("index"): u.get("dependencies")
                for u in root.find("ModelStructure/Derivatives") or []}
    # der(v) reads the positions through spring.dir and spring.x; der(pos) = v
    assert unknowns[index["der(mass.v[2])"]] == f"{index['mass.pos[1]']} {index['mass.pos[2]']}"
    assert unknowns[index["der(mass.pos[1])"]] == index["mass.v[1]"]
    with zipfile.ZipFile(path) as archive:
        files = set(archive.namelist())
    assert "binaries/linux64/SpringMass.so" in files
    assert {"sources/model.c", "sources/springc_glue.c", "sources/springc_fmi2.c"} <= files


def test_an_export_is_the_same_bytes_every_time(tmp_path: Path) -> None:
    springc.export_fmu(SEED, tmp_path / "a.fmu")
    springc.export_fmu(SEED, tmp_path / "b.fmu")
    assert (tmp_path / "a.fmu").read_bytes() == (tmp_path / "b.fmu").read_bytes()


def test_without_a_compiler_the_fmu_holds_sources_that_build(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    compiler = find_compiler()  # found before the PATH is emptied (zig cc where no cc)
    path_before = os.environ["PATH"]
    monkeypatch.setenv("PATH", str(tmp_path))  # no compiler on it
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setitem(sys.modules, "ziglang", None)  # nor zig cc from PyPI
    path = tmp_path / "SpringMass.fmu"
    result = CliRunner().invoke(main, ["fmu", SEED, "-o", str(path)])
    assert result.exit_code == 0, result.output
    assert "warning: no C compiler found (looked for $CC, cc, gcc, clang and the ziglang " \
           "package): the FMU holds the C sources only" in result.output
    with zipfile.ZipFile(path) as archive:
        assert not [n for n in archive.namelist() if n.startswith("binaries/")]
        archive.extractall(tmp_path / "unzipped")
    sources = tmp_path / "unzipped" / "sources"
    configuration, = read_build_description(str(sources / "buildDescription.xml"))
    listed = [str(sources / f) for s in configuration.sourceFileSets for f in s.sourceFiles]
    binary = tmp_path / "unzipped" / "binaries" / "x86_64-linux" / "SpringMass.so"
    binary.parent.mkdir(parents=True)
    subprocess.run([*compiler, "-shared", "-fPIC", "-O2", "-fvisibility=hidden", *listed,
                    "-lm", "-o", str(binary)], check=True,
                   env={**os.environ, "PATH": path_before})
    run = fmpy.simulate_fmu(str(tmp_path / "unzipped"), stop_time=1.0,
                            relative_tolerance=1e-9, output=["mass.pos[2]"],
                            output_interval=0.01)
    reference = springc.simulate(SEED, stop=1.0, interval=0.01, rtol=1e-9, atol=1e-9,
                                 engine="scipy", backend="python")
    assert np.max(np.abs(run["mass.pos[2]"] - reference["mass.pos[2]"])) < 1e-4


DELAYED = """model Delayed
  Real x(start = 1, fixed = true);
equation
  der(x) = -delay(x, 0.1);
end Delayed;
"""


def test_a_construct_c_cannot_express_is_refused_where_it_is(tmp_path: Path) -> None:
    model = tmp_path / "delayed.mo"
    model.write_text(DELAYED)
    result = CliRunner().invoke(main, ["fmu", str(model), "-o", str(tmp_path / "d.fmu")])
    assert result.exit_code == 1
    assert f"{model}:4:3: error: cannot generate C code for delay(...)" in result.output
    assert not (tmp_path / "d.fmu").exists()


@pytest.mark.parametrize(("target", "message"), [
    ("out.zip", "-o out.zip: the suffix must be one of .fmu (it chooses the format)"),
    ("missing/out.fmu", "-o: cannot write 'missing/out.fmu': the folder"),
])
def test_bad_outputs_are_usage_errors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                      target: str, message: str) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["fmu", SEED, "-o", target])
    assert result.exit_code == 2
    assert message in result.output


def test_the_api_refuses_to_overwrite_an_input_and_a_bad_version(tmp_path: Path) -> None:
    model = tmp_path / "seed.fmu"
    model.write_text(Path(SEED).read_text())
    with pytest.raises(UsageError, match="input") as info:
        springc.export_fmu(str(model), model)
    assert info.value.option == "output"
    with pytest.raises(UsageError, match="--fmi must be 3 or 2, not 4"):
        springc.export_fmu(SEED, tmp_path / "x.fmu", fmi_version=4)


OUTPUTS = """model WithOutputs
  parameter Real k = 2;
  output Real x(start = 1, fixed = true) "decaying state";
  output Real y "twice x";
  Real z;
equation
  der(x) = -k*x;
  y = 2*x;
  z = y + 1;
end WithOutputs;
"""


@pytest.mark.parametrize("version", [3, 2])
def test_the_models_outputs_are_the_fmus_outputs(version: int, tmp_path: Path) -> None:
    model = tmp_path / "outputs.mo"
    model.write_text(OUTPUTS)
    path = tmp_path / "outputs.fmu"
    springc.export_fmu(str(model), path, fmi_version=version)
    assert validate_fmu(str(path)) == []
    description = fmpy.read_model_description(str(path))
    assert {v.name: v.causality for v in description.modelVariables} == {
        "time": "independent", "x": "output", "der(x)": "local", "k": "parameter",
        "y": "output", "z": "local"}
    assert [(o.variable.name, [d.name for d in o.dependencies])
            for o in description.outputs] == [("x", ["x"]), ("y", ["x"])]
    assert sorted(u.variable.name for u in description.initialUnknowns) == ["der(x)", "y"]
    result = fmpy.simulate_fmu(str(path), fmi_type="CoSimulation", stop_time=1.0,
                               relative_tolerance=1e-9)
    assert result.dtype.names == ("time", "x", "y")  # the outputs, recorded by default
    assert result["y"][-1] == pytest.approx(2 * np.exp(-2.0), rel=1e-7)


def test_a_model_whose_states_springc_switches_is_exported_with_a_warning(
        tmp_path: Path) -> None:
    path = tmp_path / "pendulum.fmu"
    result = CliRunner().invoke(main, ["fmu", str(ROOT / "models" / "Scenes.mdl"),
                                       "--model", "Scenes.Pendulum", "-o", str(path), "-q"])
    assert result.exit_code == 0
    assert result.output == (
        "warning: springc switches the states of this model during a run where the choice "
        "made by index reduction turns singular; the FMU keeps the states chosen at export "
        "(x, vx) and fails where springc would switch\n")
    assert path.is_file()


@pytest.mark.parametrize("version", [3, 2])
def test_directional_derivatives_are_the_jacobian_of_the_state_derivatives(
        version: int, tmp_path: Path) -> None:
    """d der(mass.v[2]) / d mass.pos[2] of the seed, through FMI's directional
    derivative, against central differences of the derivative the FMU computes."""
    path = tmp_path / "seed.fmu"
    springc.export_fmu(SEED, path, fmi_version=version)
    flag = "providesDirectionalDerivatives" if version == 3 else \
        "providesDirectionalDerivative"
    assert [e.get(flag) for e in _description(path) if e.tag in (
        "ModelExchange", "CoSimulation")] == ["true", "true"]
    description = fmpy.read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    fmu = fmpy.instantiate_fmu(fmpy.extract(str(path)), description,
                               fmi_type="ModelExchange")
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    get = fmu.getFloat64 if version == 3 else fmu.getReal
    put = fmu.setFloat64 if version == 3 else fmu.setReal
    state, unknown = refs["mass.pos[2]"], refs["der(mass.v[2])"]
    exact = fmu.getDirectionalDerivative([unknown], [state], [1.0])[0]
    start, step = get([state])[0], 1e-6

    def derivative_at(shift: float) -> float:
        put([state], [start + shift])
        return float(get([unknown])[0])

    difference = (derivative_at(step) - derivative_at(-step)) / (2 * step)
    fmu.terminate()
    fmu.freeInstance()
    assert exact == pytest.approx(difference, rel=1e-6)
    assert abs(exact) > 1e3  # the spring's stiffness (k = 1e4) dominates it
