"""FMU files as the engine reads them: resolving a wiring's FMU reference, checking the archive,
and the modelDescription's variables and per-variable feedthrough (`FmuInfo`).

FMI 2.0 and FMI 3.0 co-simulation FMUs are read. What an FMI 3.0 FMU may declare that this
master does not run is refused when the FMU is read, in one line naming the feature
(`_fmi3_refusals`): array variables the wiring could reach, clocks, an FMU for scheduled
execution or model exchange only.

Feedthrough is read per variable from ModelStructure (`Outputs` dependencies; none declared means
the output depends on every input); initial feedthrough adds `InitialUnknowns`.
"""

import zipfile
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any, Union
from collections.abc import Callable

from fmpy import read_model_description

from aotv_cosim.model.archives import check_fmu_members, check_sizes
from aotv_cosim.errors import InputError
from aotv_cosim.model.variable_types import KIND, call_type
from aotv_cosim.paths import regular_file, resolved

VERSIONS = ("2.0", "3.0")
"""The fmiVersion values of the FMUs the master runs."""

FmuResolver = Callable[[str | Path], Union[Path, "FmuInfo"]]
"""Gives the .fmu file of a wiring's FMU reference that is not a .fmu path: a name of this
package's FMUs, or a user's FMU source (its absolute .py path). Loading takes one, so it builds
nothing itself; the API and the command line give `fmu.build.built_fmu`, which builds the FMU
when it is missing or stale. An AotvError it raises is reported against the wiring entry. It
may give an `FmuInfo` instead of a file: an in-process slave class with no FMU file
(`direct_instance.info_of_class`, the fake FMUs of the master's tests)."""


@dataclass(frozen=True)
class Variable:
    """One scalar variable of an FMU, as its modelDescription declares it: `type` its kind
    (Real, Integer, Boolean, String, Enumeration: how the master exchanges and records it,
    `variable_types.KIND`), `fmi_type` the FMI type it is declared with (Float32, UInt8, Binary...
    in FMI 3.0; the same as `type` in FMI 2.0)."""

    name: str
    vr: int
    type: str
    causality: str
    variability: str
    unit: str
    start: object
    description: str
    fmi_type: str = None  # type: ignore[assignment]  # None: the variable's `type` (__post_init__)

    def __post_init__(self):
        if self.fmi_type is None:
            object.__setattr__(self, "fmi_type", self.type)


@dataclass
class FmuInfo:
    """An FMU file and what its modelDescription says."""

    path: Path
    model_description: Any  # fmpy's ModelDescription
    variables: dict
    feedthrough: dict
    initial_feedthrough: dict
    slave_class: type | None = field(default=None, compare=False, repr=False)
    """The slave class of an FMU that is a class, not a file (`simulation.direct_instance`)."""

    @property
    def guid(self):
        return self.model_description.guid

    @property
    def model_identifier(self):
        return self.model_description.coSimulation.modelIdentifier

    @property
    def fmi_version(self) -> str:
        """"2.0" or "3.0"."""
        return self.model_description.fmiVersion

    def call_type(self, name: str) -> str:
        """The FMI type of the get/set functions of variable `name` (`variable_types.call_type`)."""
        return call_type(self.fmi_version, self.variables[name].fmi_type)


def resolve_fmu(ref: str, base: Path, fmus: FmuResolver, *, file=None, entry=None) -> "Path | FmuInfo":
    """The .fmu file of an FMU reference of a wiring file: a path ending in .fmu, relative to
    base; a user's FMU source ending in .py, relative to base, or a name of this package's FMUs,
    both given to `fmus`. A name `fmus` refuses (InputError) is reported against `file` and `entry`."""
    if ref.endswith(".fmu"):
        return resolved(base / ref, file=file, entry=entry, what=".fmu file")
    if ref.endswith(".py"):
        source = resolved(base / ref, file=file, entry=entry, what="FMU source (.py)")
        try:
            regular_file(source, what="FMU source (.py)", file=file, entry=entry)
        except InputError as exc:
            raise InputError(f"FMU source {exc.cause}", file=file, entry=entry,
                             fix="correct the path (relative to the wiring file)") from None
        return fmus(source)
    try:
        return fmus(ref)
    except InputError as exc:
        exc.file, exc.entry = exc.file or file, exc.entry or entry
        raise


def check_archive(path: Path, *, file=None, entry=None) -> None:
    """Refuse an FMU or SSP archive whose member names are absolute or climb out with '..', or
    whose sizes exceed the limits of `archives.check_sizes` (checked before any extraction).

    The error names `file` and `entry` (the document that refers to the archive) when given,
    else the archive itself. A file that is not a zip archive raises zipfile.BadZipFile.
    """
    with zipfile.ZipFile(path) as archive:
        check_sizes(archive, path, file=file, entry=entry)
        for name in archive.namelist():
            pure = PurePosixPath(name.replace("\\", "/"))
            drive = bool(pure.parts) and ":" in pure.parts[0]
            if pure.is_absolute() or ".." in pure.parts or drive:
                raise InputError(f"member {name!r} of {Path(path).name} escapes the extraction folder",
                                 file=file or path, entry=entry,
                                 fix="rebuild the archive with relative member names")


def read_fmu(path: Path, *, file, entry) -> FmuInfo:
    """Read an FMU's modelDescription into an FmuInfo; InputError if missing or corrupt, or if it
    is not a co-simulation FMU of FMI 2.0 or 3.0 this master can run."""
    try:
        regular_file(path, what=".fmu file", file=file, entry=entry)
    except InputError as exc:
        raise InputError(f"FMU {exc.cause}", file=file, entry=entry,
                         fix="correct the path (relative to the wiring file) or build the FMU") from None
    try:
        check_archive(path, file=file, entry=entry)
        md = read_model_description(str(path))
    except InputError:
        raise
    except Exception as exc:  # fmpy raises many kinds for a corrupt archive or XML
        raise InputError(f"cannot read FMU {path.name}: {exc}", file=file, entry=entry,
                         fix="give a valid FMI 2.0 or 3.0 co-simulation FMU") from exc
    if md.fmiVersion not in VERSIONS or md.coSimulation is None:
        only = " (it is for scheduled execution only)" if getattr(md, "scheduledExecution", None) else ""
        raise InputError(f"{path.name} is not an FMI 2.0 or 3.0 co-simulation FMU{only}", file=file, entry=entry,
                         fix="export the FMU for FMI 2.0 or 3.0 co-simulation")
    if md.fmiVersion == "3.0":
        refused = _fmi3_refusals(md)
        if refused:
            cause, fix = refused
            raise InputError(f"{path.name} {cause}", file=file, entry=entry, fix=fix)
    check_fmu_members(path, md.coSimulation.modelIdentifier, fmi_version=md.fmiVersion, file=file, entry=entry)
    variables = {v.name: Variable(v.name, v.valueReference, KIND[v.type], v.causality, v.variability,
                                  v.unit or (v.declaredType.unit if v.declaredType else None) or "",
                                  v.start, v.description or "", v.type)
                 for v in md.modelVariables}
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    feedthrough = _dependencies(md.outputs, inputs)
    initial = _dependencies(md.initialUnknowns, inputs)
    return FmuInfo(path, md, variables, feedthrough, {**feedthrough, **initial})


REACHABLE = ("parameter", "input", "output", "structuralParameter")
"""Causalities of the variables a wiring can set, connect or record."""


def _fmi3_refusals(md):
    """(cause, fix) of what an FMI 3.0 co-simulation FMU declares that the master does not run,
    the cause the rest of a sentence after the FMU's name, or None: array variables a wiring could
    reach (FMI 3.0 arrays), Clock variables and clocked variables (clocks). Event mode and early
    return are not refused: the master never asks for them (eventModeUsed and earlyReturnAllowed
    false), which every co-simulation FMU must accept."""
    def listed(names):
        return ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")

    arrays = [v.name for v in md.modelVariables if v.dimensions and v.causality in REACHABLE]
    if arrays:
        return (f"declares array variables ({listed(arrays)}): FMI 3.0 arrays are not supported by this master",
                "export the FMU with scalar parameters, inputs and outputs")
    clocks = [v.name for v in md.modelVariables if v.type == "Clock" or v.clocks]
    if clocks:
        return (f"declares clocks or clocked variables ({listed(clocks)}): FMI 3.0 clocks are not supported "
                "by this master", "export the FMU without clocks")
    return None


def _dependencies(unknowns, inputs):
    """{output: set of inputs it depends on}; no dependencies attribute means all inputs."""
    deps = {}
    for u in unknowns:
        if u.dependencies is None:
            deps[u.variable.name] = set(inputs)
        else:
            deps[u.variable.name] = {d.name for d in u.dependencies if d.causality == "input"}
    return deps
