"""What a campaign worker loads its scenario from (`ScenarioRef`): sent to every worker process
or Dask task in place of the loaded scenario, which holds FMU files and is not meant to travel."""

from dataclasses import dataclass
from pathlib import Path
from collections.abc import Mapping

from aotv_cosim.model.scenario import Scenario

from aotv_cosim.simulation.loading import load_scenario


@dataclass(frozen=True)
class ScenarioRef:
    """A scenario file with the overrides a campaign gives it; hashable, so a worker keeps one
    `worker.Runner` per reference."""

    path: str
    """The scenario file (absolute, so a worker in another folder finds it)."""
    sets: tuple = ()
    """The --set overrides as ('comp.var', value) pairs, in the order given."""
    start: float | None = None
    """--start, s (None: the scenario's)."""
    stop: float | None = None
    """--stop, s (None: the scenario's)."""

    @classmethod
    def of(cls, path, sets: Mapping | None = None, start: float | None = None,
           stop: float | None = None) -> "ScenarioRef":
        """The reference of scenario file `path` with --set values `sets` ({'comp.var': value})."""
        return cls(str(path), tuple((sets or {}).items()), start, stop)

    @property
    def overrides(self) -> dict:
        """The --set values as {'comp.var': value}."""
        return dict(self.sets)

    @property
    def times_overridden(self) -> bool:
        """True when --start or --stop is given."""
        return self.start is not None or self.stop is not None

    def load(self) -> Scenario:
        """The scenario with the overrides applied."""
        return load_scenario(Path(self.path), self.overrides or None, start=self.start, stop=self.stop)
