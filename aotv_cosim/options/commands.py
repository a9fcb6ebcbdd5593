"""One frozen options object per command, built alike by the command line's parser and by the
Python API's keywords, checked on construction (`options.checks`), and passed whole down to where
the work is done, the campaign workers included (local processes and Dask).

Units: times and limits in s, memory in MiB, angles in rad, lengths in m. The defaults are the
same on both faces but for `workers` (the command line's 1, the API's every usable core; None here
means every usable core) and where a face has no choice: the command line always writes into an
output folder (`results/...` by default) and draws plots, the API writes nothing without `out`.
"""

from dataclasses import dataclass, field
from pathlib import Path

from aotv_cosim.options import checks
from aotv_cosim.options.checks import (
    Options,
    bracket,
    choice,
    count,
    flag,
    grids,
    law_files,
    number,
    overrides,
    path,
    paths,
    rule,
    scheduler,
    workers,
)
from aotv_cosim.simulation.master import FMI_CALLS
from aotv_cosim.simulation.watchdog import CAMPAIGN_STEP_TIMEOUT
from aotv_cosim.studies.corridor import AIMS

DEFAULT_MAX_RSS_MIB = 2048.0
"""Resident memory a local campaign worker may use, MiB (a worker running the shipped laws holds
about 150-250 MiB)."""

_FMI_CALLS = choice(*FMI_CALLS, optional=True)


def _scenario(value, where):
    """A scenario file path, or (from Python) a loaded `model.scenario.Scenario`."""
    from aotv_cosim.model.scenario import Scenario

    return value if isinstance(value, Scenario) else path("scenario file (or .ssp)")(value, where)


def _described(value, where):
    """What `describe` takes: a name or path, or a loaded System or Scenario."""
    from aotv_cosim.model.scenario import Scenario
    from aotv_cosim.model.system import System

    if isinstance(value, (Scenario, System)):
        return value
    return str(path("FMU name, .fmu, .py source, wiring or scenario file")(value, where))


def _bracket(value, where):
    """The corridor's bracket (`checks.bracket`), or None."""
    return None if value is None else bracket(value, where)


class _Scenario(Options):
    """Options of a command about one scenario: its path names the error lines."""

    def _file(self):
        return checks.named(getattr(self, "scenario", None))


@dataclass(frozen=True, kw_only=True)
class RunOptions(_Scenario):
    """`aotv-cosim run` / `aotv_cosim.run`: one scenario, in memory or into a folder."""

    scenario: object = field(metadata=rule(_scenario, "SCENARIO"))
    """A scenario file (or an .ssp archive), or from Python a loaded Scenario."""
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """The output folder; None: in memory, nothing written."""
    sets: tuple = field(default=(), metadata=rule(overrides, "--set"))
    """Overrides of parameters and unconnected inputs, SI: a mapping {'comp.var': value}, kept as
    pairs."""
    step: float | None = field(default=None, metadata=rule(number(low=0.0, low_open=True, optional=True, unit="s",
                                                      what="the step"), "--step"))
    """Communication step, s (None: the scenario's)."""
    start: float | None = field(default=None, metadata=rule(number(optional=True, unit="s", what="the start"),
                                                            "--start"))
    """Start time, s (None: the scenario's); with start or stop given only the expectations at
    the event are checked."""
    stop: float | None = field(default=None, metadata=rule(number(optional=True, unit="s", what="the stop"), "--stop"))
    """Stop time, s (None: the scenario's)."""
    formats: tuple = field(default=("csv",), metadata=rule(checks.formats, "--format"))
    """Time series files: "csv" and/or "parquet"."""
    plots: bool = field(default=False, metadata=rule(flag, "--no-plots"))
    """Draw the PNG plots into `out` (needs `out`)."""
    step_timeout: float | None = field(default=None, metadata=rule(checks.step_limit, "--step-timeout"))
    """Wall-clock limit of one communication step, s (None: the scenario's, else none)."""
    fmi_calls: str | None = field(default=None, metadata=rule(_FMI_CALLS, "--fmi-calls"))
    """"direct" (this package's FMUs called in this interpreter; others through C) or "c" (every FMU
    through its C library); None: "direct". The results do not depend on it."""

    def _check_together(self):
        if self.plots and self.out is None:
            raise checks.InputError("plots need an output folder", file=self._file(), entry="plots",
                                    fix="give out=FOLDER, or plots=False")

    @property
    def overrides(self) -> dict:
        """The --set values as {'comp.var': value}."""
        return dict(self.sets)


@dataclass(frozen=True, kw_only=True)
class CheckOptions(Options):
    """`aotv-cosim check`: run every scenario with expectations under `paths`."""

    paths: tuple = field(default=("scenarios",), metadata=rule(paths("scenario files or folders"), "PATHS"))
    """Scenario files or folders (default: scenarios/)."""
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """Base output folder: each scenario's results in OUT/<scenario> (None: results/check)."""
    start: float | None = field(default=None, metadata=rule(number(optional=True, unit="s", what="the start"),
                                                            "--start"))
    stop: float | None = field(default=None, metadata=rule(number(optional=True, unit="s", what="the stop"), "--stop"))


@dataclass(frozen=True, kw_only=True)
class ValidateOptions(Options):
    """`aotv-cosim validate`: check scenario, wiring, comparison or .ssp files without running."""

    files: tuple = field(metadata=rule(paths("scenario, wiring or comparison files"), "FILES"))
    benchmark: Path | None = field(default=None, metadata=rule(path("benchmark set", optional=True), "--benchmark"))
    """A benchmark set (a folder, a scenario or a shipped set's name): each file, a law's wiring or
    scenario, is also checked against the set's contract (`campaigns.contract`); with no file the
    contract is what is asked for."""

    def _check_together(self):
        if not self.files and self.benchmark is None:
            raise checks.InputError("no file given", entry="FILES", fix="give at least one file to validate, or "
                                                                        "--benchmark SET for that set's contract")


@dataclass(frozen=True, kw_only=True)
class DescribeOptions(Options):
    """`aotv-cosim describe` / `aotv_cosim.describe`: the variables of an FMU or a system."""

    target: object = field(metadata=rule(_described, "FMU|WIRING"))
    """An FMU name of this package, a .fmu, a .py FMU source, a wiring, scenario or .ssp file, or
    (from Python) a loaded System or Scenario."""

    def _file(self):
        return checks.named(self.target)


@dataclass(frozen=True, kw_only=True)
class BuildOptions(Options):
    """`aotv-cosim build-fmus` / `aotv_cosim.build_fmus`: the FMUs of fmus_src or your own sources."""

    sources: tuple = field(default=(), metadata=rule(paths("FMU names or sources"), "NAME|SOURCE.py"))
    """Names of this package's FMUs or paths of .py FMU sources (none: every FMU of fmus_src)."""
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """A folder for the FMUs (NAME.fmu) instead of the cache."""
    fmi_version: int | None = field(default=None, metadata=rule(choice(2, 3, optional=True), "--fmi"))
    """2 or 3 (FMI 2.0 or 3.0); None: 2.0, or 3.0 for a pythonfmu3 class (`fmu.build_fmi3`)."""


@dataclass(frozen=True, kw_only=True)
class ExportOptions(_Scenario):
    """`aotv-cosim export-ssp`: a scenario's system as an SSP archive."""

    scenario: object = field(metadata=rule(_scenario, "SCENARIO"))
    out: Path = field(metadata=rule(path(".ssp file"), "--out"))
    """The .ssp archive to write."""
    sets: tuple = field(default=(), metadata=rule(overrides, "--set"))
    step: float | None = field(default=None, metadata=rule(number(low=0.0, low_open=True, optional=True, unit="s",
                                                      what="the step"), "--step"))
    fmi_version: int = field(default=2, metadata=rule(choice(2, 3), "--fmi"))
    """FMI version of this package's FMUs in the archive (other .fmu files are copied as they are)."""

    @property
    def overrides(self) -> dict:
        return dict(self.sets)


@dataclass(frozen=True, kw_only=True)
class CompareOptions(Options):
    """`aotv-cosim compare`: the seed documents' comparisons."""

    comparison: Path = field(metadata=rule(path("comparison file"), "COMPARISON"))
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    plots: bool = field(default=True, metadata=rule(flag, "--no-plots"))

    def _file(self):
        return checks.named(self.comparison)


@dataclass(frozen=True, kw_only=True)
class RunsOptions(_Scenario):
    """What every campaign-like command (montecarlo, benchmark, sweep, corridor) shares: where and
    how its runs are made. The whole object travels to every worker (local process or Dask task)."""

    workers: int | None = field(default=None, metadata=rule(workers, "--workers"))
    """Local worker processes (None: one per usable core; at most 4 per usable core); with a
    scheduler, batches are planned for at least this many workers (at most 4096)."""
    scheduler: object = field(default=None, metadata=rule(scheduler, "--scheduler"))
    """None for local workers, else a Dask scheduler address or (from Python) a distributed.Client;
    a Client does not travel to the workers (`__getstate__`)."""
    step_timeout: float | None = field(default=None, metadata=rule(checks.step_limit, "--step-timeout"))
    """Wall-clock limit of one step, s (None: the scenario's step_timeout, else 60 s)."""
    max_rss: float | None = field(default=DEFAULT_MAX_RSS_MIB, metadata=rule(checks.memory_limit, "--max-rss"))
    """Resident memory a local worker may use, MiB (None: no limit): a run that passes it is
    recorded failed and its worker replaced."""
    fmi_calls: str | None = field(default=None, metadata=rule(_FMI_CALLS, "--fmi-calls"))
    """As for `RunOptions.fmi_calls`; the rows do not depend on it."""
    progress: bool = field(default=False, metadata=rule(flag, "progress"))
    """Show a progress bar on stderr (the command line does)."""

    def _check_together(self):
        if self.scheduler is None:
            checks.local_workers(self.workers, checks.Where(self._file(), "--workers"))

    keep_series = False
    """Whether each row carries its run's decimated signals (only `CampaignOptions` can ask)."""
    resume = False
    """Whether a campaign continues the rows in its folder (only `CampaignOptions` can ask)."""
    plots = True
    """Whether a campaign draws its plots (`CampaignOptions` can leave them out)."""

    def step_limit(self, scenario) -> float:
        """The step limit of the campaign's runs of the loaded `scenario`, s."""
        return self.step_timeout or scenario.step_timeout or CAMPAIGN_STEP_TIMEOUT

    @property
    def max_rss_bytes(self) -> int | None:
        """`max_rss` in bytes (None: no limit)."""
        return None if self.max_rss is None else int(self.max_rss * 2**20)

    def __getstate__(self):
        """What a worker receives: everything but a distributed.Client (its address instead)."""
        state = dict(self.__dict__)
        client = state.get("scheduler")
        if client is not None and not isinstance(client, str):
            state["scheduler"] = getattr(getattr(client, "scheduler", None), "address", None)
        return state


@dataclass(frozen=True, kw_only=True)
class CampaignOptions(RunsOptions):
    """`aotv-cosim montecarlo` / `aotv_cosim.montecarlo`: dispersed runs of one scenario."""

    scenario: object = field(metadata=rule(_scenario, "SCENARIO"))
    """A scenario file that declares dispersions (from Python a loaded Scenario: run from its file,
    which every worker loads)."""
    runs: int = field(metadata=rule(count(1, checks.MAX_RUNS, "runs"), "--runs"))
    """Number of runs, 1 to MAX_RUNS."""
    seed: int = field(default=0, metadata=rule(count(0, checks.MAX_SEED, "seed"), "--seed"))
    """Campaign seed: run k's draws depend only on it and k."""
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """The campaign folder; None: a temporary one, removed."""
    resume: bool = field(default=False, metadata=rule(flag, "--resume"))
    """Continue an interrupted campaign in `out`."""
    sets: tuple = field(default=(), metadata=rule(overrides, "--set"))
    """As for `RunOptions.sets`."""
    start: float | None = field(default=None, metadata=rule(number(optional=True, unit="s", what="the start"),
                                                            "--start"))
    stop: float | None = field(default=None, metadata=rule(number(optional=True, unit="s", what="the stop"), "--stop"))
    keep_series: bool = field(default=False, metadata=rule(flag, "--keep-series"))
    """Also keep every run's recorded signals (about 200 rows a run) in series.parquet."""
    plots: bool = field(default=True, metadata=rule(flag, "plots"))
    """Draw the campaign plots (with `out`)."""

    def _check_together(self):
        from aotv_cosim.model.scenario import Scenario

        super()._check_together()
        if self.resume and self.out is None:
            raise checks.InputError("resume needs the folder of the interrupted campaign", file=self._file(),
                                    entry="--resume", fix="give out=FOLDER")
        if isinstance(self.scenario, Scenario):
            object.__setattr__(self, "scenario", Path(self.scenario.path))

    @property
    def overrides(self) -> dict:
        return dict(self.sets)


@dataclass(frozen=True, kw_only=True)
class BenchmarkOptions(RunsOptions):
    """`aotv-cosim benchmark` / `aotv_cosim.benchmark`: every law of a set and your laws through
    the same dispersions."""

    scenario_set: Path = field(metadata=rule(path("scenario set (a folder, a scenario or a shipped set's name)"),
                                             "SET"))
    """A folder of scenarios (one law each), one scenario file, or a shipped set's name
    (benchmark_seed000, benchmark_aerocapture/afe, benchmark_aerocapture/aotv)."""
    laws: tuple[Path, ...] = field(default=(), metadata=rule(law_files, "--law"))
    """Your laws: wiring or scenario files (one path alone is one law)."""
    runs: int = field(default=1000, metadata=rule(count(1, checks.MAX_RUNS, "runs"), "--runs"))
    """Runs per law, 1 to MAX_RUNS."""
    seed: int = field(default=0, metadata=rule(count(0, checks.MAX_SEED, "seed"), "--seed"))
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """The output folder; None: a temporary one, removed."""
    reuse: bool = field(default=True, metadata=rule(flag, "--refly"))
    """Reuse the stored rows of laws unchanged since an earlier benchmark (--refly: False)."""

    def _file(self):
        return checks.named(self.scenario_set)


@dataclass(frozen=True, kw_only=True)
class SweepOptions(RunsOptions):
    """`aotv-cosim sweep` / `aotv_cosim.sweep`: a scenario flown at every point of parameter grids."""

    scenario: Path = field(metadata=rule(path("scenario file"), "SCENARIO"))
    grids: tuple = field(metadata=rule(grids, "--grid"))
    """((parameter, (values...)), ...), SI, from {"comp.var": values} or "comp.var=LOW:HIGH:N" texts;
    every combination is flown (at most MAX_POINTS)."""
    sets: tuple = field(default=(), metadata=rule(overrides, "--set"))
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """A folder for sweep.csv/.parquet/.json and sweep.png; None: nothing kept."""

    def _check_together(self):
        super()._check_together()
        both = sorted({name for name, _ in self.sets} & {name for name, _ in self.grids})
        if both:
            raise checks.InputError(f"{', '.join(both)} is given both by --set and by --grid", file=self._file(),
                                    entry="--grid", fix="give each parameter by one of them (the grid flies every "
                                                        "value; drop the --set)")

    @property
    def overrides(self) -> dict:
        return dict(self.sets)

    def check_values(self, system) -> None:
        """Refuse, before any run, a grid that names no Real parameter or input of the loaded
        `system`, and a grid value that `--set` would refuse: a connected input, a value outside the
        declared min/max (the smallest and largest of each grid are checked: a range is an interval)."""
        from aotv_cosim.model.system import with_values

        for name, _ in self.grids:
            comp, _, var = name.partition(".")
            variable = system.components[comp].fmu.variables.get(var) if comp in system.components else None
            if variable is None or variable.type != "Real" or variable.causality not in ("parameter", "input"):
                raise checks.InputError(f"{name} is not a Real parameter of the system", file=self._file(),
                                        entry="--grid", fix="sweep a parameter or start value (`aotv-cosim describe "
                                                            "SCENARIO` lists them)")
        file = f"{self.scenario} (with --grid)"
        for pick in (min, max):
            with_values(system, {name: pick(values) for name, values in self.grids}, file)


@dataclass(frozen=True, kw_only=True)
class CorridorOptions(RunsOptions):
    """`aotv-cosim corridor` / `aotv_cosim.corridor`: the entry corridor by bisection at full lift up
    and down (`studies.corridor`)."""

    scenario: Path = field(metadata=rule(path("scenario file"), "SCENARIO"))
    lift_to_drag: float | None = field(default=None, metadata=rule(number(low=0.0, low_open=True, optional=True,
                                                                          what="L/D"), "--lift-to-drag"))
    """L/D flown at full lift up and down by a vehicle steered by its lift acceleration (finite,
    > 0; required there); None for a bank-angle vehicle, which flies its own C_L/C_D."""
    aim: str = field(default="target", metadata=rule(choice(*AIMS), "--aim"))
    """"target": both bounds exit on the target apogee (the theoretical corridor); "band": the
    steep bound on the capture band's lower edge, the shallow on its upper edge."""
    angle_tolerance: float = field(default=1e-6, metadata=rule(number(low=0.0, low_open=True, high=0.01, unit="rad",
                                                                      what="the angle tolerance"), "--angle-tolerance"))
    """A bisection ends when its gamma0 bracket is this narrow, rad (finite, in (0, 0.01])."""
    tolerance: float | None = field(default=None, metadata=rule(number(low=0.0, low_open=True, optional=True, unit="m",
                                                                       what="the tolerance"), "--tolerance"))
    """A bisection also ends when a run's apogee error is this close to the aim, m (None: only
    the angle tolerance ends it; finite, > 0)."""
    step: float | None = field(default=None, metadata=rule(number(low=0.0, low_open=True, optional=True, unit="s",
                                                                  what="the step"), "--step"))
    """Communication step of the passes flown, s (None: the scenario's, at most 0.1 s)."""
    bracket: tuple | None = field(default=None, metadata=rule(_bracket, "--bracket"))
    """(steep, shallow) entry flight-path angles searched, rad, -pi/2 < steep < shallow < 0 (None:
    each bound searched outward from the scenario's entry)."""
    sets: tuple = field(default=(), metadata=rule(overrides, "--set"))
    """As for `RunOptions.sets`, applied to the passes flown (not to the guidance taken out)."""
    out: Path | None = field(default=None, metadata=rule(path("output folder", optional=True), "--out"))
    """A folder for corridor.json, corridor.png and the two scenarios flown; None: nothing kept."""
    workers: int | None = field(default=None, metadata=rule(workers, "--workers"))
    """Local worker processes (None: one per usable core): the two bounds are searched side by side
    with 2; more are not used."""

    @property
    def overrides(self) -> dict:
        return dict(self.sets)

