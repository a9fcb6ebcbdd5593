"""Scenario -> .ssp archive: FMUs, SystemStructure.ssd, one .ssv per component, default experiment.

The SSD lists every component with a connector for each of its FMU's parameters, connected
inputs and outputs (kind = causality, type and SI unit, description), the units' SI base-unit
exponents,
the connections, a ParameterBinding per component that references its values in
``resources/<component>.ssv`` (the wiring's values with the scenario's overrides applied; every
SSV names its ParameterSet `PARAMETER_SET`, so that an engine which applies one named set, such as
Ecos with ``--parameterSet scenario``, applies every component's values), and
the default experiment: start and stop as attributes (a stop the system reaches, see
`experiment`), the communication step in the OSP
annotation libcosim reads (``osp:FixedStepAlgorithm baseStepSize``) and, with the master
algorithm, in an aotv-cosim annotation. Both XML files are checked against the SSP 1.0 schemas
FMPy ships. The archive is reproducible: members in sorted order with a fixed date, no
generation time, so the same scenario and FMUs give the same bytes.

An input left unconnected (given a value in the wiring) gets its value from the parameter
binding but no connector: FMPy 0.3's SSP simulator writes every input connector each step,
with 0 when unconnected, and wires an unconnected input connector to the source of the
connection listed before it; SSP allows bindings to name FMU variables without connectors.
"""

import errno
import io
import os
import zipfile
from pathlib import Path
from xml.etree import ElementTree
from xml.etree.ElementTree import Element, SubElement

from aotv_cosim import __version__
from aotv_cosim.errors import BuildError, InputError
from aotv_cosim.fmu.build import write_reproducible_zip
from aotv_cosim.ssp.experiment import reachable_stop
from aotv_cosim.model.ssp_names import (AOTV_ANNOTATION, OSP_ANNOTATION, SSD_SCHEMA, SSV_SCHEMA, q,
                                schema_problems)

KINDS = ("parameter", "input", "output")
"""FMI 2.0 causalities exposed as connectors (SSP requires kind == causality for FMI 2.0)."""
TYPES = {"Real": "ssc:Real", "Integer": "ssc:Integer", "Boolean": "ssc:Boolean", "String": "ssc:String"}
BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
PARAMETER_SET = "scenario"
"""Name of the ParameterSet of every exported SSV (one name for the whole system)."""


def export_ssp(scenario, out, fmi_version=2) -> Path:
    """Write `scenario` (a loaded Scenario) as the SSP archive `out`; returns its path.

    fmi_version 3: this package's FMUs (a name of fmus_src or a .py source in the wiring) go into
    the archive as their FMI 3.0 builds (`aotv_cosim.fmu.build_fmi3`: the same variables, the same
    outputs); an .fmu file is copied as it is."""
    out = Path(out)
    system = scenario.system
    sources, fmu_files = _fmu_members(system, fmi_version)
    members = {name: path.read_bytes() for name, path in fmu_files.items()}
    ssv_sources = {}
    for comp in system.components.values():
        if comp.parameters:
            member = f"resources/{comp.name}.ssv"
            members[member] = _checked(_ssv(comp), SSV_SCHEMA, member)
            ssv_sources[comp.name] = member
    members["SystemStructure.ssd"] = _checked(_ssd(scenario, sources, ssv_sources), SSD_SCHEMA,
                                              "SystemStructure.ssd")
    _write_atomically(out, members)
    return out


def _write_atomically(out: Path, members: dict) -> None:
    """Write the archive to a temporary file beside `out`, then rename it over `out`: a failed
    or interrupted write leaves no truncated archive (and an existing `out` as it was). A folder
    that cannot take it (missing and not creatable, read-only, full) is an InputError."""
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        if out.is_dir():
            raise IsADirectoryError(errno.EISDIR, "a folder is in the way", str(out))
        write_reproducible_zip(tmp, members)
        os.replace(tmp, out)
    except OSError as exc:
        raise InputError(f"cannot write the archive: {exc.strerror or exc}", file=out, entry="-o",
                         fix="free space on that disk, or choose a writable -o") from None
    finally:
        tmp.unlink(missing_ok=True)


def _fmu_members(system, fmi_version=2):
    """({component: archive path of its FMU}, {archive path: FMU file}); one file per distinct FMU."""
    sources, files, by_guid = {}, {}, {}
    for comp in system.components.values():
        fmu = comp.fmu
        if fmu.guid not in by_guid:
            member = f"resources/{fmu.model_identifier}.fmu"
            if member in files:  # two different FMUs with one model identifier
                member = f"resources/{fmu.model_identifier}_{comp.name}.fmu"
            by_guid[fmu.guid] = member
            files[member] = _fmu_file(system, comp, fmi_version)
        sources[comp.name] = by_guid[fmu.guid]
    return sources, files


def _fmu_file(system, comp, fmi_version):
    """The file of the component's FMU: for FMI 3.0, the FMI 3.0 build of this package's FMU."""
    ref = comp.fmu_ref
    if fmi_version == 2 or ref.endswith(".fmu"):
        return comp.fmu.path
    from aotv_cosim.fmu.build import ensure_fmu, is_source_path

    return ensure_fmu(system.path.parent / ref if is_source_path(ref) else ref, fmi_version=fmi_version)


def _checked(root, schema_file, member) -> bytes:
    xml = _serialize(root)
    problems = schema_problems(xml, schema_file)
    if problems:
        raise BuildError(f"{member} violates {schema_file}: " + " | ".join(problems[:5]),
                         fix="report this as a bug of the SSP exporter")
    return xml


def _serialize(root) -> bytes:
    ElementTree.indent(root, space="  ")
    buffer = io.BytesIO()
    ElementTree.ElementTree(root).write(buffer, encoding="UTF-8", xml_declaration=True)
    return buffer.getvalue() + b"\n"


def _ssd(scenario, sources, ssv_sources):
    system = scenario.system
    root = Element(q("ssd:SystemStructureDescription"),
                   {"version": "1.0", "name": scenario.path.stem,
                    "generationTool": f"aotv-cosim {__version__}"})
    if scenario.description:
        root.set("description", scenario.description)
    top = SubElement(root, q("ssd:System"), {"name": system.path.stem})
    elements = SubElement(top, q("ssd:Elements"))
    units = {}
    for comp in system.components.values():
        connected = {c.input for c in system.connections if c.target == comp.name}
        _component(elements, comp, sources[comp.name], ssv_sources.get(comp.name), units, connected)
    if system.connections:
        connections = SubElement(top, q("ssd:Connections"))
        for c in system.connections:
            if c.as_type:  # SSP 1.0 has no conversion on a connection: a plain one is a type mismatch
                raise InputError(f"the connection {c} converts {c.as_type}, which an SSP connection cannot "
                                 "express", file=system.path, entry="connections",
                                 fix="export a system whose connections join variables of one type")
            SubElement(connections, q("ssd:Connection"),
                       {"startElement": c.source, "startConnector": c.output,
                        "endElement": c.target, "endConnector": c.input})
    if units:
        unit_list = SubElement(root, q("ssd:Units"))
        for name in sorted(units):
            unit = SubElement(unit_list, q("ssc:Unit"), {"name": name})
            SubElement(unit, q("ssc:BaseUnit"), units[name])
    _default_experiment(root, scenario)
    return root


def _component(elements, comp, source, ssv_source, units, connected):
    node = SubElement(elements, q("ssd:Component"),
                      {"name": comp.name, "type": "application/x-fmu-sharedlibrary", "source": source})
    defined = _unit_exponents(comp.fmu.model_description)
    connectors = SubElement(node, q("ssd:Connectors"))
    for var in comp.fmu.variables.values():
        if var.causality not in KINDS or (var.causality == "input" and var.name not in connected):
            continue
        if var.type not in TYPES:
            raise InputError(f"{comp.name}.{var.name} is of type {var.type}, which SSP tools cannot connect",
                             file=comp.fmu.path, fix="use Real, Integer, Boolean or String variables")
        attributes = {"name": var.name, "kind": var.causality}
        if var.description:
            attributes["description"] = var.description
        connector = SubElement(connectors, q("ssd:Connector"), attributes)
        type_node = SubElement(connector, q(TYPES[var.type]))
        if var.type == "Real" and var.unit:
            type_node.set("unit", var.unit)
            units[var.unit] = defined.get(var.unit, {})
    if ssv_source:
        bindings = SubElement(node, q("ssd:ParameterBindings"))
        SubElement(bindings, q("ssd:ParameterBinding"),
                   {"type": "application/x-ssp-parameter-set", "source": ssv_source})


def _unit_exponents(model_description):
    """{unit name: {base unit: exponent as text}} from an FMU's UnitDefinitions (non-zero only)."""
    exponents = {}
    for unit in model_description.unitDefinitions:
        base = unit.baseUnit
        exponents[unit.name] = {b: str(getattr(base, b)) for b in BASE_UNITS
                                if base is not None and getattr(base, b)}
        if base is not None and base.factor != 1.0:
            exponents[unit.name]["factor"] = repr(base.factor)
        if base is not None and base.offset != 0.0:
            exponents[unit.name]["offset"] = repr(base.offset)
    return exponents


def _ssv(comp):
    """The component's values as an SSV ParameterSet (names are the FMU's variable names)."""
    root = Element(q("ssv:ParameterSet"), {"version": "1.0", "name": PARAMETER_SET})
    parameters = SubElement(root, q("ssv:Parameters"))
    units = {}
    defined = _unit_exponents(comp.fmu.model_description)
    for name, value in comp.parameters.items():
        var = comp.fmu.variables[name]
        node = SubElement(SubElement(parameters, q("ssv:Parameter"), {"name": name}),
                          q(f"ssv:{var.type}"), {"value": format_value(var.type, value)})
        if var.type == "Real" and var.unit:
            node.set("unit", var.unit)
            units[var.unit] = defined.get(var.unit, {})
    if units:
        unit_list = SubElement(root, q("ssv:Units"))
        for name in sorted(units):
            SubElement(SubElement(unit_list, q("ssc:Unit"), {"name": name}), q("ssc:BaseUnit"), units[name])
    return root


def default_experiment(ssp) -> tuple:
    """(start s, stop s, step s) of the default experiment of an archive written by `export_ssp`."""
    with zipfile.ZipFile(ssp) as archive:
        root = ElementTree.fromstring(archive.read("SystemStructure.ssd"))
    experiment = root.find(q("ssd:DefaultExperiment"))
    step = experiment.find(".//" + q("osp:FixedStepAlgorithm")).get("baseStepSize")
    return float(experiment.get("startTime")), float(experiment.get("stopTime")), float(step)


def format_value(kind: str, value) -> str:
    """An XML attribute spelling of a value of FMI type `kind` that reads back exactly."""
    if kind == "Real":
        return repr(float(value))
    if kind == "Integer":
        return str(int(value))
    if kind == "Boolean":
        return "true" if value else "false"
    return str(value)


def _default_experiment(root, scenario):
    """Start, a stop the system reaches (`experiment.reachable_stop`), step and algorithm."""
    experiment = SubElement(root, q("ssd:DefaultExperiment"),
                            {"startTime": repr(scenario.start), "stopTime": repr(reachable_stop(scenario))})
    annotations = SubElement(experiment, q("ssd:Annotations"))
    osp = SubElement(annotations, q("ssc:Annotation"), {"type": OSP_ANNOTATION})
    algorithm = SubElement(osp, q("osp:Algorithm"))
    SubElement(algorithm, q("osp:FixedStepAlgorithm"), {"baseStepSize": repr(scenario.step)})
    aotv = SubElement(annotations, q("ssc:Annotation"), {"type": AOTV_ANNOTATION})
    SubElement(aotv, q("aotv:Experiment"), {"stepSize": repr(scenario.step), "algorithm": scenario.algorithm})
