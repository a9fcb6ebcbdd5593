"""Base class of every FMU in ``fmus_src``: a thin pythonfmu adapter with SI units declared.

pythonfmu's own modelDescription lacks units, ``InitialUnknowns`` and output dependencies, so
`fmpy validate` fails on it and no tool can tell which outputs feed through from inputs. This
class declares each variable with its unit, description and (for outputs) the inputs it depends
on at the same instant, and writes them into the modelDescription it generates at build time:
``UnitDefinitions`` in SI base units, ``<Real unit=...>``, ``ModelStructure/Outputs`` with exact
``dependencies`` (empty when an output depends only on the FMU's state) and ``InitialUnknowns``.
The master reads those dependencies to order components and to reject algebraic loops.

get_real/set_real are overridden with precomputed getter/setter tables: the FMI call floor of a
Python FMU is dominated by this per-call Python work.

This module is bundled into every FMU (``aotv_cosim.fmu.build.RUNTIME``): it may import only pythonfmu,
the standard library and other bundled modules.
"""

from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real

# SI base-unit exponents of every unit used at an FMU interface (FMI 2.0 BaseUnit attributes).
UNIT_EXPONENTS = {
    "1": {},
    "m": {"m": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s2": {"m": 1, "s": -2},
    "m/s3": {"m": 1, "s": -3},
    "m2/s2": {"m": 2, "s": -2},
    "m2/s3": {"m": 2, "s": -3},
    "m3/s2": {"m": 3, "s": -2},
    "s": {"s": 1},
    "rad": {"rad": 1},
    "rad/s": {"rad": 1, "s": -1},
    "kg/m3": {"kg": 1, "m": -3},
    "kg/m2": {"kg": 1, "m": -2},
    "m2/kg": {"kg": -1, "m": 2},
    "Pa": {"kg": 1, "m": -1, "s": -2},
    "W/m2": {"kg": 1, "s": -3},
    "kg/(s.m)": {"kg": 1, "m": -1, "s": -1},
    "1/m": {"m": -1},
    "1/rad": {"rad": -1},
    "1/rad2": {"rad": -2},
    "m2": {"m": 2},
    "kg": {"kg": 1},
    "1/s": {"s": -1},
    "1/s2": {"s": -2},
    "N.m": {"kg": 1, "m": 2, "s": -2},
}

XSD_SPECIAL = {"inf": "INF", "-inf": "-INF", "nan": "NaN"}
"""xs:double spellings of the non-finite start values Python formats as inf/-inf/nan."""


class AotvSlave(Fmi2Slave):
    """pythonfmu slave with declared units, dependencies and a fast value table.

    Subclasses call `parameter`, `input` and `output` in ``__init__`` and implement ``do_step``.
    `default_step` (s) sets the DefaultExperiment step size of the FMU.
    """

    default_step = 0.1
    default_stop = 300.0

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._units = {}
        self._output_deps = {}
        self._initial_deps = {}
        self._getters = {}
        self._setters = {}
        self.start_time = 0.0

    # ---- declarations -------------------------------------------------------------------
    def parameter(self, name, start, unit, description, tunable=False):
        """Declare a Real parameter `name` (attribute of the same name) in `unit`."""
        setattr(self, name, float(start))
        variability = Fmi2Variability.tunable if tunable else Fmi2Variability.fixed
        self._register(Real(name, causality=Fmi2Causality.parameter, variability=variability,
                            description=description), unit)

    def integer_parameter(self, name, start, description):
        """Declare an Integer parameter (a mode switch or a seed)."""
        setattr(self, name, int(start))
        self.register_variable(Integer(name, causality=Fmi2Causality.parameter,
                                       variability=Fmi2Variability.fixed,
                                       description=description))

    def input(self, name, start, unit, description):
        """Declare a continuous Real input `name` (attribute of the same name) in `unit`."""
        setattr(self, name, float(start))
        self._register(Real(name, causality=Fmi2Causality.input, description=description), unit)

    def output(self, name, unit, description, getter, depends_on=(), initial_depends_on=None):
        """Declare a continuous Real output computed by `getter()` when it is read.

        depends_on: the inputs this output depends on at the same instant while stepping (direct
        feedthrough); initial_depends_on: the same in initialization mode (default depends_on).
        """
        var = Real(name, causality=Fmi2Causality.output, description=description, getter=getter)
        self._register(var, unit)
        self._output_deps[name] = tuple(depends_on)
        self._initial_deps[name] = tuple(depends_on if initial_depends_on is None
                                         else initial_depends_on)

    def _register(self, var, unit):
        if unit not in UNIT_EXPONENTS:
            raise ValueError(f"unit {unit!r} of {var.name} is not in UNIT_EXPONENTS")
        self.register_variable(var)
        self._units[var.name] = unit
        self._getters[var.value_reference] = var.getter
        if var.setter is not None:
            self._setters[var.value_reference] = var.setter

    # ---- FMI calls ------------------------------------------------------------------------
    def setup_experiment(self, start_time, stop_time, tolerance):
        self.start_time = float(start_time)

    def get_real(self, vrs):
        getters = self._getters
        return [getters[vr]() for vr in vrs]

    def set_real(self, vrs, values):
        setters = self._setters
        for vr, value in zip(vrs, values):
            setters[vr](value)

    # ---- model description ------------------------------------------------------------------
    def to_xml(self, model_options=dict()):
        """pythonfmu's modelDescription plus units, dependencies, InitialUnknowns, DefaultExperiment."""
        root = super().to_xml(model_options)
        index = {v.name: i + 1 for i, v in enumerate(self.vars.values())}
        for node in root.find("ModelVariables"):
            unit = self._units.get(node.get("name"))
            real = node.find("Real")
            if unit:
                real.set("unit", unit)
            if real is not None and real.get("start") in XSD_SPECIAL:
                real.set("start", XSD_SPECIAL[real.get("start")])
        position = list(root).index(root.find("CoSimulation")) + 1
        root.insert(position, self._unit_definitions())
        if root.find("DefaultExperiment") is None:
            experiment = Element("DefaultExperiment", startTime="0", stopTime=repr(self.default_stop),
                                 stepSize=repr(self.default_step))
            root.insert(list(root).index(root.find("ModelVariables")), experiment)
        parameters = [v.name for v in self.vars.values() if v.causality == Fmi2Causality.parameter]
        structure = root.find("ModelStructure")
        for child in list(structure):
            structure.remove(child)
        if self._output_deps:
            outputs = SubElement(structure, "Outputs")
            initial = SubElement(structure, "InitialUnknowns")
            for name in self._output_deps:
                deps = sorted(index[d] for d in self._output_deps[name])
                SubElement(outputs, "Unknown", index=str(index[name]),
                           dependencies=" ".join(map(str, deps)))
                init = sorted(index[d] for d in self._initial_deps[name] + tuple(parameters))
                SubElement(initial, "Unknown", index=str(index[name]),
                           dependencies=" ".join(map(str, init)))
        return root

    def _unit_definitions(self):
        definitions = Element("UnitDefinitions")
        for unit in sorted(set(self._units.values())):
            node = SubElement(definitions, "Unit", name=unit)
            SubElement(node, "BaseUnit", {k: str(v) for k, v in UNIT_EXPONENTS[unit].items()})
        return definitions
