"""The master's FMI calls, prepared once per run: value-reference and value arrays over one shared
ctypes buffer (`Call`, `Plan`), bound to the instances' C entry points (`bind`) and made in order
(`run_bound`). A value array whose buffer positions are consecutive is a view of the buffer, so
the loop passes inputs and reads outputs without a copy per step. Integer, Boolean, Enumeration
and String values go through a `TypedCall`: one fmi2Get/SetInteger, Boolean or String call per
component and type, converting between its C values and the buffer's float64 slots
(`variable_types`).
"""

import ctypes

from aotv_cosim.model.variable_types import C_TYPE, FMI_TYPE


class Call:
    """One fmi2SetReal or fmi2GetReal call: value references, values, their places in the buffer.

    Variables are sorted by the position of their values in the master's output buffer (an
    input: its source's); when those positions are consecutive the value array is a view into
    the buffer itself (no copy per step), otherwise `pairs` lists (value slot, buffer index)
    copied before a set or after a get.
    """

    def __init__(self, inst, names, positions, values, alias=True):
        ranked = sorted(zip(positions, names))
        self.positions = [s for s, _ in ranked]
        self.n = len(ranked)
        self.size = ctypes.c_size_t(self.n)  # passed to C as is (`FmuInstance` entry points)
        self.vrs = (ctypes.c_uint * self.n)(*[inst.info.variables[name].vr for _, name in ranked])
        first = self.positions[0] if ranked else 0
        if alias and self.positions == list(range(first, first + self.n)):
            self.vals = (ctypes.c_double * self.n).from_buffer(values, first * 8)
            self.pairs = ()
        else:
            self.vals = (ctypes.c_double * max(self.n, 1))()
            self.pairs = tuple(enumerate(self.positions))


class TypedCall:
    """One fmi2Get/Set of Integer (an Enumeration too), Boolean or String values of one component.

    Bound like a `Call` (`bind`), with `function` in place of the C entry point: it makes the C
    call and converts the values between their C type and the buffer's float64 slots (a String
    through the run's `Strings` table), so `pairs` is empty for `run_bound`."""

    def __init__(self, inst, kind, fmi_type, names, positions, values, strings):
        ranked = sorted(zip(positions, names))
        self.positions = [s for s, _ in ranked]
        self.n = len(ranked)
        self.size = ctypes.c_size_t(self.n)
        self.vrs = (ctypes.c_uint * self.n)(*[inst.info.variables[name].vr for _, name in ranked])
        self.vals = (C_TYPE[fmi_type] * max(self.n, 1))()
        self.pairs = ()
        self.what = f"fmi2{kind}{fmi_type}"
        raw = inst.raw[(kind, fmi_type)]
        slots = tuple(enumerate(self.positions))
        if kind == "Get":
            convert = strings.number if fmi_type == "String" else None

            def function(c, vrs, n, vals):
                status = raw(c, vrs, n, vals)
                for i, j in slots:
                    values[j] = convert(vals[i].decode("utf-8", "replace")) if convert else vals[i]
                return status
        else:
            def function(c, vrs, n, vals):
                for i, j in slots:
                    vals[i] = strings.text(values[j]).encode("utf-8") if fmi_type == "String" \
                        else int(values[j])
                return raw(c, vrs, n, vals)
        self.function = function


def calls_by_type(inst, kind, names, positions, values, strings, alias=True):
    """The calls that get or set `names` of `inst` (values at `positions` of the buffer): a
    `Call` for the Real ones, then a `TypedCall` per other FMI type; the empty Real call is kept
    (the loop's fresh and delayed sets are Real calls, possibly of nothing)."""
    variables = inst.info.variables
    groups = {}
    for name, pos in zip(names, positions):
        groups.setdefault(FMI_TYPE[variables[name].type], []).append((name, pos))
    real = groups.pop("Real", [])
    made = [Call(inst, [n for n, _ in real], [p for _, p in real], values, alias)]
    for fmi_type, group in groups.items():
        made.append(TypedCall(inst, kind.capitalize(), fmi_type, [n for n, _ in group],
                              [p for _, p in group], values, strings))
    return made


class Plan:
    """Arrays and index maps of one component, built once before stepping.

    The last `stale` outputs are re-read later in each sweep (they feed through from an input
    set after the component stepped): the get after its step reads only the others
    (`n_fresh_out`), so those outputs are not computed twice per step."""

    def __init__(self, inst, outputs, values, offset, stale=0):
        self.inst = inst
        self.n_out = len(outputs)
        self.out_size = ctypes.c_size_t(self.n_out)
        self.n_fresh_out = self.n_out - stale
        self.fresh_out_size = ctypes.c_size_t(self.n_fresh_out)
        self.out_vrs = (ctypes.c_uint * self.n_out)(*[inst.info.variables[o].vr for o in outputs])
        self.out_vals = (ctypes.c_double * self.n_out).from_buffer(values, offset * 8)
        self.offset = offset


def bind(actions):
    """(is_get, inst, component, C function, vrs, n, vals, pairs, name) per (kind, inst, Call).

    The C functions are looked up here, when the loop starts, so a wrapper put on an instance
    after the plans were built (bench/run.py times every call) is the one called."""
    return [(kind == "get", inst, inst.component, inst.raw_get_real if kind == "get" else inst.raw_set_real,
             call.vrs, call.size, call.vals, call.pairs, "fmi2GetReal" if kind == "get" else "fmi2SetReal")
            if isinstance(call, Call) else
            (kind == "get", inst, inst.component, call.function, call.vrs, call.size, call.vals, (), call.what)
            for kind, inst, call in actions]


def run_bound(bound, values, t):
    """Make the bound calls in order: a set copies its values in first, a get copies them out after."""
    for is_get, inst, c, call, vrs, n, vals, pairs, what in bound:
        if not is_get:
            for i, j in pairs:
                vals[i] = values[j]
        if call(c, vrs, n, vals) > 1:
            raise inst.failure(what, t)
        if is_get:
            for i, j in pairs:
                values[j] = vals[i]
