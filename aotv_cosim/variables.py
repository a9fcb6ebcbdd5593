"""The variables of an FMU or of every FMU of a wiring, as a table (`aotv-cosim describe`).

One row per variable: causality, variability, type, unit, start value, declared min and max
and description, as the modelDescription states them (a missing min/max is None: no range
declared). For a wiring the table also names the component and gives `value`: what the wiring
(or a scenario's overrides) sets, or the source of a connected input ('<- vehicle.h').
"""

from pathlib import Path
from typing import cast

import pandas as pd

from aotv_cosim.errors import InputError
from aotv_cosim.model.variable_types import KIND

COLUMNS = ("variable", "causality", "variability", "type", "unit", "start", "min", "max", "description")


def _typed(text, type_):
    """A modelDescription attribute (a string) as a number of the variable's type (`type_`, its
    declared FMI 2.0 or 3.0 type)."""
    kind = KIND.get(type_)
    if text is None:
        return None
    if kind == "Real":
        return float(text)
    if kind in ("Integer", "Enumeration"):
        return int(text)
    if kind == "Boolean":
        return text in ("true", "1")
    return text


def fmu_rows(info) -> list:
    """One dict per variable of an FmuInfo (system.read_fmu), in declaration order."""
    rows = []
    for v in info.model_description.modelVariables:
        declared = v.declaredType
        low = v.min if v.min is not None else getattr(declared, "min", None)
        high = v.max if v.max is not None else getattr(declared, "max", None)
        rows.append({"variable": v.name, "causality": v.causality, "variability": v.variability,
                     "type": v.type, "unit": info.variables[v.name].unit, "start": _typed(v.start, v.type),
                     "min": _typed(low, v.type), "max": _typed(high, v.type),
                     "description": _with_items(v)})
    return rows


def _with_items(variable) -> str:
    """A variable's description, followed for an Enumeration by its declared type's items
    ('Mode: 1 Hold, 2 Ramp'), which the wiring and --set accept by integer or by name."""
    text = variable.description or ""
    declared = variable.declaredType
    if variable.type != "Enumeration" or declared is None:
        return text
    listed = f"{declared.name}: " + ", ".join(f"{item.value} {item.name}" for item in declared.items)
    return f"{text} ({listed})" if text else listed


def describe(target) -> pd.DataFrame:
    """The variables of `target`: an FMU of fmus_src by name, a .fmu/.ssp file, a .py FMU source
    (built first, `fmu.build.ensure_fmu`), a wiring or a scenario file (its system, with the scenario's overrides), or a
    loaded System/Scenario."""
    from aotv_cosim.model.scenario import Scenario
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.model.fmu_file import read_fmu, resolve_fmu
    from aotv_cosim.model.system import System
    from aotv_cosim.simulation.loading import load_system
    from aotv_cosim.fmu.build import built_fmu

    if isinstance(target, Scenario):
        return _system_table(target.system)
    if isinstance(target, System):
        return _system_table(target)
    text = str(target)
    path = Path(text)
    if path.suffix in (".fmu", ".py") or (not path.suffix and not path.exists()):
        fmu = cast(Path, resolve_fmu(text, Path.cwd(), built_fmu, file=text, entry="FMU"))  # built_fmu: a file
        return pd.DataFrame(fmu_rows(read_fmu(fmu, file=text, entry="FMU")), columns=list(COLUMNS),
                            dtype=object)  # an Integer's start stays an integer beside Real ones
    if not path.is_file():  # a folder, a device or a FIFO is there, or nothing
        from aotv_cosim.paths import regular_file

        regular_file(path, what="wiring, scenario, .fmu or .py FMU source file")
        raise InputError("file not found", file=text,
                         fix="give an FMU name of this package, a .fmu, a .py FMU source, a wiring or a scenario file")
    if path.suffix != ".ssp" and "system" in _document(path):
        return _system_table(load_scenario(path, fmus=built_fmu).system)
    return _system_table(load_system(path, fmus=built_fmu))


def _document(path) -> dict:
    """The JSON object in `path`, or {} if it is none (the wiring loader then says what is wrong)."""
    from aotv_cosim.model.documents import strict_json

    try:
        doc = strict_json(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return {}
    return doc if isinstance(doc, dict) else {}


def _system_table(system) -> pd.DataFrame:
    sources = system.source_of()
    rows = []
    for comp in system.components.values():
        for row in fmu_rows(comp.fmu):
            name = row["variable"]
            value = comp.parameters.get(name)
            if (comp.name, name) in sources:
                value = "<- " + ".".join(sources[(comp.name, name)])
            rows.append({"component": comp.name, **row, "value": value})
    return pd.DataFrame(rows, columns=["component", *COLUMNS, "value"], dtype=object)


def format_table(frame: pd.DataFrame) -> str:
    """The table as aligned text, blank where a value is not declared."""
    return frame.astype(object).where(frame.notna(), "").to_string(index=False)
