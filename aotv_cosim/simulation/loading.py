"""Loading for running: the model's loaders with this package's FMUs built on first use.

`model.scenario.load_scenario` and `model.system.load_system` take an FMU resolver and never
build anything themselves; these give them `fmu.build.built_fmu`, which builds an FMU of
fmus_src (or a user's FMU source) when its .fmu is missing or stale. The command line, the API,
the campaigns and the studies load through here; a caller with FMUs of its own (or in-process
fakes, `direct_instance.info_of_class`) passes another resolver.

Building runs a user's FMU source in a child process for up to a minute (`fmu.source_check`), and
loading holds nothing a signal could leave half done: so while SIGINT/SIGTERM are deferred (a
command that runs), the first signal during a load raises `interrupts.Interrupted` at once
(`interrupts.forcible`), and the child is killed on the way out.
"""

from aotv_cosim.fmu.build import built_fmu
from aotv_cosim.model import scenario as _scenario
from aotv_cosim.model import system as _system
from aotv_cosim.model.fmu_file import FmuResolver
from aotv_cosim.simulation import interrupts


def load_scenario(path, sets=None, step=None, start=None, stop=None, *,
                  fmus: FmuResolver = built_fmu) -> _scenario.Scenario:
    """`model.scenario.load_scenario` with FMUs built when missing or stale (`fmus`)."""
    with interrupts.forcible(first=True):
        return _scenario.load_scenario(path, sets, step, start, stop, fmus=fmus)


def load_system(path, overrides=None, overrides_file=None, *, fmus: FmuResolver = built_fmu) -> _system.System:
    """`model.system.load_system` with FMUs built when missing or stale (`fmus`)."""
    with interrupts.forcible(first=True):
        return _system.load_system(path, overrides, overrides_file, fmus=fmus)
