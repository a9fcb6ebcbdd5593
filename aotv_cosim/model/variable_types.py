"""FMI 2.0 variable types as the master exchanges them: Real, Integer, Boolean, Enumeration, String.

Every exchanged value has one float64 slot in the master's buffer: a Real as it is, an Integer or
an Enumeration as its integer (exact: |value| < 2**31), a Boolean as 0.0 or 1.0, and a String as
the number of its text in the run's `Strings` table. Records and summaries turn the slots back
into their types (`typed`).

An Enumeration is given by its integer or by its item's name; it is exchanged as an fmi2Integer.
"""

import ctypes

FMI_TYPE = {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean",
            "String": "String"}
"""Variable type -> the FMI 2.0 get/set functions that exchange it (fmi2GetInteger for an Enumeration)."""

C_TYPE = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int,
          "String": ctypes.c_char_p}
"""FMI 2.0 function type -> the C type of its values (fmi2Boolean is an int)."""

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


def typed(kind: str, slot: float, strings: Strings = None):
    """A buffer slot value as the Python value of a variable of type `kind`."""
    if kind in ("Integer", "Enumeration"):
        return int(slot)
    if kind == "Boolean":
        return bool(slot)
    if kind == "String":
        return strings.text(slot) if strings is not None else str(slot)
    return float(slot)


def slot(kind: str, value, strings: Strings = None) -> float:
    """The buffer slot value of a Python value of a variable of type `kind`."""
    if kind == "String":
        return strings.number(value)
    return float(value)


class Decoder:
    """Turns recorded float64 columns back into their types: `types` {column: type} names the
    columns that are not Real, `texts` the run's String values by number (`Strings.texts`)."""

    def __init__(self, types: dict = None, texts: list = None):
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
        """A recorded column as a numpy array of its type (int32, bool, object for String)."""
        import numpy as np

        kind = self.kind(column)
        values = np.asarray(values, dtype=float)
        if kind in ("Integer", "Enumeration"):
            return values.astype(np.int32)
        if kind == "Boolean":
            return values != 0.0
        if kind == "String":
            return np.array([self.texts[int(v)] for v in values], dtype=object)
        return values
