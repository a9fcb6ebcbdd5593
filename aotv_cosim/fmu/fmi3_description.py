"""The FMI 3.0 modelDescription of an FMU this package builds (`aotv_cosim.fmu.build_fmi3`).

For a pythonfmu class (an Fmi2Slave: this package's AotvSlave and its guidance bases, or a plain
pythonfmu class) the FMI 3.0 description is derived from the FMI 2.0 one the class writes
(`from_fmi2`): the same variables, value references, units, ranges, nominal values, dependencies
and default experiment, in FMI 3.0's form:

- ``ScalarVariable``/``Real`` -> ``Float64``, ``Integer`` -> ``Int32``, ``Boolean``, ``String`` (its
  start as a ``Start`` element), ``Enumeration``; TypeDefinitions' ``SimpleType`` -> ``Float64Type``,
  ``Int32Type``, ``EnumerationType``, ...;
- ``ModelStructure``: ``Outputs``/``InitialUnknowns`` ``Unknown index`` -> ``Output`` and
  ``InitialUnknown`` ``valueReference``, dependencies as value references (FMI 2.0 counts
  variables from 1, FMI 3.0 names value references);
- the independent variable FMI 3.0 requires (`TIME`, unit s) one past the largest value
  reference, served by the FMI 3.0 wrapper (fmi3_lean.c), which applies the same rule;
- capability flags: canGetAndSetFMUState and canSerializeFMUState as in FMI 2.0,
  canHandleVariableCommunicationStepSize true (the slave takes any step), no event mode;
- start values at full precision (`starts`: the values the slave holds after construction; pythonfmu
  writes 16 significant digits, which does not always give the double back).

A pythonfmu3 class writes an FMI 3.0 description itself; `complete` adds what it leaves out:
the independent variable, the capability flags above (pythonfmu3 0.3.4 writes
canHandleVariableCommunicationStepSize from a leftover loop variable), full-precision starts, the
UnitDefinitions of the units its variables name and the class's description (pythonfmu3 sets the
instance's to None).

`finish` drops the generation date and sets the instantiation token, derived from the sources
and the XML as the FMI 2.0 build derives its GUID.
"""

import hashlib
import io
import uuid
from xml.etree import ElementTree
from xml.etree.ElementTree import Element, SubElement

TIME = "time"
"""Name of the independent variable added to a class that declares none."""
TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String", "Enumeration": "Enumeration"}
"""FMI 2.0 variable types -> FMI 3.0 element names."""
XSD_SPECIAL = {"inf": "INF", "-inf": "-INF", "nan": "NaN"}
"""xs:double spellings of the non-finite values Python formats as inf/-inf/nan."""
CO_SIMULATION = ("modelIdentifier", "needsExecutionTool", "canBeInstantiatedOnlyOncePerProcess")
"""CoSimulation attributes FMI 2.0 and 3.0 share by name."""
ROOT_ATTRIBUTES = ("modelName", "description", "author", "version", "copyright", "license", "generationTool",
                   "variableNamingConvention")
"""fmiModelDescription attributes FMI 2.0 and 3.0 share."""
VARIABLE_ATTRIBUTES = ("name", "valueReference", "description", "causality", "variability", "initial")
TYPED_ATTRIBUTES = ("declaredType", "quantity", "unit", "displayUnit", "relativeQuantity", "min", "max", "nominal",
                    "unbounded", "start", "reinit")
"""Attributes of an FMI 2.0 type element carried to the FMI 3.0 variable (``derivative`` is mapped)."""


def from_fmi2(xml: bytes, starts: dict) -> Element:
    """The FMI 3.0 modelDescription (root element, instantiationToken empty) of a slave whose FMI 2.0
    modelDescription is `xml`; `starts` {value reference: value} gives the full-precision start
    values (module docstring)."""
    old = ElementTree.fromstring(xml)
    root = Element("fmiModelDescription", {"fmiVersion": "3.0"})
    for name in ROOT_ATTRIBUTES:
        if (value := old.get(name)) is not None:
            root.set(name, value)
    root.set("instantiationToken", "")
    cs = _child(old, "CoSimulation")
    SubElement(root, "CoSimulation", _co_simulation(cs.get, cs.get("canGetAndSetFMUstate", "false"),
                                                     cs.get("canSerializeFMUstate", "false")))
    variables = _child(old, "ModelVariables").findall("ScalarVariable")
    references = [int(v.attrib["valueReference"]) for v in variables]
    units = old.find("UnitDefinitions")
    units = _copy(units) if units is not None else Element("UnitDefinitions")
    time = _time_variable(references, {v.get("name") for v in variables}, units)
    types = None
    if (definitions := old.find("TypeDefinitions")) is not None:
        types = Element("TypeDefinitions")
        types.extend(_type_definition(simple) for simple in definitions)
    root.append(units)  # never empty: it defines s, the unit of time
    if types is not None:
        root.append(types)
    for element in (old.find("LogCategories"), old.find("DefaultExperiment")):
        if element is not None:
            root.append(_copy(element))
    for category in root.iter("Category"):
        if description := category.get("description"):
            category.set("description", description.replace("fmi2", "fmi3"))
    model_variables = SubElement(root, "ModelVariables")
    model_variables.append(time)
    by_index = {i + 1: vr for i, vr in enumerate(references)}
    model_variables.extend(_variable(var, starts, by_index) for var in variables)
    _model_structure(root, old.find("ModelStructure"), by_index)
    return root


def complete(xml: bytes, starts: dict, can_get_and_set_state: bool, description=None) -> Element:
    """A pythonfmu3 class's FMI 3.0 modelDescription `xml` completed (module docstring), with the
    class's `description` where it has none: root element, instantiationToken empty."""
    root = ElementTree.fromstring(xml)
    root.attrib.pop("generationDateAndTime", None)
    if description and not root.get("description"):
        root.set("description", description)
    root.set("instantiationToken", "")
    cs = _child(root, "CoSimulation")
    flags = _co_simulation(cs.get, "true" if can_get_and_set_state else "false", "false")
    cs.attrib.clear()
    cs.attrib.update(flags)
    model_variables = _child(root, "ModelVariables")
    declared = list(model_variables)
    for var in declared:
        value = starts.get(int(var.attrib["valueReference"]))
        if var.tag == "Float64" and var.get("start") is not None and value is not None:
            var.set("start", _real_text(value))
    units = root.find("UnitDefinitions")
    if units is None:
        units = Element("UnitDefinitions")
        root.insert(list(root).index(cs) + 1, units)
    if not any(var.get("causality") == "independent" for var in declared):
        model_variables.insert(0, _time_variable([int(v.attrib["valueReference"]) for v in declared],
                                                 {v.get("name") for v in declared}, units))
    _define_units(units, {var.get("unit") for var in root.iter() if var.get("unit")})
    if not len(units):
        root.remove(units)
    return root


def finish(root: Element, digest: str) -> bytes:
    """The modelDescription as bytes, its instantiationToken derived from the source hash `digest`
    and the XML (as the FMI 2.0 build's GUID: the same sources give the same token)."""
    root.set("instantiationToken", "")
    ElementTree.indent(root, space="  ")
    body = ElementTree.tostring(root, encoding="unicode")
    token = uuid.UUID(bytes=hashlib.sha256((digest + "fmi3" + body).encode()).digest()[:16], version=5)
    root.set("instantiationToken", "{" + str(token) + "}")
    out = io.BytesIO()
    ElementTree.ElementTree(root).write(out, encoding="UTF-8", xml_declaration=True)
    return out.getvalue() + b"\n"


def start_references(xml: bytes) -> list:
    """Value references of the variables whose start the modelDescription `xml` (FMI 2.0 or 3.0)
    states: those `starts` must give."""
    root = ElementTree.fromstring(xml)
    if root.get("fmiVersion", "").startswith("2"):
        return [int(v.attrib["valueReference"]) for v in root.iter("ScalarVariable")
                if any(child.get("start") is not None for child in v)]
    return [int(v.attrib["valueReference"]) for v in _child(root, "ModelVariables")
            if v.get("start") is not None or v.find("Start") is not None]


def _co_simulation(get, can_get_and_set_state: str, can_serialize_state: str) -> dict:
    flags = {name: get(name) for name in CO_SIMULATION if get(name) is not None}
    flags.update(canGetAndSetFMUState=can_get_and_set_state, canSerializeFMUState=can_serialize_state,
                 canHandleVariableCommunicationStepSize="true", hasEventMode="false")
    return flags


def _child(parent: Element, tag: str) -> Element:
    """The child `tag` of `parent`, which every modelDescription pythonfmu writes has."""
    child = parent.find(tag)
    if child is None:
        raise ValueError(f"the modelDescription has no {tag}")
    return child


def _copy(element: Element) -> Element:
    return ElementTree.fromstring(ElementTree.tostring(element))


def _type_definition(simple: Element) -> Element:
    """FMI 2.0 SimpleType -> FMI 3.0 <Float64Type>, <Int32Type>, <EnumerationType> (Items kept), ..."""
    kind = simple[0]
    node = Element(f"{TYPES[kind.tag]}Type", {"name": simple.attrib["name"]})
    if description := simple.get("description"):
        node.set("description", description)
    node.attrib.update({k: v for k, v in kind.attrib.items() if k != "start"})
    for item in kind.findall("Item"):
        node.append(_copy(item))
    return node


def _time_variable(references: list, names: set, units: Element) -> Element:
    """The independent variable, one past the largest value reference (fmi3_lean.c's rule), its
    unit s added to `units`. ValueError when a variable of `names` is already called `TIME`."""
    if TIME in names:
        raise ValueError(f"a variable is named {TIME!r}, the name of the FMI 3.0 independent variable this "
                         "package adds; rename that variable")
    _define_units(units, {"s"})
    return Element("Float64", {"name": TIME, "valueReference": str(max(references, default=-1) + 1),
                               "description": "Simulation time", "causality": "independent",
                               "variability": "continuous", "unit": "s"})


def _define_units(units: Element, names: set) -> None:
    """Add to `units` a Unit for each SI unit string of `names` it lacks (BaseUnit exponents from
    `aotv_cosim.fmu.slave.unit_exponents`); a unit that is not SI is left undefined (validation
    then names it)."""
    from aotv_cosim.fmu.slave import unit_exponents

    defined = {unit.get("name") for unit in units.findall("Unit")}
    for name in sorted(names - defined):
        try:
            exponents = unit_exponents(name)
        except ValueError:
            continue
        SubElement(SubElement(units, "Unit", name=name), "BaseUnit", {k: str(v) for k, v in exponents.items()})
    units[:] = sorted(units, key=lambda unit: unit.attrib["name"])


def _variable(var: Element, starts: dict, by_index: dict) -> Element:
    """One FMI 2.0 ScalarVariable as its FMI 3.0 typed variable."""
    typed = next(child for child in var if child.tag in TYPES)
    node = Element(TYPES[typed.tag], {k: v for k in VARIABLE_ATTRIBUTES if (v := var.get(k)) is not None})
    if "variability" not in node.attrib:
        node.set("variability", "continuous" if typed.tag == "Real" else "discrete")
    for name in TYPED_ATTRIBUTES:
        if (value := typed.get(name)) is not None:
            node.set(name, value)
    if (derivative := typed.get("derivative")) is not None:
        node.set("derivative", str(by_index[int(derivative)]))
    vr = int(var.attrib["valueReference"])
    if typed.get("start") is not None and vr in starts:
        node.set("start", _start_text(typed.tag, starts[vr]))
    if typed.tag == "String" and node.get("start") is not None:
        SubElement(node, "Start", value=node.attrib.pop("start"))
    return node


def _start_text(kind: str, value) -> str:
    if kind == "Real":
        return _real_text(value)
    if kind == "Boolean":
        return "true" if value else "false"
    if kind in ("Integer", "Enumeration"):
        return str(int(value))
    return str(value)


def _real_text(value) -> str:
    """A double as xs:double text that reads back to the same double."""
    text = repr(float(value))
    return XSD_SPECIAL.get(text, text)


def _model_structure(root: Element, old: Element | None, by_index: dict) -> None:
    """FMI 2.0 Outputs/Derivatives/InitialUnknowns (indices) -> FMI 3.0 Output/ContinuousStateDerivative/
    InitialUnknown (value references)."""
    structure = SubElement(root, "ModelStructure")
    if old is None:
        return
    for group, tag in (("Outputs", "Output"), ("Derivatives", "ContinuousStateDerivative"),
                       ("InitialUnknowns", "InitialUnknown")):
        for unknown in old.findall(f"{group}/Unknown"):
            node = SubElement(structure, tag, valueReference=str(by_index[int(unknown.attrib["index"])]))
            if (dependencies := unknown.get("dependencies")) is not None:
                node.set("dependencies", " ".join(str(by_index[int(i)]) for i in dependencies.split()))
            if (kind := unknown.get("dependenciesKind")) is not None:
                node.set("dependenciesKind", kind)
