""".ssp archive -> the wiring document and default experiment this package runs.

The archive is checked (no absolute or '..' member names), extracted once into the cache
(``<cache>/ssp/<content hash>``), and its SystemStructure.ssd validated against the SSP 1.0
schema. The supported subset is a flat system of FMU components: each component's FMU must be a
.fmu inside the archive, its ParameterBindings give values by FMU variable name (inline
ParameterValues or an .ssv file in the archive; a binding's prefix is stripped; later bindings
win), and connections join two components without transformation. Anything else (nested
systems, signal dictionaries, parameter mappings, connector transformations, system-level
connectors) is refused with the entry named, never silently dropped. The result goes through
the same checks as a wiring file (`system.load_system`).
"""

import hashlib
import shutil
import zipfile
from pathlib import Path, PurePosixPath
from xml.etree import ElementTree

from aotv_cosim.model.archives import extract_to
from aotv_cosim.errors import InputError
from aotv_cosim.model.fmu_file import check_archive
from aotv_cosim.paths import regular_file
from aotv_cosim.model import ssp_units as units
from aotv_cosim.model.ssp_names import (AOTV_ANNOTATION, OSP_ANNOTATION, SSD_SCHEMA, SSV_SCHEMA, local, q,
                                schema_problems, xml_problem)

SSD = "SystemStructure.ssd"
FMU_TYPE = "application/x-fmu-sharedlibrary"


def extract(path: Path) -> Path:
    """The folder holding the extracted archive `path` (extracted once per distinct content)."""
    from aotv_cosim.fmu.build import cache_dir

    path = Path(path)
    regular_file(path, what=".ssp file")
    if not zipfile.is_zipfile(path):
        raise InputError("not a zip archive", file=path, fix="give an SSP archive (.ssp)")
    check_archive(path)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    folder = cache_dir() / "ssp" / digest
    if folder.is_dir():
        return folder
    return extract_to(path, folder)


def _member(folder: Path, reference: str, *, file, entry, suffix) -> Path:
    """A relative archive path named in the SSD, resolved inside `folder`; InputError otherwise."""
    pure = PurePosixPath(reference)
    if ":" in reference or pure.is_absolute() or ".." in pure.parts or not reference.endswith(suffix):
        raise InputError(f"{reference!r} is not a relative path to a {suffix} file inside the archive",
                         file=file, entry=entry, fix=f"put the {suffix} file in the archive and name it relatively")
    return folder.joinpath(*pure.parts)


def _parse(xml_path: Path, schema_file: str, *, file, entry):
    if not xml_path.is_file():
        raise InputError(f"{xml_path.name} missing from the archive", file=file, entry=entry,
                         fix="give an SSP archive with the files its SSD references")
    xml = xml_path.read_bytes()
    problem = xml_problem(xml)
    if problem:
        raise InputError(f"{xml_path.name} {problem}", file=file, entry=entry,
                         fix="give a well-formed XML file without a DOCTYPE")
    problems = schema_problems(xml, schema_file)
    if problems:
        raise InputError(f"{xml_path.name} violates the SSP 1.0 schema: {problems[0]}", file=file,
                         entry=entry, fix="correct the file so that it validates against " + schema_file)
    return ElementTree.fromstring(xml)


def read_ssp(path):
    """(wiring document, base folder of its FMU paths, SSD root element) of the archive `path`.

    An archive refused here has its extracted folder removed from the cache."""
    path = Path(path)
    folder = extract(path)
    try:
        return _read(path, folder)
    except InputError:
        shutil.rmtree(folder, ignore_errors=True)
        raise


def _read(path, folder):
    root = _parse(folder / SSD, SSD_SCHEMA, file=path, entry=SSD)
    system = root.find(q("ssd:System"))
    entry = f"System '{system.get('name')}'"
    if system.find(q("ssd:Connectors")) is not None:
        _unsupported("system-level connectors", path, entry)
    if system.find(q("ssd:SignalDictionaries")) is not None:
        _unsupported("signal dictionaries", path, entry)
    components = {}
    ssd_units = units.definitions(root.find(q("ssd:Units")))
    for element in system.findall(q("ssd:Elements") + "/*"):
        name = element.get("name")
        if element.tag != q("ssd:Component"):
            _unsupported(f"element {local(element.tag)}", path, f"{entry}.{name}")
        if name in components:
            raise InputError(f"two components are named {name!r}", file=path, entry=f"{entry}.{name}",
                             fix="give each component of the SSD its own name")
        components[name] = _component(element, folder, path, f"{entry}.{name}", ssd_units)
    connections = [_connection(c, path, f"{entry}.Connections[{k}]")
                   for k, c in enumerate(system.findall(q("ssd:Connections") + "/" + q("ssd:Connection")))]
    return {"components": components, "connections": connections}, folder, root


def _unsupported(what, file, entry):
    raise InputError(f"{what} are not supported", file=file, entry=entry,
                     fix="flatten the system to FMU components joined by plain connections")


def _component(element, folder, file, entry, ssd_units):
    if element.get("type", FMU_TYPE) != FMU_TYPE:
        raise InputError(f"component type {element.get('type')!r} is not an FMU", file=file, entry=entry,
                         fix=f"use components of type {FMU_TYPE}")
    fmu = _member(folder, element.get("source"), file=file, entry=f"{entry} source", suffix=".fmu")
    fmu_units = _fmu_units(fmu)
    parameters = {}
    bindings = element.findall(q("ssd:ParameterBindings") + "/" + q("ssd:ParameterBinding"))
    for k, binding in enumerate(bindings):
        parameters.update(_binding(binding, folder, file, f"{entry}.ParameterBindings[{k}]",
                                   ssd_units, fmu_units))
    return {"fmu": fmu.relative_to(folder).as_posix(), "parameters": parameters}


def _fmu_units(fmu: Path):
    """({variable: unit name}, {unit name: definition}) of the FMU `fmu`; empty if unreadable
    (the wiring checks then report the FMU itself)."""
    from fmpy import read_model_description

    try:
        md = read_model_description(str(fmu))
    except Exception:  # fmpy raises many kinds; system.read_fmu reports the file
        return {}, {}
    return ({v.name: v.unit or (v.declaredType.unit if v.declaredType else None) or ""
             for v in md.modelVariables}, units.fmu_definitions(md))


def _binding(binding, folder, file, entry, ssd_units, fmu_units):
    if binding.find(q("ssd:ParameterMapping")) is not None:
        _unsupported("parameter mappings", file, entry)
    if binding.get("sourceBase", "SSD") != "SSD":
        _unsupported("parameter sources inside components", file, entry)
    source = binding.get("source")
    if source:
        ssv = _member(folder, source, file=file, entry=f"{entry} source", suffix=".ssv")
        parameter_set = _parse(ssv, SSV_SCHEMA, file=file, entry=f"{entry} source")
    else:
        parameter_set = binding.find(q("ssd:ParameterValues") + "/" + q("ssv:ParameterSet"))
        if parameter_set is None:
            return {}
    prefix = binding.get("prefix", "")
    ssp_units = {**ssd_units, **units.definitions(parameter_set.find(q("ssv:Units")))}
    variable_units, defined = fmu_units
    values = {}
    for parameter in parameter_set.findall(q("ssv:Parameters") + "/" + q("ssv:Parameter")):
        name = parameter.get("name")
        where = f"{entry} parameter {name}"
        if prefix and name.startswith(prefix):
            name = name[len(prefix):]
        if name in values:
            raise InputError(f"parameter {name!r} is given twice", file=file, entry=where,
                             fix="give each parameter once in a parameter set")
        values[name] = _value(parameter[0], file, where)
        unit = parameter[0].get("unit")
        if unit is not None and local(parameter[0].tag) == "Real" and name in variable_units:
            values[name] = units.to_fmu_unit(values[name], unit, variable_units[name], ssp_units, defined,
                                             file=file, entry=where)
    return values


def _value(node, file, entry):
    kind = local(node.tag)
    text = node.get("value").strip()
    if kind == "Real":
        return float(text)
    if kind == "Integer":
        return int(text)
    if kind == "Boolean":
        return text in ("true", "1")
    if kind == "String":
        return node.get("value")
    raise InputError(f"{kind} parameter values are not supported", file=file, entry=entry,
                     fix="give Real, Integer, Boolean or String values")


def _connection(node, file, entry):
    start, end = node.get("startElement"), node.get("endElement")
    if not start or not end:
        _unsupported("connections to system-level connectors", file, entry)
    for child in node:
        kind = local(child.tag)
        if kind not in ("ConnectionGeometry", "Annotations"):
            _unsupported(f"connection transformations ({kind})", file, entry)
    return f"{start}.{node.get('startConnector')} -> {end}.{node.get('endConnector')}"


def scenario_document(path, step_given=False) -> dict:
    """A scenario document that runs the archive `path` over its default experiment.

    Start and stop come from DefaultExperiment; the step and master algorithm from the
    aotv-cosim annotation, else the step from OSP's FixedStepAlgorithm annotation (algorithm
    Gauss-Seidel). Without a step in the archive, `step_given` (a --step) must be true.
    """
    path = Path(path).resolve()
    _, _, root = read_ssp(path)
    experiment = root.find(q("ssd:DefaultExperiment"))
    if experiment is None or experiment.get("stopTime") is None:
        raise InputError("no DefaultExperiment stopTime", file=path, entry=SSD,
                         fix="set <ssd:DefaultExperiment stopTime=...> in the SSD")
    doc = {"system": str(path), "start": float(experiment.get("startTime", 0.0)),
           "stop": float(experiment.get("stopTime"))}
    for annotation in experiment.findall(q("ssd:Annotations") + "/" + q("ssc:Annotation")):
        if annotation.get("type") == AOTV_ANNOTATION:
            ours = annotation.find(q("aotv:Experiment"))
            entry = f"{SSD} annotation {AOTV_ANNOTATION}"
            if ours is None:
                raise InputError("no aotv:Experiment element", file=path, entry=entry,
                                 fix='give <aotv:Experiment stepSize="..."/> in the annotation, or remove it')
            doc["step"] = _step_size(ours, "stepSize", path, entry)
            doc["algorithm"] = ours.get("algorithm", "gauss-seidel")
            if doc["algorithm"] not in ALGORITHMS:
                raise InputError(f"unknown algorithm {doc['algorithm']!r}", file=path, entry=f"{entry} algorithm",
                                 fix=f"use one of {', '.join(ALGORITHMS)}")
        elif annotation.get("type") == OSP_ANNOTATION and "step" not in doc:
            fixed = annotation.find(q("osp:Algorithm") + "/" + q("osp:FixedStepAlgorithm"))
            if fixed is None:
                raise InputError("no osp:Algorithm/osp:FixedStepAlgorithm element", file=path,
                                 entry=f"{SSD} annotation {OSP_ANNOTATION}",
                                 fix='give <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="..."/>')
            doc["step"] = _step_size(fixed, "baseStepSize", path, f"{SSD} annotation {OSP_ANNOTATION}")
    if "step" not in doc and not step_given:
        raise InputError("no communication step in the archive", file=path, entry=SSD,
                         fix="give --step (s), or an OSP FixedStepAlgorithm annotation in the SSD")
    return doc


ALGORITHMS = ("gauss-seidel", "jacobi")
"""The master algorithms an aotv-cosim experiment annotation may name (scenario schema's enum)."""


def _step_size(node, attribute, file, entry) -> float:
    """The finite number in the step attribute of an annotation element; InputError otherwise."""
    text = node.get(attribute)
    try:
        return float(text)
    except (TypeError, ValueError):
        problem = f"no {attribute}" if text is None else f"{attribute} {text!r} is not a number"
        raise InputError(problem, file=file, entry=f"{entry} {attribute}",
                         fix=f'give {attribute}="0.1" (the communication step in s)') from None
