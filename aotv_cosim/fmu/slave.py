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
dominated by this per-call Python work. `revision` counts the sets (of every type), so an adapter
may cache a value computed from the inputs until the next set or step.

Any legal FMI 2.0 call order: a host may set parameters and start values before
fmi2EnterInitializationMode (as this package's master does) or after it (Ecos does), set and read
in several passes while initializing, and reset the instance (pythonfmu builds a new slave
object). So an adapter never derives its start from the values it saw at one call: it implements
`start_state` (its initial state, clocks and parameter-built laws from the current values), which
runs before an output is read in initialization mode whenever a value was set since, and once
more when initialization ends, then `latch` (what the steps start from). Expensive solves are
cached by the values they use, so a host's repeated passes with unchanged values solve once.

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
import functools
import math
import numbers
import re
import sys
import traceback
from functools import partial
from typing import cast
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Status

BASE_UNITS = ("A", "K", "cd", "kg", "m", "mol", "rad", "s")
"""The base units of FMI 2.0 `BaseUnit` (the SI base units and rad)."""

DERIVED_UNITS = {
    "N": {"kg": 1, "m": 1, "s": -2}, "Pa": {"kg": 1, "m": -1, "s": -2}, "J": {"kg": 1, "m": 2, "s": -2},
    "W": {"kg": 1, "m": 2, "s": -3}, "Hz": {"s": -1}, "C": {"A": 1, "s": 1},
    "V": {"kg": 1, "m": 2, "s": -3, "A": -1}, "Ohm": {"kg": 1, "m": 2, "s": -3, "A": -2},
    "T": {"kg": 1, "s": -2, "A": -1}, "Wb": {"kg": 1, "m": 2, "s": -2, "A": -1}, "sr": {},
}
"""SI derived units with special names, as base-unit exponents (sr is dimensionless)."""

_UNIT_TOKEN = re.compile(r"([A-Za-z]+)(\^?-?[0-9]+)?|1|[./*()]")


@functools.cache
def unit_exponents(unit: str) -> dict:
    """The SI base-unit exponents of a unit string, {base unit: exponent} sorted by name (FMI 2.0
    `BaseUnit` attributes); ValueError for a string that is not a product of SI units.

    Grammar (the FMI/Modelica spelling): factors joined by "." or "*", each a symbol of
    `BASE_UNITS` or `DERIVED_UNITS` with an optional integer exponent ("m2", "s-1", "s^2"); "/"
    divides by the next factor or parenthesised group; "1" is dimensionless. "m/s4" is
    {"m": 1, "s": -4}, "kg/(s.m)" is {"kg": 1, "m": -1, "s": -1}. Prefixed units (km, ms) are not
    SI interface units and are refused."""
    tokens, position = [], 0
    while position < len(unit):
        match = _UNIT_TOKEN.match(unit, position)
        if match is None:
            raise ValueError(f"unit {unit!r}: cannot read {unit[position:]!r}; write SI units like "
                             "'m/s2', 'kg/(s.m)' or 'N.m'")
        tokens.append(match)
        position = match.end()
    exponents, rest = _unit_quotient(unit, tokens)
    if rest or not tokens:
        raise ValueError(f"unit {unit!r}: unexpected {rest[0].group() if rest else 'empty unit'!r}; "
                         "write SI units like 'm/s2', 'kg/(s.m)' or 'N.m' ('1' if dimensionless)")
    return {name: exponents[name] for name in sorted(exponents) if exponents[name]}


def _unit_quotient(unit, tokens):
    """(exponents, tokens left) of `product ("/" (factor | "(" quotient ")"))*`."""
    exponents, tokens = _unit_product(unit, tokens)
    while tokens and tokens[0].group() == "/":
        divisor, tokens = _unit_factor(unit, tokens[1:])
        for name, power in divisor.items():
            exponents[name] = exponents.get(name, 0) - power
    return exponents, tokens


def _unit_product(unit, tokens):
    exponents, tokens = _unit_factor(unit, tokens)
    while tokens and tokens[0].group() in ".*":
        factor, tokens = _unit_factor(unit, tokens[1:])
        for name, power in factor.items():
            exponents[name] = exponents.get(name, 0) + power
    return exponents, tokens


def _unit_factor(unit, tokens):
    if not tokens:
        raise ValueError(f"unit {unit!r} ends where a unit is expected")
    token, text = tokens[0], tokens[0].group()
    if text == "1":
        return {}, tokens[1:]
    if text == "(":
        exponents, rest = _unit_quotient(unit, tokens[1:])
        if not rest or rest[0].group() != ")":
            raise ValueError(f"unit {unit!r}: a '(' is not closed")
        return exponents, rest[1:]
    symbol = token.group(1)
    if symbol is None:
        raise ValueError(f"unit {unit!r}: unexpected {text!r} where a unit is expected")
    if symbol in BASE_UNITS:
        base = {symbol: 1}
    elif symbol in DERIVED_UNITS:
        base = DERIVED_UNITS[symbol]
    else:
        raise ValueError(f"unit {unit!r}: {symbol!r} is not an SI unit; use the base units "
                         f"{', '.join(BASE_UNITS)} or {', '.join(DERIVED_UNITS)} (no prefixes: SI at every interface)")
    power = int(token.group(2).lstrip("^")) if token.group(2) else 1
    return {name: p * power for name, p in base.items()}, tokens[1:]


POSITIVE = sys.float_info.min
"""Declared `min` of a quantity that must be strictly positive (a speed, a mass, an area, a
radius): the smallest positive normal double, 2.2e-308."""

XSD_SPECIAL = {"inf": "INF", "-inf": "-INF", "nan": "NaN"}
"""xs:double spellings of the non-finite start values Python formats as inf/-inf/nan."""


NOT_STATE = frozenset({
    "vars", "log_queue", "instance_name", "resources", "visible", "guid", "_units", "_output_deps",
    "_initial_deps", "_getters", "_names", "_ranges", "_input_ranges", "_ranged_vrs", "_nominals"})
"""Instance attributes that are declarations or pythonfmu's own (its C++ side keeps a reference to
`log_queue`): never part of a saved FMU state. Every other instance attribute is (`SAVED_STATE`)."""

SAVED_STATE = """What fmi2GetFMUstate saves of an AotvSlave, and so what an adapter may hold:
every instance attribute but NOT_STATE. Immutable values (numbers, strings, tuples of them) are
shared; a list, dict, set or numpy array is copied one level deep, so an adapter may change its
items in place but not the objects inside them; an object is shared unless its class sets
`MUTABLE_STATE = True` (then copy.copy: an adaptive law whose estimates change over a run).
Anything else an adapter changes over a run must be replaced, not mutated."""
"""The saved-state rules as text (the extension module and the docs quote it)."""


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


def _abstract_names(cls) -> set:
    """Names of the abstract methods of `cls` as ABCMeta will compute them (it does so only after
    ``__init_subclass__`` has run)."""
    names = {name for name, value in vars(cls).items() if getattr(value, "__isabstractmethod__", False)}
    for base in cls.__bases__:
        names |= {name for name in getattr(base, "__abstractmethods__", ())
                  if getattr(getattr(cls, name, None), "__isabstractmethod__", False)}
    return names


STEP_CONTRACT = """What ``do_step(self, current_time, step_size)`` returns: True when the step is
done; False to refuse it (fmi2Discard: the instance stays usable and the run fails with the
message that the FMU refused the step at t = ..., or the error-controlled stepping retries it with
a shorter step); never None (a forgotten `return`: an error naming the file and line of the
do_step). An exception fails the run with its traceback (file and line) in the FMU's log."""
"""The step contract as text (the extension module and the docs quote it)."""


class StepContractError(TypeError):
    """do_step returned None (or something else that is neither true nor false)."""


def checked_step(do_step):
    """do_step held to `STEP_CONTRACT` in every host, the C wrapper's and the direct calls alike
    (both call this method and map its outcome: an exception to fmi2Fatal, False to fmi2Discard):

    - an exception is logged with its traceback at fmi2Fatal before it is re-raised (pythonfmu
      0.7 turns it into fmi2Fatal with its message only, so the author's file and line reach the
      master's log, summary.json error_detail, this way); logged once, by the innermost wrapper;
    - None raises `StepContractError` naming the author's file and the line of the do_step;
    - a false value is returned with an error logged saying the step was refused at t = ... (unless
      the step's last log message already is an error: its own reason), so that no host takes the
      discard for a request to end the simulation (pythonfmu's wrappers answer fmi2Terminated true
      after any discard; the master's `refused_step` reads a discard ending in an error as a
      failure);
    - True is returned at once (the common case costs one identity test)."""
    code = getattr(do_step, "__code__", None)
    where = (f"{_authors_file(code.co_filename)}, line {code.co_firstlineno}" if code is not None
             else getattr(do_step, "__qualname__", "do_step"))

    @functools.wraps(do_step)
    def wrapper(self, current_time, step_size):
        try:
            result = do_step(self, current_time, step_size)
        except Exception as exc:
            if not getattr(exc, "_aotv_logged", False):
                exc._aotv_logged = True  # type: ignore[attr-defined]  # a mark for the wrappers above
                text = _authors_traceback(exc)
                self.log(f"{type(self).__name__}.do_step raised at t = {current_time!r} s:\n{text}",
                         Fmi2Status.fatal)
            raise
        if result is True:
            return result
        return _judged(self, result, current_time, where)
    wrapper._aotv_contract = True  # type: ignore[attr-defined]  # a mark `checked_step` looks for
    return wrapper


def _judged(slave, result, current_time, where):
    """The outcome of a do_step at current_time (s) that returned `result`, not True: a true value
    as is, None an error, a false value a refusal (`checked_step`)."""
    if result is None:
        message = (f"{where}: {type(slave).__name__}.do_step returned None at t = {current_time!r} s (a "
                   "missing `return`?); return True when the step is done, False to refuse it")
        slave.log(message, Fmi2Status.fatal)
        error = StepContractError(message)
        error._aotv_logged = True  # type: ignore[attr-defined]
        raise error
    try:
        done = bool(result)
    except Exception:  # as the wrappers count it: an error in the truth test is a step done
        return result
    if not done:
        queue = slave.log_queue
        if not (queue and int(getattr(queue[-1], "status", 0)) >= Fmi2Status.error):
            slave.log(f"{type(slave).__name__} refused the step at t = {current_time!r} s: do_step returned "
                      f"{result!r} ({where})", Fmi2Status.error)
    return result


def enforce_step_contract(cls):
    """Hold the do_step of `cls`, a plain pythonfmu Fmi2Slave class, to `STEP_CONTRACT` (an
    AotvSlave's is, from its definition: `AotvSlave.__init_subclass__`). The build appends a call
    of this to the module of such a class in the FMU (`aotv_cosim.fmu.build`)."""
    own = cls.do_step
    if not getattr(own, "_aotv_contract", False):
        cls.do_step = checked_step(own)
    return cls


_BUNDLED_NAME = re.compile(r"^(?P<stem>.+)_[0-9a-f]{16}\.py$")
"""File name of a module bundled into an FMU: the build appends the source hash to its stem."""


def _authors_file(filename: str) -> str:
    """`filename` of a module, or its author's file name (``MyLaw.py``) for the FMU's bundled
    copy ``resources/MyLaw_<hash16>.py``."""
    bundled = _BUNDLED_NAME.match(filename.rpartition("/")[2])
    return f"{bundled['stem']}.py" if bundled else filename


def _authors_traceback(exc) -> str:
    """The traceback of `exc` without the logging wrapper's frame, each bundled module named by
    its author's file name (`_authors_file`; the line numbers are the author's: the build
    rewrites only import lines, one line for one, and appends after the last)."""
    frames = traceback.extract_tb(exc.__traceback__.tb_next)
    for frame in frames:
        frame.filename = _authors_file(frame.filename)
    return "".join(["Traceback (most recent call last):\n", *frames.format(),
                    *traceback.format_exception_only(type(exc), exc)])


def _copy_mutable(source, target):
    """target[name] = _copied(value) for each value of `source` that is not of a _SCALARS type
    (the state's scalars are shared: a snapshot costs a dict copy and a few list copies)."""
    for name, value in source.items():
        if type(value) not in _SCALARS:
            target[name] = _copied(value)


def _real_start(name: str, start) -> float:
    """The start value of Real `name` as a float; ValueError naming it for NaN (a NaN start built,
    then failed the first run at another component's non-finite output). An infinite one may stand
    for no bound (AngleActuator's lower and upper)."""
    value = float(start)
    if math.isnan(value):
        raise ValueError(f"{name}: start {start!r} is not a number; give a number (inf for no bound)")
    return value


class AotvSlave(Fmi2Slave):
    """pythonfmu slave with declared units, dependencies and a fast value table.

    Subclasses call `parameter`, `input` and `output` in ``__init__`` and implement ``do_step``.
    `default_step` (s) sets the DefaultExperiment step size of the FMU.
    """

    default_step = 0.1
    default_stop = 300.0

    def __init_subclass__(cls, **kwargs):
        """Check the class when it is defined: a concrete FMU class (no abstract method left)
        defines ``do_step`` in its own body, since pythonfmu 0.7's runtime finds the slave class
        through the class that owns do_step (with an inherited one, instantiation corrupts the
        FMU's module and every later instance fails). Each own do_step is held to
        `STEP_CONTRACT` (`checked_step`: tracebacks logged, None an error, False a refusal)."""
        super().__init_subclass__(**kwargs)
        own = vars(cls).get("do_step")
        if own is not None and not getattr(own, "__isabstractmethod__", False):
            cls.do_step = checked_step(own)
        elif own is None and not _abstract_names(cls):
            raise TypeError(f"class {cls.__qualname__} ({cls.__module__}) must define do_step itself, "
                            "not inherit it: add `def do_step(self, current_time, step_size)` to the class "
                            "(e.g. `return self.advance(current_time, step_size)`)")

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
        self._nominals = {}
        self._inputs_checked = True
        self._outside = ()
        self._undefined: frozenset[str] = frozenset()
        self.revision = 0  # not `version`: pythonfmu writes that attribute into the modelDescription
        self.start_time = 0.0
        self.initializing = True  # until fmi2ExitInitializationMode
        self._started = -1  # the revision `start_state` last ran at

    # ---- declarations -------------------------------------------------------------------
    def parameter(self, name, start, unit, description, tunable=False, min=None, max=None, nominal=None):
        """Declare a Real parameter `name` (attribute of the same name) in `unit`, optionally
        within [min, max] (SI, inclusive); `nominal`: its typical magnitude (FMI nominal), from
        which the master warns about a value given in the wrong unit (`output.plausibility`)."""
        setattr(self, name, _real_start(name, start))
        self._declare_nominal(name, nominal)
        variability = Fmi2Variability.tunable if tunable else Fmi2Variability.fixed
        self._register(Real(name, causality=Fmi2Causality.parameter, variability=variability,
                            description=description), unit)
        self._declare_range(name, min, max, start)

    def integer_parameter(self, name, start, description, min=None, max=None):
        """Declare an Integer parameter (a mode switch or a seed); min/max: its allowed codes."""
        setattr(self, name, int(start))
        self.register_variable(Integer(name, causality=Fmi2Causality.parameter,
                                       variability=Fmi2Variability.fixed,
                                       description=description))
        self._declare_range(name, min, max, start)

    def input(self, name, start, unit, description, min=None, max=None, nominal=None):
        """Declare a continuous Real input `name` (attribute of the same name) in `unit`; outputs
        depending on it read 0 while it lies outside [min, max] (module docstring); `nominal`: its
        typical magnitude (FMI nominal), from which the master warns about a value given to it
        unconnected in the wrong unit, as for a parameter."""
        setattr(self, name, _real_start(name, start))
        self._declare_nominal(name, nominal)
        var = self._register(Real(name, causality=Fmi2Causality.input, description=description), unit)
        self._declare_range(name, min, max, start)
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

    def _declare_range(self, name, low, high, start=None):
        """Record [low, high] (None: unbounded) of variable `name`; ValueError naming it for a
        bound that is not a number, low above high, or a `start` outside."""
        if low is None and high is None:
            return
        bounds = (-math.inf if low is None else low, math.inf if high is None else high)
        if any(isinstance(b, bool) or not isinstance(b, numbers.Real) or math.isnan(b) for b in bounds):
            raise ValueError(f"{name}: min and max must be numbers, not {low!r} and {high!r}")
        if bounds[0] > bounds[1]:
            raise ValueError(f"{name}: min {low!r} is above max {high!r}")
        if start is not None and not bounds[0] <= start <= bounds[1]:
            raise ValueError(f"{name}: start {start!r} lies outside [min, max] = [{bounds[0]!r}, {bounds[1]!r}]")
        self._ranges[name] = bounds

    def _declare_nominal(self, name, nominal):
        """Record the FMI nominal of Real `name`; ValueError naming it unless finite and > 0 (FMI
        2.0: the typical magnitude of the quantity, e.g. 7045.0 for a scale height in m)."""
        if nominal is None:
            return
        if (isinstance(nominal, bool) or not isinstance(nominal, numbers.Real)
                or not 0.0 < cast(float, nominal) < math.inf):
            raise ValueError(f"{name}: nominal {nominal!r} must be a finite number above 0 (the quantity's "
                             "typical magnitude in its SI unit)")
        self._nominals[name] = float(nominal)

    def _register(self, var, unit):
        if not isinstance(unit, str):
            raise TypeError(f"{var.name}: unit {unit!r} is not a text; write SI units like 'm/s2' ('1' if "
                             "dimensionless)")
        try:
            unit_exponents(unit)
        except ValueError as exc:
            raise ValueError(f"{var.name}: {exc}") from None
        self.register_variable(var)
        self._units[var.name] = unit
        if var.causality == Fmi2Causality.output:
            self._getters[var.value_reference] = var.getter
        else:  # a plain attribute: read and written in the instance dict, without a Python call
            self._getters[var.value_reference] = partial(self.__dict__.__getitem__, var.name)
            self._names[var.value_reference] = var.name
        return var

    # ---- initialization (module docstring) ------------------------------------------------------
    def start_state(self):
        """Derive from the current parameters, start values and start time everything the FMU's
        outputs read before the first step (subclass hook; cheap, or cached by the values used)."""

    def latch(self):
        """Fix, when initialization ends, what the steps start from (subclass hook)."""

    def _start_if_changed(self):
        if self._started != self.revision:
            self.start_state()
            self._started = self.revision

    def enter_initialization_mode(self):
        self.initializing = True

    def exit_initialization_mode(self):
        self._start_if_changed()
        self.latch()
        self.initializing = False

    # ---- FMI calls ------------------------------------------------------------------------
    def setup_experiment(self, start_time, stop_time, tolerance):
        self.start_time = float(start_time)
        self.revision += 1

    def get_real(self, vrs):
        getters = self._getters
        if self.initializing and self._started != self.revision:
            self._start_if_changed()
        if not self._inputs_checked:
            self._check_inputs()
        if self._undefined:
            undefined = self._undefined
            return [0.0 if vr in undefined else getters[vr]() for vr in vrs]
        if len(vrs) == 1:  # most connections read one value: no comprehension frame
            return [getters[vrs[0]]()]
        return [getters[vr]() for vr in vrs]

    def set_real(self, vrs, values):
        """Store the values in the instance dict; the range check is left to the next get or
        step, and made only when an input with a declared range was set."""
        state, names = self.__dict__, self._names
        if len(vrs) == 1:  # most connections set one value: no loop
            state[names[vrs[0]]] = values[0]
        else:
            for vr, value in zip(vrs, values):
                state[names[vr]] = value
        self.revision += 1
        if self._inputs_checked and not self._ranged_vrs.isdisjoint(vrs):
            self._inputs_checked = False

    def get_integer(self, vrs):
        if self.initializing and self._started != self.revision:
            self._start_if_changed()
        return super().get_integer(vrs)

    def set_integer(self, vrs, values):
        super().set_integer(vrs, values)
        self.revision += 1

    def set_boolean(self, vrs, values):
        super().set_boolean(vrs, values)
        self.revision += 1

    def set_string(self, vrs, values):
        super().set_string(vrs, values)
        self.revision += 1

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
        tests/fmus/test_fmus_alone.py::test_fmu_state_round_trip checks every FMU). pythonfmu calls this for
        fmi2GetFMUstate."""
        state = self.__dict__.copy()  # then only the few mutable values copied in Python
        for name in NOT_STATE.intersection(state):
            del state[name]
        _copy_mutable(state, state)
        return state

    def _set_fmu_state(self, state):
        """Restore a `_get_fmu_state` snapshot (it stays usable: restored values are copies)."""
        self.__dict__.update(state)
        _copy_mutable(state, self.__dict__)

    # ---- model description ------------------------------------------------------------------
    def to_xml(self, model_options=dict()):  # noqa: B006 - pythonfmu's signature; the dict is only read
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
            if node.get("name") in self._nominals:
                real.set("nominal", repr(self._nominals[node.get("name")]))
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
            SubElement(node, "BaseUnit", {k: str(v) for k, v in unit_exponents(unit).items()})
        return definitions
