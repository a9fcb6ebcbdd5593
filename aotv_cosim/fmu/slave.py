"""Base class of every FMU in ``fmus_src``: a thin pythonfmu adapter with SI units declared.

pythonfmu's own modelDescription lacks units, ``InitialUnknowns`` and output dependencies, so
`fmpy validate` fails on it and no tool can tell which outputs feed through from inputs. This
class declares each variable with its unit, description and (for outputs) the inputs it depends
on at the same instant, and writes them into the modelDescription it generates at build time:
``UnitDefinitions`` in SI base units, ``<Real unit=...>``, ``ModelStructure/Outputs`` with exact
``dependencies`` (empty when an output depends only on the FMU's state) and ``InitialUnknowns``.
The master reads those dependencies to order components and to reject algebraic loops.

get_real/set_real are overridden with precomputed tables: parameters and inputs are read and
written in the instance dict directly (pythonfmu's own path makes two Python calls per value), and
input ranges are checked once after a set, not per read: the FMI call floor of a Python FMU is
dominated by this per-call Python work. `revision` counts the sets, so an adapter may cache a
value computed from the inputs until the next set or step.

Physical ranges: every declaration may give `min`/`max` (SI, inclusive), written into the
modelDescription; the master validates given values against them and stops a run whose output
leaves its range (a vehicle's h below 0: impact). A tool may hold every input at 0 before its first
exchange, outside the range of e.g. a measured speed (min `POSITIVE`): while an input lies outside
its declared range, the outputs that depend on it (step or initialization dependencies) read 0,
undefined rather than a failed call, until the tool gives a value in range.

This module is bundled into every FMU (``aotv_cosim.fmu.build.RUNTIME``): it may import only
pythonfmu, the standard library and other bundled modules.
"""

import copy
import sys
from functools import partial
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Status

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
    "rad/s2": {"rad": 1, "s": -2},
    "kg/m3": {"kg": 1, "m": -3},
    "kg/m2": {"kg": 1, "m": -2},
    "m2/kg": {"kg": -1, "m": 2},
    "Pa": {"kg": 1, "m": -1, "s": -2},
    "W/m2": {"kg": 1, "s": -3},
    "J/m2": {"kg": 1, "s": -2},
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

POSITIVE = sys.float_info.min
"""Declared `min` of a quantity that must be strictly positive (a speed, a mass, an area, a
radius): the smallest positive normal double, 2.2e-308."""

XSD_SPECIAL = {"inf": "INF", "-inf": "-INF", "nan": "NaN"}
"""xs:double spellings of the non-finite start values Python formats as inf/-inf/nan."""


_NOT_STATE = frozenset({
    "vars", "log_queue", "instance_name", "resources", "visible", "guid", "_units", "_output_deps",
    "_initial_deps", "_getters", "_names", "_ranges", "_input_ranges", "_ranged_vrs"})
"""Instance attributes that are declarations or pythonfmu's own (its C++ side keeps a reference to
`log_queue`): never part of a saved FMU state."""


_SCALARS = frozenset({float, int, bool, str, bytes, type(None), frozenset})
"""Immutable types kept as they are, checked first (most of an adapter's attributes)."""


def _copied(value):
    """value, copied one level when it holds state an adapter changes in place: a list, dict,
    set or numpy array; an object whose class sets `MUTABLE_STATE` (an adaptive law whose
    estimates it replaces: copy.copy); a tuple holding either (copied element-wise)."""
    kind = type(value)
    if kind in _SCALARS:
        return value
    if kind in (list, dict, set) or kind.__name__ == "ndarray":
        return value.copy()
    if isinstance(value, tuple):
        return tuple(map(_copied, value))
    if getattr(kind, "MUTABLE_STATE", False):
        return copy.copy(value)
    return value


def _copy_mutable(source, target):
    """target[name] = _copied(value) for each value of `source` that is not of a _SCALARS type
    (the state's scalars are shared: a snapshot costs a dict copy and a few list copies)."""
    for name, value in source.items():
        if type(value) not in _SCALARS:
            target[name] = _copied(value)


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
        self._names = {}
        self._ranges = {}
        self._input_ranges = {}
        self._ranged_vrs = set()
        self._inputs_checked = True
        self._outside = ()
        self._undefined = frozenset()
        self.revision = 0  # not `version`: pythonfmu writes that attribute into the modelDescription
        self.start_time = 0.0

    # ---- declarations -------------------------------------------------------------------
    def parameter(self, name, start, unit, description, tunable=False, min=None, max=None):
        """Declare a Real parameter `name` (attribute of the same name) in `unit`, optionally
        within [min, max] (SI, inclusive)."""
        setattr(self, name, float(start))
        variability = Fmi2Variability.tunable if tunable else Fmi2Variability.fixed
        self._register(Real(name, causality=Fmi2Causality.parameter, variability=variability,
                            description=description), unit)
        self._declare_range(name, min, max)

    def integer_parameter(self, name, start, description, min=None, max=None):
        """Declare an Integer parameter (a mode switch or a seed); min/max: its allowed codes."""
        setattr(self, name, int(start))
        self.register_variable(Integer(name, causality=Fmi2Causality.parameter,
                                       variability=Fmi2Variability.fixed,
                                       description=description))
        self._declare_range(name, min, max)

    def input(self, name, start, unit, description, min=None, max=None):
        """Declare a continuous Real input `name` (attribute of the same name) in `unit`; outputs
        depending on it read 0 while it lies outside [min, max] (module docstring)."""
        setattr(self, name, float(start))
        var = self._register(Real(name, causality=Fmi2Causality.input, description=description), unit)
        self._declare_range(name, min, max)
        if min is not None or max is not None:
            self._input_ranges[name] = self._ranges[name]
            self._ranged_vrs.add(var.value_reference)
            self._inputs_checked = False

    def output(self, name, unit, description, getter, depends_on=(), initial_depends_on=None,
               min=None, max=None):
        """Declare a continuous Real output computed by `getter()` when it is read.

        depends_on: the inputs this output depends on at the same instant while stepping (direct
        feedthrough); initial_depends_on: the same in initialization mode (default depends_on).
        min/max: its physical range; the master stops a run when it leaves it.
        """
        var = Real(name, causality=Fmi2Causality.output, description=description, getter=getter)
        self._register(var, unit)
        self._declare_range(name, min, max)
        self._output_deps[name] = tuple(depends_on)
        self._initial_deps[name] = tuple(depends_on if initial_depends_on is None
                                         else initial_depends_on)

    def _declare_range(self, name, low, high):
        if low is not None or high is not None:
            self._ranges[name] = (-float("inf") if low is None else low,
                                  float("inf") if high is None else high)

    def _register(self, var, unit):
        if unit not in UNIT_EXPONENTS:
            raise ValueError(f"unit {unit!r} of {var.name} is not in UNIT_EXPONENTS")
        self.register_variable(var)
        self._units[var.name] = unit
        if var.causality == Fmi2Causality.output:
            self._getters[var.value_reference] = var.getter
        else:  # a plain attribute: read and written in the instance dict, without a Python call
            self._getters[var.value_reference] = partial(self.__dict__.__getitem__, var.name)
            self._names[var.value_reference] = var.name
        return var

    # ---- FMI calls ------------------------------------------------------------------------
    def setup_experiment(self, start_time, stop_time, tolerance):
        self.start_time = float(start_time)

    def get_real(self, vrs):
        getters = self._getters
        if not self._inputs_checked:
            self._check_inputs()
        if self._undefined:
            undefined = self._undefined
            return [0.0 if vr in undefined else getters[vr]() for vr in vrs]
        return [getters[vr]() for vr in vrs]

    def set_real(self, vrs, values):
        """Store the values in the instance dict; the range check is left to the next get or
        step, and made only when an input with a declared range was set."""
        state, names = self.__dict__, self._names
        for vr, value in zip(vrs, values):
            state[names[vr]] = value
        self.revision += 1
        if self._inputs_checked and not self._ranged_vrs.isdisjoint(vrs):
            self._inputs_checked = False

    def step_refused(self):
        """True, after logging why at fmi2Error, when an input lies outside its declared range: the
        FMU's do_step then returns False without changing its state, which pythonfmu reports as
        fmi2Discard (the step is not done, the instance stays usable; any Python exception would be
        fmi2Fatal, pythonfmu 0.7 has no other status)."""
        if not self._inputs_checked:
            self._check_inputs()
        if not self._outside:
            return False
        ranges = self._input_ranges
        self.log(f"{type(self).__name__}: step refused, inputs outside their declared ranges: "
                 + "; ".join(f"{name} = {getattr(self, name)!r} not in [{ranges[name][0]:g}, "
                             f"{ranges[name][1]:g}]" for name in self._outside), Fmi2Status.error)
        return True

    def _check_inputs(self):
        """Find the inputs outside their declared ranges and, when that set changed, the value
        references of the outputs it leaves undefined (those depending on such an input while
        stepping or initializing)."""
        state = self.__dict__
        for name, (low, high) in self._input_ranges.items():
            if not low <= state[name] <= high:
                outside = tuple(name for name, (low, high) in self._input_ranges.items()
                                if not low <= state[name] <= high)
                break
        else:  # the usual case: every input in range
            outside = ()
        if outside != self._outside:
            self._outside = outside
            self._undefined = frozenset(
                var.value_reference for var in self.vars.values() if var.name in self._output_deps
                and set(outside).intersection(self._output_deps[var.name] + self._initial_deps[var.name]))
        self._inputs_checked = True

    # ---- FMU state (fmi2GetFMUstate / fmi2SetFMUstate) ------------------------------------------
    def _get_fmu_state(self):
        """A snapshot of everything the instance computes with: every attribute but the
        declarations and pythonfmu's own bookkeeping, lists, dicts, sets and arrays copied one
        level deep by `_copied` (an adapter replaces or mutates its state at most one level deep;
        tests/test_fmus_alone.py::test_fmu_state_round_trip checks every FMU). pythonfmu calls this for fmi2GetFMUstate."""
        state = self.__dict__.copy()  # then only the few mutable values copied in Python
        for name in _NOT_STATE.intersection(state):
            del state[name]
        _copy_mutable(state, state)
        return state

    def _set_fmu_state(self, state):
        """Restore a `_get_fmu_state` snapshot (it stays usable: restored values are copies)."""
        self.__dict__.update(state)
        _copy_mutable(state, self.__dict__)

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
            if node.get("name") in self._ranges:
                typed = real if real is not None else node.find("Integer")
                for attribute, bound in zip(("min", "max"), self._ranges[node.get("name")]):
                    if abs(bound) != float("inf"):
                        typed.set(attribute, repr(bound) if real is not None else str(int(bound)))
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
