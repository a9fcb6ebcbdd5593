"""Shared fixtures (a scenario loader, a tiny fault-injection FMU, the package FMUs built once) and
the selection rules of the `slow` and `integration` markers (pyproject.toml registers them)."""

import os

# Tiny matrices are ~30x slower with OpenBLAS's thread pool on 2 shared cores.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import json
import textwrap
from pathlib import Path

import pytest

from tests.helpers import NOMINAL, WIRING, drawing


def pytest_collection_modifyitems(config, items):
    """Slow studies stay out of every run whose -m expression does not name `slow`: the default
    run, and also `-m "not integration"` or `-m integration` (a -m on the command line replaces
    one given in addopts, so this cannot be left to addopts)."""
    if "slow" in config.getoption("markexpr"):
        return
    slow = [item for item in items if item.get_closest_marker("slow")]
    if slow:
        config.hook.pytest_deselected(items=slow)
        items[:] = [item for item in items if not item.get_closest_marker("slow")]


@pytest.fixture
def drawn(monkeypatch):
    """{absolute path: Drawing} of every figure this process saves during the test, taken just
    before it is written: what the PNG shows, not only that it exists."""
    from matplotlib.figure import Figure

    saved = {}
    original = Figure.savefig

    def savefig(fig, fname, *args, **kwargs):
        saved[Path(fname).resolve()] = drawing(fig)
        return original(fig, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return saved


@pytest.fixture
def wiring_doc():
    """The seed-000 wiring file as a dict, with the package FMUs named (paths need no rewrite)."""
    return json.loads(WIRING.read_text())


@pytest.fixture
def scenario_doc():
    """The nominal scenario as a dict whose system path is absolute."""
    doc = json.loads(NOMINAL.read_text())
    doc["system"] = str(WIRING)
    return doc


FAULTY_SOURCE = textwrap.dedent('''
    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


    class Faulty(Fmi2Slave):
        """Test FMU: y = t; raises inside do_step once t passes fail_at (s), or outputs NaN."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.fail_at = 1.0
            self.nan_instead = 0.0
            self.y = 0.0
            self.register_variable(Real("fail_at", causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))
            self.register_variable(Real("nan_instead", causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))
            self.register_variable(Real("y", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            t = current_time + step_size
            if t > self.fail_at:
                if self.nan_instead:
                    self.y = float("nan")
                    return True
                raise RuntimeError(f"injected fault at t={t:.3f}")
            self.y = t
            return True
''')


@pytest.fixture(scope="session")
def faulty_fmu(tmp_path_factory):
    """A pythonfmu FMU that raises (or outputs NaN) after fail_at seconds."""
    from pythonfmu.builder import FmuBuilder

    folder = tmp_path_factory.mktemp("faulty")
    script = folder / "Faulty.py"
    script.write_text(FAULTY_SOURCE)
    return FmuBuilder.build_FMU(script, dest=folder / "Faulty.fmu")


@pytest.fixture(scope="session", autouse=True)
def built_fmus(request):
    """Every FMU of fmus_src built before the first test, when an integration test is to run (the
    others need none). A first build reports its progress on the terminal, which tests of one-line
    errors and of printed file lists must not read (the progress itself is tested with an empty
    cache in output/test_cli_results.py)."""
    if any(item.get_closest_marker("integration") for item in request.session.items):
        from aotv_cosim.fmu import build

        build.build_all()
