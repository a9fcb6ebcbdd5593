"""FMI variable types as the master exchanges them.

Every variable has a declared FMI type (`Variable.fmi_type`: Real, Integer, Boolean, String,
Enumeration in FMI 2.0; Float32, Float64, Int8 ... UInt64, Boolean, String, Binary, Enumeration in
FMI 3.0) and a kind (`Variable.type`, `KIND`): what the master exchanges, records and checks it as,
in FMI 2.0's words: Real (Float32 and Float64 too), Integer (every integer width), Boolean,
String (Binary too, as the hexadecimal text of its bytes) and Enumeration.

Every exchanged value has one float64 slot in the master's buffer: a Real as it is (a Float32
exactly), an integer or an Enumeration as its number (exact within +-2^53, which only Int64 and
UInt64 values can exceed: such a value read from an FMU fails the run), a Boolean as 0.0 or 1.0,
and a String (a Binary's hexadecimal text) as the number of its text in the run's `Strings`
table. Records and summaries turn the slots back into their types (`typed`).

An Enumeration is given by its integer or by its item's name; it is exchanged as an fmi2Integer
(FMI 2.0) or an fmi3Int64 (FMI 3.0): `call_type`.
"""

KIND = {"Real": "Real", "Float32": "Real", "Float64": "Real",
        "Integer": "Integer", "Int8": "Integer", "UInt8": "Integer", "Int16": "Integer", "UInt16": "Integer",
        "Int32": "Integer", "UInt32": "Integer", "Int64": "Integer", "UInt64": "Integer",
        "Boolean": "Boolean", "String": "String", "Binary": "String", "Enumeration": "Enumeration"}
"""Declared FMI type -> the kind the master exchanges, records and checks it as."""

INTEGER_RANGE = {"Integer": (-2**31, 2**31 - 1), "Int32": (-2**31, 2**31 - 1),
                 "Int8": (-2**7, 2**7 - 1), "UInt8": (0, 2**8 - 1), "Int16": (-2**15, 2**15 - 1),
                 "UInt16": (0, 2**16 - 1), "UInt32": (0, 2**32 - 1), "Int64": (-2**63, 2**63 - 1),
                 "UInt64": (0, 2**64 - 1), "Enumeration": (-2**31, 2**31 - 1)}
"""Declared integer type -> (lowest, highest) value (an FMI 2.0 Enumeration is an fmi2Integer;
an FMI 3.0 one's range is Int64's, `integer_range`)."""

FLOAT64_CALLS = ("Real", "Float64")
"""Call types whose values are C doubles: passed to and from the buffer without conversion."""

FMI_TYPE = {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean",
            "String": "String"}
"""FMI 2.0 variable type -> the get/set functions that exchange it (fmi2GetInteger for an Enumeration)."""

SAME = {"Real": "Float64", "Integer": "Int32"}
"""An FMI 2.0 type -> the FMI 3.0 type of the same values (a connection across versions)."""


def call_type(fmi_version: str, fmi_type: str) -> str:
    """The FMI type whose get/set functions exchange a variable declared `fmi_type` in an FMU of
    `fmi_version` ("2.0": `FMI_TYPE`; "3.0": the type itself, an Enumeration as Int64)."""
    if fmi_version == "2.0":
        return FMI_TYPE[fmi_type]
    return "Int64" if fmi_type == "Enumeration" else fmi_type


def integer_range(fmi_version: str, fmi_type: str) -> tuple:
    """(lowest, highest) value of an integer or Enumeration variable declared `fmi_type`."""
    if fmi_type == "Enumeration" and fmi_version != "2.0":
        return INTEGER_RANGE["Int64"]
    return INTEGER_RANGE[fmi_type]


def lossless(source: str, target: str) -> bool:
    """True when every value of declared type `source` is a value of `target`, so an output of
    the one may feed an input of the other: the same type (Real and Float64, Integer and Int32
    are the same across FMI versions), Float32 into Float64, an integer into a wider one."""
    source, target = SAME.get(source, source), SAME.get(target, target)
    if source == target:
        return True
    if (source, target) == ("Float32", "Float64"):
        return True
    if source in INTEGER_RANGE and target in INTEGER_RANGE and "Enumeration" not in (source, target):
        (low, high), (lowest, highest) = INTEGER_RANGE[source], INTEGER_RANGE[target]
        return lowest <= low and high <= highest
    return False


DISCRETE = ("Integer", "Enumeration", "Boolean", "String")
"""Types whose values change only at events: recorded and compared exactly."""


class Strings:
    """The String values met in a run, each numbered once: the buffer holds the number."""

    def __init__(self):
        self.texts = [""]
        self.numbers = {"": 0}

    def number(self, text: str) -> float:
        """The buffer slot value of `text` (a new number for a text not seen before)."""
        found = self.numbers.get(text)
        if found is None:
            found = self.numbers[text] = len(self.texts)
            self.texts.append(text)
        return float(found)

    def text(self, number: float) -> str:
        """The text a buffer slot value stands for."""
        return self.texts[int(number)]


def items(fmu, name: str) -> dict:
    """{item name: integer value} of the Enumeration variable `name` of an FmuInfo ({} if none)."""
    var = next((v for v in fmu.model_description.modelVariables if v.name == name), None)
    declared = getattr(var, "declaredType", None)
    return {item.name: int(item.value) for item in getattr(declared, "items", None) or ()}


def declared_type_name(fmu, name: str):
    """The name of the declared type of variable `name` (an Enumeration's SimpleType), or None."""
    var = next((v for v in fmu.model_description.modelVariables if v.name == name), None)
    declared = getattr(var, "declaredType", None)
    return getattr(declared, "name", None)


def enumeration_value(fmu, name: str, value):
    """The integer of an Enumeration value given by its integer or its item name; None when
    `value` is neither an item's integer nor an item's name."""
    known = items(fmu, name)
    if isinstance(value, bool):
        return None
    if isinstance(value, int) and (value in known.values() or not known):
        return value
    if isinstance(value, str) and value in known:
        return known[value]
    return None


def typed(kind: str, slot: float, strings: Strings | None = None):
    """A buffer slot value as the Python value of a variable of type `kind`."""
    if kind in ("Integer", "Enumeration"):
        return int(slot)
    if kind == "Boolean":
        return bool(slot)
    if kind == "String":
        return strings.text(slot) if strings is not None else str(slot)
    return float(slot)


def slot(kind: str, value, strings: Strings | None = None) -> float:
    """The buffer slot value of a Python value of a variable of type `kind`."""
    if kind == "String":
        assert strings is not None, "a String value is numbered by the run's Strings"
        return strings.number(value)
    return float(value)


class Decoder:
    """Turns recorded float64 columns back into their types: `types` {column: type} names the
    columns that are not Real, `texts` the run's String values by number (`Strings.texts`)."""

    def __init__(self, types: dict | None = None, texts: list | None = None):
        self.types = dict(types or {})
        self.texts = texts if texts is not None else []

    def kind(self, column: str) -> str:
        return self.types.get(column, "Real")

    def value(self, column: str, slot: float):
        """One recorded value of `column` as its type's Python value."""
        kind = self.kind(column)
        if kind == "String":
            return self.texts[int(slot)]
        return typed(kind, slot)

    def column(self, column: str, values):
        """A recorded column as a numpy array of its type (int32, bool, object for String); an
        integer column with a value beyond int32 (an FMI 3.0 UInt32, Int64 or UInt64) is int64,
        which holds every integer the buffer carries exactly (+-2^53)."""
        import numpy as np

        kind = self.kind(column)
        values = np.asarray(values, dtype=float)
        if kind in ("Integer", "Enumeration"):
            fits = values.size == 0 or (values.min() >= -2**31 and values.max() < 2**31)
            return values.astype(np.int32 if fits else np.int64)
        if kind == "Boolean":
            return values != 0.0
        if kind == "String":
            return np.array([self.texts[int(v)] for v in values], dtype=object)
        return values
