"""Units of SSV parameter values: a value given in another unit than the FMU variable's is
converted through both units' SI base-unit definitions, or refused.

SSP 1.0 (and FMI 2.0) define a unit by its exponents of the SI base units and a factor and
offset: value in base units = factor * value + offset. A parameter `h0 value="80" unit="km"`
whose unit is defined in the SSV's or the SSD's `Units` (km: m = 1, factor = 1000) sets the FMU's
`h0` in m to 80000; a unit defined nowhere, or of another dimension, is refused rather than
flown as if it were the FMU's unit.
"""

from aotv_cosim.errors import InputError
from aotv_cosim.model.ssp_names import q

BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def definitions(*unit_lists) -> dict:
    """{unit name: (exponents, factor, offset)} of the ssc:Unit elements of `Units` elements
    (None entries are skipped; a later list wins)."""
    found = {}
    for units in unit_lists:
        if units is None:
            continue
        for unit in units.findall(q("ssc:Unit")):
            base = unit.find(q("ssc:BaseUnit"))
            attrs = base.attrib if base is not None else {}
            found[unit.get("name")] = (tuple(int(attrs.get(b, 0)) for b in BASE_UNITS),
                                       float(attrs.get("factor", 1.0)), float(attrs.get("offset", 0.0)))
    return found


def fmu_definitions(model_description) -> dict:
    """{unit name: (exponents, factor, offset)} of an FMU's UnitDefinitions (FMPy's objects)."""
    found = {}
    for unit in model_description.unitDefinitions:
        base = unit.baseUnit
        if base is not None:
            found[unit.name] = (tuple(int(getattr(base, b) or 0) for b in BASE_UNITS),
                                float(base.factor), float(base.offset))
    return found


def to_fmu_unit(value: float, unit: str, fmu_unit: str, ssp_units: dict, fmu_units: dict, *,
                file, entry) -> float:
    """`value` given in `unit`, expressed in the FMU variable's `fmu_unit`.

    Equal names need no definition. Otherwise both must be defined (the SSP's unit in
    `ssp_units`, the FMU's in `fmu_units`, else in `ssp_units`; a unit absent from both with the
    name of an SI base unit or '1' is that unit) with the same exponents. A variable without a
    declared unit takes a value in a coherent SI unit (factor 1, offset 0) as it is."""
    if unit == fmu_unit:
        return value
    given = ssp_units.get(unit) or _plain(unit)
    if not fmu_unit and given is not None and given[1:] == (1.0, 0.0):
        return value  # a coherent SI unit for a variable that declares none: SI at the interface
    target = fmu_units.get(fmu_unit) or ssp_units.get(fmu_unit) or _plain(fmu_unit)
    if given is None:
        raise InputError(f"unit {unit!r} is not defined, and the FMU's unit is {fmu_unit or 'not declared'!r}",
                         file=file, entry=entry,
                         fix=f"give the value in {fmu_unit or 'the FMU unit'}, or define {unit!r} "
                             "(ssc:Unit with its ssc:BaseUnit) in the SSV's or SSD's Units")
    if target is None or target[0] != given[0]:
        raise InputError(f"unit {unit!r} cannot be converted to the FMU's unit {fmu_unit or '(none)'!r}",
                         file=file, entry=entry,
                         fix=f"give the value in {fmu_unit or 'the FMU variable unit'}")
    base = given[1] * value + given[2]
    return (base - target[2]) / target[1]


def _plain(name):
    """The definition of an SI base unit or of '1' named plainly, else None."""
    if name == "1":
        return (0,) * len(BASE_UNITS), 1.0, 0.0
    if name in BASE_UNITS:
        return tuple(int(b == name) for b in BASE_UNITS), 1.0, 0.0
    return None
