"""An FMU's interface -> ``modelDescription.xml`` (FMI 3.0 or FMI 2.0) and, for FMI 3.0,
``sources/buildDescription.xml``.

The unit definitions give every unit its SI base-unit exponents and factor (from
:mod:`springc.units`); the default experiment is the model's ``experiment``
annotation; the model structure lists outputs, state derivatives, initial unknowns and
event indicators with the dependencies of :mod:`.variables`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass

from ..ir import flat
from ..units import UnitSyntaxError, parse_unit
from .variables import FmuInterface, FmuVariable

GENERATION_TOOL = "springc"
BASE_ATTRIBUTES = ("kg", "m", "s", "A", "K", "mol", "cd")


@dataclass(frozen=True)
class Header:
    """What the root element and the interface elements say of the model."""

    model_name: str
    identifier: str
    token: str
    description: str
    experiment: flat.Experiment
    version: str  # the springc version
    directional: bool = False  # the model's Jacobian in C: directional derivatives


def _flag(value: bool) -> str:
    return "true" if value else "false"


def _number(value: float) -> str:
    return repr(float(value))


def _unit_definitions(variables: Sequence[FmuVariable]) -> ET.Element | None:
    names = sorted({v.unit for v in variables if v.unit})
    if not names:
        return None
    root = ET.Element("UnitDefinitions")
    for name in names:
        unit = ET.SubElement(root, "Unit", name=name)
        try:
            parsed = parse_unit(name)
        except UnitSyntaxError:
            parsed = None
        if parsed is None or any(e.denominator != 1 for e in parsed.exponents):
            continue
        base = {b: str(int(e)) for b, e in zip(BASE_ATTRIBUTES, parsed.exponents) if e}
        if parsed.scale != 1.0:
            base["factor"] = _number(parsed.scale)
        ET.SubElement(unit, "BaseUnit", base)
    return root


def _experiment(experiment: flat.Experiment) -> ET.Element | None:
    values = {"startTime": experiment.start, "stopTime": experiment.stop,
              "tolerance": experiment.tolerance, "stepSize": experiment.interval}
    given = {k: _number(v) for k, v in values.items() if v is not None}
    return ET.Element("DefaultExperiment", given) if given else None


def _variable_attributes(v: FmuVariable) -> dict[str, str]:
    attributes = {"name": v.name, "valueReference": str(v.reference)}
    if v.description:
        attributes["description"] = v.description
    attributes["causality"] = v.causality
    attributes["variability"] = v.variability
    if v.initial:
        attributes["initial"] = v.initial
    return attributes


def _start_text(v: FmuVariable) -> str | None:
    if v.start is None or v.initial not in ("exact", "approx"):
        return None
    if v.type == "Boolean":
        return "true" if v.start else "false"
    if v.type == "Integer":
        return str(int(v.start))
    return _number(v.start)


FMI3_TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}


def model_description_3(header: Header, face: FmuInterface) -> str:
    """modelDescription.xml of an FMI 3.0 FMU (Model Exchange and Co-Simulation)."""
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": header.model_name,
        "instantiationToken": header.token, "description": header.description,
        "generationTool": f"{GENERATION_TOOL} {header.version}",
        "variableNamingConvention": "structured"})
    if not header.description:
        del root.attrib["description"]
    common = {"modelIdentifier": header.identifier, "canGetAndSetFMUState": "false",
              "canSerializeFMUState": "false",
              "providesDirectionalDerivatives": _flag(header.directional)}
    ET.SubElement(root, "ModelExchange", common)
    ET.SubElement(root, "CoSimulation", {**common,
                                         "canHandleVariableCommunicationStepSize": "true",
                                         "hasEventMode": "false"})
    _append(root, _unit_definitions(face.variables))
    _append(root, _experiment(header.experiment))
    variables = ET.SubElement(root, "ModelVariables")
    for v in face.variables:
        attributes = _variable_attributes(v)
        if v.derivative_of is not None:
            attributes["derivative"] = str(v.derivative_of)
        start = _start_text(v)
        if start is not None:
            attributes["start"] = start
        if v.unit and v.type == "Real":
            attributes["unit"] = v.unit
        ET.SubElement(variables, FMI3_TYPES[v.type], attributes)
    structure = ET.SubElement(root, "ModelStructure")
    for tag, refs in (("Output", face.outputs), ("ContinuousStateDerivative",
                                                 face.derivatives)):
        for ref in refs:
            ET.SubElement(structure, tag, valueReference=str(ref),
                          dependencies=" ".join(map(str, face.dependencies[ref])))
    for ref in face.initial_unknowns:
        ET.SubElement(structure, "InitialUnknown", valueReference=str(ref))
    for ref in face.indicator_references:
        ET.SubElement(structure, "EventIndicator", valueReference=str(ref))
    return _text(root)


FMI2_START_TYPES = {"Real": "Real", "Integer": "Integer", "Boolean": "Boolean"}


def model_description_2(header: Header, face: FmuInterface) -> str:
    """modelDescription.xml of an FMI 2.0 FMU (Model Exchange and Co-Simulation)."""
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": header.model_name, "guid": header.token,
        "description": header.description,
        "generationTool": f"{GENERATION_TOOL} {header.version}",
        "variableNamingConvention": "structured",
        "numberOfEventIndicators": str(len(face.indicator_references))})
    if not header.description:
        del root.attrib["description"]
    common = {"modelIdentifier": header.identifier, "canGetAndSetFMUstate": "false",
              "canSerializeFMUstate": "false",
              "providesDirectionalDerivative": _flag(header.directional)}
    ET.SubElement(root, "ModelExchange", common)
    ET.SubElement(root, "CoSimulation", {**common,
                                         "canHandleVariableCommunicationStepSize": "true"})
    _append(root, _unit_definitions(face.variables))
    _append(root, _experiment(header.experiment))
    variables = ET.SubElement(root, "ModelVariables")
    index = {v.reference: i + 1 for i, v in enumerate(face.variables)}
    for v in face.variables:
        scalar = ET.SubElement(variables, "ScalarVariable", _variable_attributes(v))
        typed: dict[str, str] = {}
        start = _start_text(v)
        if start is not None:
            typed["start"] = start
        if v.unit and v.type == "Real":
            typed["unit"] = v.unit
        if v.derivative_of is not None:
            typed["derivative"] = str(index[v.derivative_of])
        ET.SubElement(scalar, FMI2_START_TYPES[v.type], typed)
    structure = ET.SubElement(root, "ModelStructure")
    for tag, refs in (("Outputs", face.outputs), ("Derivatives", face.derivatives)):
        if refs:
            group = ET.SubElement(structure, tag)
            for ref in refs:
                ET.SubElement(group, "Unknown", index=str(index[ref]), dependencies=" ".join(
                    str(index[d]) for d in face.dependencies[ref]))
    if face.initial_unknowns:
        group = ET.SubElement(structure, "InitialUnknowns")
        for ref in sorted(face.initial_unknowns, key=index.__getitem__):
            ET.SubElement(group, "Unknown", index=str(index[ref]))
    return _text(root)


def build_description(identifier: str, sources: Sequence[str]) -> str:
    """sources/buildDescription.xml (FMI 3.0, section 2.5.1): one configuration that
    compiles ``sources`` as C99 and links the math library."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    configuration = ET.SubElement(root, "BuildConfiguration", modelIdentifier=identifier)
    source_set = ET.SubElement(configuration, "SourceFileSet", language="C99")
    for name in sources:
        ET.SubElement(source_set, "SourceFile", name=name)
    ET.SubElement(configuration, "Library", name="m")
    return _text(root)


def _append(parent: ET.Element, child: ET.Element | None) -> None:
    if child is not None:
        parent.append(child)


def _text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(
        root, encoding="unicode") + "\n"
